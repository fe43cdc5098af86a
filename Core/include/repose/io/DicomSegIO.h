// DICOM Segmentation objects (SEG: one multi-frame file, BINARY or FRACTIONAL, one or more
// segments with coded terminology) through DCMTK. docs/FORMATS.md has the mapping.
#pragma once

#include "repose/io/VolumeIO.h"

#include <cstdint>
#include <memory>
#include <optional>
#include <string>

namespace repose {

// True when the file is DICOM with the Segmentation Storage SOP class.
bool isDicomSegFile(const std::string& path);

// The one DICOM SEG file among a folder's files (not its subfolders); nothing when there is none.
// Throws naming the folder when it holds several.
std::optional<std::string> findDicomSegInFolder(const std::string& folder);

// A SEG as a label map: each segment a label whose value is its segment number (or, in a SEG
// Repose wrote, the value and layer it had), with its name,
// colour (RecommendedDisplayCIELabValue) and terminology (Label::tags, SegmentTerminology.h).
// Frames are placed by their plane position and orientation on the grid of the series the SEG
// references, when that series is in the SEG's folder or one of its subfolders, else on the
// grid its frames span. Segments that overlap go to further layers, as in .seg.nrrd. A
// FRACTIONAL SEG is thresholded at half its maximum value (said through options.note).
// Throws repose::Error naming the file for a truncated or inconsistent SEG.
Volume readDicomSeg(const std::string& path, const ReadOptions& options = {});

// A SEG's frames are native pixel data: at most this many bytes (a 32-bit even length), 4 GiB.
constexpr std::int64_t kDicomSegPixelDataBytes = 0xFFFFFFFE;

struct DicomSegWriteOptions {
  // A DICOM file (a slice of the input series, or the input SEG) whose patient and study the SEG
  // takes; "": none (they stay empty).
  std::string sourceDicom;
  std::string description = "Repose segmentation";  // SeriesDescription and ContentDescription
  std::string seriesNumber = "1";
  ProgressFn progress;
};

// Writes a label map as a BINARY DICOM SEG, atomically: one segment per label of the table and
// per value present (layers included), named, coloured (CIELab) and coded from Label::tags
// (SCT "Tissue" when it has no terminology); one frame per segment and slice where it has voxels,
// and an empty frame for a slice or a segment with none, so reading it back gives the same grid,
// labels and voxels. A new frame of reference, series and instance; no derivation references:
// the label map is a new geometry. Throws repose::Error naming the file for what DICOM cannot
// hold (rows or columns over 65535, a sheared or left-handed grid, over 65535 labels, frames
// beyond native pixel data's 4 GiB). Written through DicomSegSlabWriter: the frames' bits go to
// a temporary file beside the output, not to memory.
void writeDicomSeg(const Volume& volume, const std::string& path,
                   const DicomSegWriteOptions& options = {});

// The same file written slice by slice (k slabs in order), for a label map larger than memory:
// the frames' bits go to a temporary file as the slices come, and each frame's slice, layer and
// value (12 bytes) stay in memory; the header (its segments: the table's labels and the values
// met) and the frames' functional groups are written at finish(). Atomic: nothing appears at
// `path` until finish(). The bytes are writeDicomSeg's but for the new UIDs and dates.
class DicomSegSlabWriter {
 public:
  // Throws naming `path` for a grid or type a SEG cannot hold (see writeDicomSeg).
  DicomSegSlabWriter(const std::string& path, const VolumeGeometry& geometry, ScalarType type,
                     int layers, const LabelTable& labels,
                     const DicomSegWriteOptions& options = {});
  ~DicomSegSlabWriter();
  // `slices` whole k-slices where the last call ended: each layer's slices together, layer after
  // layer (as LabelSlabs writes a slab). Throws naming `path` once the frames pass 4 GiB.
  void writeSlices(const void* data, std::int64_t slices);
  void finish();  // throws unless every slice was written

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace repose
