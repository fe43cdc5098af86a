// The command line's side of the input checks: Core's one poseable rule (pose/PoseRun.h) for
// every front end, and its unnamed-label warning said on stderr as the commands say warnings.
#pragma once

#include "repose/pose/PoseRun.h"
#include "repose/volume/Volume.h"

#include <string>
#include <vector>

namespace repose::cli {

using repose::requirePoseableLabels;

// "repose <command>: warning: <path>: labels 7, 9 have voxels but no name ..." on stderr.
void warnUnnamedLabels(const Volume& volume, const std::string& path, const std::string& command);
// The same for label values already counted (warp's out-of-core path never holds the volume).
void warnUnnamedLabels(const std::vector<int>& values, const std::string& path,
                       const std::string& command);

}  // namespace repose::cli
