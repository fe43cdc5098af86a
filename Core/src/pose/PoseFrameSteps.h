// The steps a posed frame shares whether it is made whole in memory (poseFrame) or slab by slab
// into its folder (poseFrameToFolder, issue 56): the start (the posed mesh's prediction and the
// output grid), the report assembled from the raster's, the pockets' and the posed maps' counts,
// and the frame's folder written as one unit. Both paths call the same steps, so their reports
// and folders agree by construction. Internal to pose/.
#pragma once

#include "repose/pose/PoseFrame.h"
#include "repose/pose/PosedTally.h"
#include "repose/pose/SlabRanks.h"
#include "repose/raster/PocketFilling.h"
#include "repose/raster/Rasterizer.h"
#include "repose/util/Error.h"

#include <nlohmann/json.hpp>

#include <cstdint>
#include <filesystem>
#include <functional>
#include <memory>
#include <string>
#include <vector>

namespace repose::frame {

// What a frame knows before any voxel: the rig's frame, the posed mesh's prediction (its warning
// already said), the output grid, and the mesh's outer faces.
struct FrameStart {
  PoseRig::Frame frame;
  nlohmann::json prediction;
  VolumeGeometry grid;
  std::vector<std::uint8_t> outer;
  std::vector<std::string> warnings;  // said through PoseFrameOptions::warn as they came
};
FrameStart startFrame(const PoseRig& rig, std::size_t index, const Volume& organs,
                      const Volume& parts, const PoseFrameOptions& options);
// The frame whole in memory (poseFrame after its start and memory check).
PosedFrame poseFrameFrom(FrameStart& start, const PoseRig& rig, const Volume& organs,
                         const Volume& parts, const PoseFrameOptions& options);
// The frame slab by slab into `folder` (poseFrameToFolder after its start); `complete` gives the
// report as the job completes it before it is written (null: as it is). Over `ranks` (null: this
// process alone) every rank calls it; rank 0 writes the folder and returns the report's text, the
// others make slabs and return "".
std::string poseFrameToFolderFrom(FrameStart& start, const PoseRig& rig, const Volume& organs,
                                  const Volume& parts, const PoseFrameOptions& options,
                                  const std::string& folder, const FrameWriteOptions& write,
                                  double memoryBudget, std::int64_t slabSlices,
                                  const std::function<std::string(const std::string&)>& complete,
                                  SlabRanks* ranks = nullptr);
// An upper estimate of the frames of `map` posed on start.grid as a DICOM SEG (one per segment
// and slice where it has voxels, one per empty slice and per segment with none), from the
// segments' rest voxels and the posed tets that reach them (FrameDicomSegEstimate.cpp); `parts`
// is the rest body-part map S the mesh was made from.
std::int64_t dicomSegFramesEstimate(const FrameStart& start, const TransferMesh& mesh,
                                    const Volume& map, const Volume& parts);
// Throws one line naming `folder`'s posed_G.dcm or posed_S.dcm when its estimate passes the 4 GiB
// of pixel data a DICOM object holds: said before the work, in core and slab by slab alike.
// Returns report.json's "dicom_seg": the limit, and per file the estimate and its bytes.
nlohmann::json checkDicomSegFits(const FrameStart& start, const TransferMesh& mesh,
                                 const Volume& organs, const Volume& parts,
                                 const std::string& folder);

// Says `line` (when not empty) through options.warn and keeps it for the report.
void warn(FrameStart& start, const PoseFrameOptions& options, const std::string& line);

// The rasterizer's options for G (S, the image and the field take them with no rounding and no
// progress): the shell's outer faces, the rest parts, the pieces' map and the bones' pieces.
RasterOptions rasterOptions(const FrameStart& start, const Volume& organs, const Volume& parts,
                            const PoseFrameOptions& options);

// The labels of G that move rigidly (the rasterizer's: the mesh's pieces, and through
// RigSettings::bonePieces the other labels of each bone, with or without tets of their own);
// empty when the mesh has no pieces. The posed maps' tally counts collisions between them.
std::vector<int> rigidLabels(const TransferMesh& mesh, const PoseFrameOptions& options);

// The report.json object of the frame: everything but the files' own names, from the counts of
// the rasterizer (G's), the pockets and the posed maps (complete).
std::string frameReport(FrameStart& start, const PoseRig& rig, const Volume& organs,
                        const Volume& parts, const PoseFrameOptions& options,
                        const RasterReport& raster, const PocketReport& pockets,
                        const PosedTally& posed, bool withImage);

// report.json's "outputs" for files written as `files` (the image's added when there is one).
nlohmann::json outputFiles(LabelMapFiles files, bool withImage);

// A frame's folder written as one unit: the files go into a hidden folder beside it, moved in
// together by commit() (an error, a Cancel or an interrupt never leaves half a frame; an existing
// folder's files are replaced, ours this frame does not write removed).
class FrameFolder {
 public:
  FrameFolder(const std::string& folder, bool lockFolder);
  ~FrameFolder();
  const std::filesystem::path& temp() const { return temp_; }  // write the files here
  const std::filesystem::path& dir() const { return dir_; }    // where they will lie
  // A writer's error naming the file where the user will look for it, not in the hidden folder.
  Error named(const Error& e) const;
  // Writes scene.mrml (when options ask for one) and report.json (its "outputs" naming the
  // files written), then moves the folder in. Returns report.json's text.
  std::string commit(nlohmann::json report, const FrameWriteOptions& options, bool withImage);

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
  std::string folder_;
  std::filesystem::path dir_, temp_;
};

}  // namespace repose::frame
