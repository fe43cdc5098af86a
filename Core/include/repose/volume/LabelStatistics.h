// Per-label voxel counts and volumes of a label map, per layer, for `repose info` and reports.
#pragma once

#include "repose/volume/Volume.h"

#include <cstdint>
#include <vector>

namespace repose {

struct LabelCount {
  int layer = 0;
  int value = 0;
  std::int64_t voxels = 0;
  double volumeMm3 = 0;
};

// Every non-zero value present, sorted by (layer, value). Throws for float volumes.
std::vector<LabelCount> countLabels(const Volume& volume);

// Labels present in the voxels that the volume's label table does not name, when it has a table
// (a file edited by another tool, a segment deleted but its voxels kept): they are posed like
// any other, but reports and tissue tables cannot name them, so commands warn.
std::vector<LabelCount> unnamedLabels(const Volume& volume);

// Per voxel of layer 0: 1 where the value is 0 and a 6-connected path of zeros reaches the
// grid's border (the outside), else 0. Throws for float volumes.
std::vector<char> outsideBackground(const Volume& volume);

// Background (0) voxels of layer 0 that no 6-connected path of background joins to the grid's
// border: holes inside the body. A pose must not create new ones. Throws for float volumes.
std::int64_t countEnclosedBackground(const Volume& volume);

}  // namespace repose
