// Checks of input volumes shared by the commands that pose: one line naming the file for what
// cannot be posed, a warning for what can but may surprise.
#pragma once

#include "repose/volume/Volume.h"

#include <string>
#include <vector>

namespace repose::cli {

// A label map a rig is built from or posed: integer voxels, at least one non-zero voxel, and
// orthogonal voxel axes. Throws repose::Error naming `path`.
void requirePoseableLabels(const Volume& volume, const std::string& path);

// "warning: <path>: labels 7, 9 have voxels but no name in its label table" on stderr.
void warnUnnamedLabels(const Volume& volume, const std::string& path, const std::string& command);
// The same for label values already counted (warp's out-of-core path never holds the volume).
void warnUnnamedLabels(const std::vector<int>& values, const std::string& path,
                       const std::string& command);

}  // namespace repose::cli
