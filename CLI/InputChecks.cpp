#include "InputChecks.h"

#include "repose/util/Error.h"
#include "repose/volume/LabelStatistics.h"

#include <iostream>

namespace repose::cli {

void requirePoseableLabels(const Volume& volume, const std::string& path) {
  if (!isIntegerType(volume.scalarType()))
    throwFileError(path, "not a label map (float voxels); pose images with --image");
  volume.geometry().requireOrthogonalAxes(path);
  if (countLabels(volume).empty())
    throwFileError(path, "the segmentation is empty: every voxel is 0, there is no body to pose");
}

void warnUnnamedLabels(const Volume& volume, const std::string& path, const std::string& command) {
  std::vector<int> values;
  for (const LabelCount& c : unnamedLabels(volume)) values.push_back(c.value);
  warnUnnamedLabels(values, path, command);
}

void warnUnnamedLabels(const std::vector<int>& unnamed, const std::string& path,
                       const std::string& command) {
  if (unnamed.empty()) return;
  std::string list;
  for (std::size_t i = 0; i < unnamed.size() && i < 10; ++i)
    list += (i ? ", " : "") + std::to_string(unnamed[i]);
  if (unnamed.size() > 10) list += " and " + std::to_string(unnamed.size() - 10) + " more";
  std::cerr << "repose " << command << ": warning: " << path << ": label"
            << (unnamed.size() > 1 ? "s " : " ") << list << (unnamed.size() > 1 ? " have" : " has")
            << " voxels but no name in its label table; posed like the others, reported by value\n";
}

}  // namespace repose::cli
