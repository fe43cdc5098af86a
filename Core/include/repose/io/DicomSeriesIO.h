// A DICOM image series (one folder) through GDCM, compressed transfer syntaxes (JPEG 2000
// lossless, ...) included. Slices sorted along their normal; geometry from IPP/IOP in LPS.
#pragma once

#include "repose/io/VolumeIO.h"

namespace repose {

// Reads the single series in folder (or the series with the most slices if several, named in
// the error if they cannot be told apart). Rescale slope/intercept applied (int16 or float32).
Volume readDicomSeries(const std::string& folder, const ReadOptions& options = {});

}  // namespace repose
