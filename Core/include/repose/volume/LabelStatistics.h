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

}  // namespace repose
