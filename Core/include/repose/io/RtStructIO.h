// DICOM RT Structure Sets (RTSTRUCT: each ROI as planar contours in patient mm) rasterized to a
// label map, through DCMTK's dcmdata. docs/FORMATS.md has the rules.
#pragma once

#include "repose/io/VolumeIO.h"

#include <optional>
#include <string>

namespace repose {

struct RtStructOptions {
  // The grid: an image's (any file or DICOM folder readVolume takes; a DICOM folder must hold
  // the series the structure set references) ...
  std::string reference;
  // ... or, with no reference, a grid spanning the contours with voxels of this size (mm): rows
  // and columns in the contours' plane, slices along its normal from the lowest contour plane.
  double spacingMm = 0;
  ProgressFn progress;
  double memoryLimitBytes = 0;  // as ReadOptions
  std::function<void(const std::string&)> note;
};

// True when the file is DICOM with the RT Structure Set Storage SOP class.
bool isRtStructFile(const std::string& path);

// Each ROI becomes a label: value = its ROI Number (or its position when the numbers are not
// distinct and in 1..65535), name = ROI Name, colour = ROI Display Color. A voxel belongs to an
// ROI when its centre is inside the ROI's contours on the slice's plane, by the even-odd rule
// (a contour inside another is a hole). Each slice takes the contours of the ROI's nearest
// contour plane within half the contours' plane spacing, so a grid finer than the contours is
// filled between them. ROIs that overlap go to separate layers. Throws repose::Error naming the
// file for a broken structure set (a contour with fewer than three points, one not in a plane of
// the grid's slices, an ROI contour naming no ROI, a reference that is another series).
Volume readRtStruct(const std::string& path, const RtStructOptions& options);

}  // namespace repose
