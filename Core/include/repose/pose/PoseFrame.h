// One frame of a rigged pose at full resolution — what `repose pose`, the module's export and the
// Python bindings all produce: the posed organ map G and body-part map S (and image) on a grid that
// holds the posed body, the displacement field (output -> input), background pockets a bent joint
// trapped filled, and the frame's report (report.json, docs/FORMATS.md).
#pragma once

#include "repose/pose/PoseRig.h"
#include "repose/pose/SlabRanks.h"
#include "repose/util/Progress.h"
#include "repose/volume/TissueTable.h"
#include "repose/volume/Volume.h"

#include <functional>
#include <optional>
#include <string>
#include <vector>

namespace repose {

// The files that hold a frame's posed label maps (docs/FORMATS.md): NIfTI with a 3D Slicer colour
// table beside each (.ctbl: Slicer ignores a NIfTI's own label table and would show grey values),
// Slicer segmentations (.seg.nrrd: names, colours and terminology open as segments), both, or
// DICOM SEG (.dcm: for a PACS, or Slicer's DICOM module; io/DicomSegIO.h).
enum class LabelMapFiles { Nifti, SegNrrd, Both, DicomSeg };
// "nii.gz", "seg.nrrd", "both" or "dcmseg"; "auto": .seg.nrrd when the input label map is one,
// else NIfTI.
// Throws repose::Error naming the choice otherwise.
LabelMapFiles labelMapFilesFor(const std::string& choice, const std::string& inputPath);
// The label-map files of a frame written as `files` (posed_G and posed_S in its formats, and the
// colour tables beside NIfTI): what a report of that format lists among its outputs.
std::vector<std::string> labelMapFileNames(LabelMapFiles files);

// docs/QUALITY.md's targets the report holds a frame to: the whole body within 0.5 %, every label
// of >= 1000 voxels and every body part the posed mesh predicts within 1 %.
constexpr double kBodyTargetPercent = 0.5;
constexpr double kLabelTargetPercent = 1.0;
// Two rigid pieces may share at most this share of the smaller one's volume (at least one rest
// voxel's): a tenth of the label target, for two voxel staircases turned against each other at a
// joint.
constexpr double kCollisionAllowancePercent = 0.1;

// The exit status of `repose pose` and `repose sweep` when every frame was written but some
// missed a target (report.json's "targets"): scripts tell it from success (0), an error (1), a
// usage error (2), a sweep whose jobs failed (3) and a cancel (130).
constexpr int kExitTargetsMissed = 4;

struct PoseFrameOptions {
  const Volume* image = nullptr;  // on G's grid, posed alongside (trilinear)
  // The image's value where no tissue is; unset: imageBackground(*image).
  std::optional<double> background;
  const TissueTable* tissues = nullptr;  // densities and rigid labels; null: no masses
  std::string tissueTableName = "none";  // how the report names the table
  bool fillPockets = true;               // docs/QUALITY.md
  // Each soft label of G rounded to the volume the deformation gives it, not left to
  // nearest-neighbour sampling (RasterOptions::preserveLabelVolumes; docs/QUALITY.md). The
  // report then holds those labels' change itself to the target (no resampling floor off).
  bool preserveLabelVolumes = true;
  double spacingMm = 0;  // output voxel size; 0: the input's spacing
  int threads = 0;
  ProgressFn progress;  // rasterizing G (the long part); may cancel
  // Called with the output grid before anything is allocated for it: a memory budget's check
  // (throw to refuse the frame).
  std::function<void(const VolumeGeometry& grid)> checkGrid;
  // Called with each warning as soon as it is known, one line each, without the frame's name
  // (the front end says which frame): the body volume the posed mesh predicts beyond the target
  // (before rasterizing), rigid pieces run into each other, folds. The report's "warnings"
  // holds them too.
  std::function<void(const std::string&)> warn;
  // The rig's RigSettings::bonePieces: which labels of G a bone's one piece holds.
  std::map<int, int> bonePieces;
  // Labels the rig meshes as pieces that still bend where they cross a joint (labelsEncasedInBone:
  // the spinal cord, soft within kEncasedJointBandMm of another body part). The mesh poses them;
  // they are not rigid copies, so neither bones that may collide nor rigid labels for the pockets.
  std::vector<int> bendingPieces;
  LabelMapFiles labelMapFiles = LabelMapFiles::Nifti;  // what writePosedFrame writes
};

struct PosedFrame {
  std::string name;
  VolumeGeometry grid;
  Volume organs, parts;
  std::optional<Volume> image;
  std::vector<float> field;  // 3 floats a voxel, RAS mm from the voxel to its rest position
  std::string reportJson;    // the report.json object (the caller may add what it knows)
  LabelMapFiles labelMapFiles = LabelMapFiles::Nifti;  // its "outputs" name these files
};

// Bytes a posed frame holds per output voxel (G, S, image, field): budgets check this times the
// grid's voxels before posing.
double posedBytesPerVoxel(const Volume& organs, const Volume& parts, const Volume* image);

// The one memory rule of a pose job, for every front end: the posed volumes of a frame on `grid`
// (`bytesPerVoxel`, posedBytesPerVoxel) beside what the process holds now (its resident set)
// must fit in `budget` bytes (0: memoryBudgetByDefault(), half the physical memory). Otherwise
// throws one line: "<what> needs ... beyond the ... in use, more than the memory budget of ...
// (<hint>)", the hint saying where the front end sets the budget and how to pose out of core.
void checkFrameMemory(const VolumeGeometry& grid, double bytesPerVoxel, double budget,
                      const std::string& what, const std::string& hint);
// Whether checkFrameMemory would let the frame through.
bool frameFitsMemory(const VolumeGeometry& grid, double bytesPerVoxel, double budget);

// The value a posed image takes where no tissue is, unless the user gives one: the image's
// minimum, which is air in a CT (-1000 or -1024 HU) and the dark of an MR, so the body is not
// posed into water (0 HU). The same rule for every front end, the live slices and the export.
double imageBackground(const Volume& image);

// The frame `index` of the rig, posed. G and S are the rig's inputs at rest (S's labels name the
// parts). Throws repose::Error, or Cancelled when the progress callback says so.
PosedFrame poseFrame(const PoseRig& rig, std::size_t index, const Volume& organs,
                     const Volume& parts, const PoseFrameOptions& options = {});

// Writes the frame into `folder` (created; its parent must exist): posed_G and posed_S as
// frame.labelMapFiles says (posed_G.nii.gz + posed_G.ctbl, posed_G.seg.nrrd, all three, or
// posed_G.dcm),
// posed_image.nii.gz (with an image), transform.nrrd and report.json, as one unit: an error or an
// interrupt leaves the folder as it was. Files of ours an earlier run left there and this frame
// does not write (another label-map format, an image) are removed, so nothing stale remains.
std::string writePosedFrame(const PosedFrame& frame, const std::string& folder);
struct FrameWriteOptions {
  LabelMapFiles labelMapFiles = LabelMapFiles::Nifti;
  // With a rig kept in a scene folder: also scene.mrml, a 3D Slicer scene of the input label map,
  // the posed one, the field, the cage and the transfer mesh (pose/SlicerSceneMrml.h). Absolute
  // paths of G, the cage and the mesh; empty: no scene.mrml.
  std::string sceneInputLabels, sceneCage, sceneTransferMesh;
  // Hold the folder's FolderLock while the frame is written into an existing folder, so that a
  // `repose pose` writing there refuses, and this write refuses while one does (callers that
  // hold no lock of their own: Python, the workbench). The command line locks its --out for the
  // whole run instead.
  bool lockFolder = false;
  // DICOM SEG outputs: a DICOM file of the input (its SEG, or a slice of its series) whose
  // patient and study they take (dicomSourceOf); "": none.
  std::string sourceDicom;
};
// The same, with the label maps and the scene as `options` say (not frame.labelMapFiles).
// Both return report.json's text as written (its "outputs" name the files written).
std::string writePosedFrame(const PosedFrame& frame, const std::string& folder,
                            const FrameWriteOptions& options);

// Out of core (issue 56): the frame made slab by slab and written into `folder` as it goes, for
// a frame whose posed volumes do not fit in memory. The same files (voxel for voxel; the NIfTI,
// NRRD and segmentation files byte for byte) and the same report as poseFrame then
// writePosedFrame, plus report.json's "streamed" (the slabs). Holds the rest maps, the rig and
// slabs sized to `memoryBudget` bytes (0: memoryBudgetByDefault()) beside what the process
// holds; the label-volume rounding's candidates beyond a quarter of that go to a temporary file.
// `slabSlices` > 0 sets the slabs' thickness instead (tests cut a frame into slabs of a slice).
// A DICOM SEG is written in pieces too (DicomSegSlabWriter); one whose frames would pass the
// 4 GiB of pixel data DICOM holds is refused in one line before the work. Returns
// report.json's text as written. Throws repose::Error, or Cancelled from options.progress;
// nothing is written then. Over `ranks` (SlabRanks.h; null: this process alone) every rank calls
// it with the same arguments: the other ranks make the slabs, rank 0 writes the folder and returns
// the report (the others "").
std::string poseFrameToFolder(const PoseRig& rig, std::size_t index, const Volume& organs,
                              const Volume& parts, const PoseFrameOptions& options,
                              const std::string& folder, const FrameWriteOptions& write,
                              double memoryBudget = 0, std::int64_t slabSlices = 0,
                              SlabRanks* ranks = nullptr);

}  // namespace repose
