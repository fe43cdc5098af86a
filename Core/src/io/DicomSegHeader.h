// The part of a DICOM SEG that DCMTK's dcmseg builds and checks: patient, study, series,
// equipment, frame of reference, the segments (names, colours, codes, Repose's value and layer),
// the shared functional groups and the dimensions. The frames (their functional groups and their
// bits) are not in it: DicomSegWrite.cpp streams them after it, so a SEG larger than memory can
// be written (issue 56).
#pragma once

#include "repose/io/DicomSegIO.h"
#include "repose/volume/LabelTable.h"
#include "repose/volume/VolumeGeometry.h"

#include <Eigen/Core>

#include <cstdint>
#include <string>
#include <vector>

class DcmFileFormat;

namespace repose::io {

// A DS value: at most 16 characters (PS3.5 6.2). Throws naming `path` for one that cannot fit.
std::string dicomDecimal(const std::string& path, double v);

// The frames' plane of `grid` in LPS: ijk to LPS, and the unit directions along a row (i) and a
// column (j). Throws naming `path` unless a SEG can hold frames of its slices: rows and columns
// within 65535, slices stacked along the normal of their rows and columns.
struct DicomSegPlane {
  Eigen::Matrix4d lps;
  Eigen::Vector3d row, column;
};
DicomSegPlane dicomSegPlane(const std::string& path, const VolumeGeometry& grid);

// The SEG's dataset for `segments` (in (layer, value) order: segment n is segments[n - 1]) on
// `grid`, with NumberOfFrames `frames` and neither PerFrameFunctionalGroupsSequence nor
// PixelData: both come after everything else in the file, and the caller appends them.
void makeDicomSegHeader(DcmFileFormat& file, const std::string& path, const VolumeGeometry& grid,
                        const std::vector<Label>& segments, std::int64_t frames,
                        const DicomSegWriteOptions& options);

}  // namespace repose::io
