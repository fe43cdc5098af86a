// A DICOM image series (one folder) through GDCM, compressed transfer syntaxes (JPEG 2000
// lossless, ...) included. Slices sorted along their normal; geometry from IPP/IOP in LPS.
#pragma once

#include "repose/io/VolumeIO.h"

#include <optional>

namespace repose {

// Reads the single series in folder (or the series with the most slices if several, named in
// the error if they cannot be told apart). Rescale slope/intercept applied (int16 or float32).
Volume readDicomSeries(const std::string& folder, const ReadOptions& options = {});

// The grid of the series with this SeriesInstanceUID among the slices in folder (not its
// subfolders), without reading its pixels: what a DICOM SEG that references the series is placed
// on. Nothing when the folder holds no slice of it; throws naming the file when its slices do not
// make one grid.
std::optional<VolumeGeometry> findDicomSeriesGeometry(const std::string& folder,
                                                      const std::string& seriesUid);

}  // namespace repose
