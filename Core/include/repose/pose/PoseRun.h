// The steps of a pose job that every front end runs the same way (`repose pose`, `repose sweep`,
// the module's Logic, Python): the one rule for what can be posed, and one frame from the rig to
// its files — the memory rule, the frame, the report completed with what the job knows, the
// write, and whether the frame met its targets. Front ends translate their arguments into a
// FrameRun and say what comes back in their own way (a stderr line, a Python warning, the panel);
// none of them assembles a frame.
#pragma once

#include "repose/pose/PoseFrame.h"
#include "repose/pose/PoseJob.h"
#include "repose/pose/PoseRig.h"
#include "repose/pose/SceneFolder.h"
#include "repose/util/Progress.h"
#include "repose/volume/Volume.h"

#include <cstddef>
#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <vector>

namespace repose {

// A label map a rig is built from or posed: integer voxels, at least one non-zero voxel, and
// orthogonal voxel axes. Throws repose::Error naming `name` (its file or node), one line.
void requirePoseableLabels(const Volume& volume, const std::string& name);

// One line for the labels of `volume` with voxels but no name in its label table ("<name>: labels
// 7, 9 have voxels but no name in its label table; posed like the others, reported by value"),
// or "" when every label present is named. The values version is for labels already counted
// (an out-of-core map never held whole).
std::string unnamedLabelsWarning(const Volume& volume, const std::string& name);
std::string unnamedLabelsWarning(const std::vector<int>& values, const std::string& name);

// The rig of a job, reused from a scene folder when the folder holds one built for the same S and
// settings (the job's sceneKey), else built, and saved there.
struct SceneRigRun {
  std::string folder;        // the scene folder; "": none (built here, kept nowhere)
  SceneInputs inputs;        // what scene.json records of G, S and the image when it is written
  bool saveBuilt = true;     // write a rig built here into the folder (with a folder)
  int threads = 0;           // embedding (0: all cores)
  ProgressFn buildProgress;  // building the cage (0-0.5) and the mesh (0.5-1)
  // What happens, one line each, as a front end shows its progress ("reusing the cage and
  // transfer mesh of ...", "building the cage ...", "embedding the mesh in the cage", where the
  // Green coordinates came from).
  std::function<void(const std::string&)> say;
  // Why a scene in the folder was not reused and is built again (saved over it), one line.
  std::function<void(const std::string&)> note;
};

struct SceneRig {
  std::unique_ptr<PoseRig> rig;
  bool reused = false;  // from the scene folder (report.json's scene_reused)
};

// Reads the scene's rig (readSceneRig) or builds one (PoseJob::buildGeometry), embeds it
// (PoseJob::makeRig) and saves a built one into the folder. A reused scene whose Green
// coordinates file does not belong to its cage and mesh (an older version) has them computed and
// saved, so the next run reads them. Throws repose::Error, or Cancelled from buildProgress.
SceneRig rigForScene(const PoseJob& job, const SceneRigRun& run);

// One frame's run: what the front end was asked for, translated.
struct FrameRun {
  // What the frame holds and how it is sampled (PoseFrameOptions' fields of the same names); the
  // tissue table, the threads and the bones' pieces are the job's.
  const Volume* image = nullptr;  // on G's grid
  std::optional<double> background;
  double spacingMm = 0;
  bool fillPockets = true;
  bool preserveLabelVolumes = true;
  LabelMapFiles labelMapFiles = LabelMapFiles::Nifti;
  // The memory rule (checkFrameMemory): the posed G, S, image and field on the frame's grid
  // beside what the process holds must fit `memoryBudget` bytes (0: half the physical memory).
  // A refusal starts with `budgetWhat` and ends with `budgetHint` (where this front end sets the
  // budget, how to pose out of core).
  double memoryBudget = 0;
  std::string budgetWhat = "the posed volumes";
  std::string budgetHint = "out of core: `repose warp`";
  bool sceneReused = false;  // the rig came from a scene folder (report.json's scene_reused)
  ProgressFn progress;       // posing and rasterizing; may cancel
  // Each warning once known (PoseFrameOptions::warn), one line without the frame's name.
  std::function<void(const std::string&)> warn;
  // The frame's grid once it has passed the memory rule, before anything is allocated for it.
  std::function<void(const VolumeGeometry&)> onGrid;
  // When not empty, the frame is written there (writePosedFrame with `write`, whose
  // labelMapFiles is set from the one above).
  std::string folder;
  FrameWriteOptions write;
  // With a folder: a frame whose posed volumes exceed the memory budget is made slab by slab and
  // written as it goes (poseFrameToFolder: the same files and report), instead of refused. Its
  // outcome holds no volumes (FrameOutcome::streamed).
  bool outOfCore = false;
  // With a folder: every frame slab by slab, whatever its size (the slabs sized to the budget).
  bool alwaysOutOfCore = false;
  // With a folder: the ranks that share every frame's slabs (SlabRanks.h; every rank runs the
  // frame, rank 0 writes it and has the outcome's report). Null: this process alone.
  SlabRanks* ranks = nullptr;
};

struct FrameOutcome {
  PosedFrame frame;        // its reportJson is completed by the job
  std::string reportJson;  // report.json as written (its "outputs" name the files), or completed
  bool targetsMet = true;  // report.json's targets.met
  std::vector<std::string> missed;  // report.json's targets.missed, one line each
  // Made slab by slab into the folder (FrameRun::outOfCore): `frame` holds its name, grid and
  // report only.
  bool streamed = false;
  // "<missed>; <missed>": what a front end says after "written, but it missed its targets: ".
  std::string missedLine() const;
};

// Frame `index` of `rig` (made by `job`; G and S are the job's, at rest), run as `run` says.
// Throws repose::Error (the rig's when index is not one of its frames, the memory rule's one line
// before anything is allocated for the frame) or Cancelled when progress says so; nothing is
// written then.
FrameOutcome runPoseFrame(const PoseJob& job, const PoseRig& rig, std::size_t index,
                          const Volume& organs, const Volume& parts, const FrameRun& run);

}  // namespace repose
