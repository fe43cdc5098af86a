// Scene folders (docs/FORMATS.md, "Scene folders") as the command line and the Python bindings
// write and read them: scene.json in the module's MRML scene format — which the Logic and the
// workbench load — naming the input volumes where they are (absolute paths: nothing large is
// copied), the cage, transfer mesh and pose files beside it, and what the rig was built for, so
// a later run reuses the rig only for the same S and settings.
#pragma once

#include "repose/pose/Pose.h"
#include "repose/pose/PoseRig.h"

#include <optional>
#include <string>

namespace repose {

struct SceneInputs {
  std::string organs, parts, image;  // paths of G, S and the image ("" when none)
};

// What a rig is built for: S (path, size, modification time), the rig settings and the
// separations it was cut with (the pose's own and the automatic ones), as JSON text (the
// scene's "built_for").
std::string sceneRigKey(const std::string& partsPath,
                        const std::vector<LimbSeparation>& separations,
                        const RigSettings& settings);

// Writes scene.json, cage.vtk, tm.vtu and <pose>.pose.json into `folder` (created), each
// atomically, scene.json last.
void writeSceneFolder(const std::string& folder, const PoseRig& rig, const std::string& key,
                      const SceneInputs& inputs, const RigSettings& settings);

struct SceneContents {
  SceneInputs inputs;
  RigGeometry geometry;  // the cage and transfer mesh
  Pose pose;
  std::string key;  // "built_for", JSON text ("" when the scene has none)
};

// Reads a scene folder: the first segmentation's inputs, its cage, transfer mesh and pose.
// Throws repose::Error naming the folder or file and the problem, also when a rig file differs
// from what scene.json recorded when it was written (edited or replaced by hand).
SceneContents readSceneFolder(const std::string& folder);

// The scene's cage and transfer mesh when the folder holds a scene built for `key`; nullopt when
// there is no scene there, or it was built for another S or other settings, or scene.json is not
// a Repose scene, or a rig file is missing or differs from what scene.json recorded. Except when
// there is no scene at all, `why` (if given) then says why it is not reused, in one line.
std::optional<RigGeometry> readSceneRig(const std::string& folder, const std::string& key,
                                        std::string* why = nullptr);

}  // namespace repose
