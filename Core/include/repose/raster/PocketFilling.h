// Background pockets a pose makes inside the body, filled from their neighbours.
//
// Where a joint bends far (a 90° elbow), the skin of the two sides meets in the crease and the
// deformed transfer mesh folds: the posed map then holds a few enclosed background voxels that
// the rest body did not have — outside air trapped in the crease, or gaps no deformed tet covers.
// For a field solver both are air pockets inside tissue that no anatomy has. A posed background
// voxel that no background path joins to the grid's border is filled when it comes from the
// outside of the rest body (its rest position, through the inverse map, is background joined to
// the rest grid's border) or from nowhere (no tet covers it); background that comes from a cavity
// of the rest body (enclosed there too) is kept. Filled voxels take the most common non-zero
// label among their 6 neighbours, layer by layer from the pocket's wall inwards.
#pragma once

#include "repose/volume/Volume.h"

#include <cstdint>
#include <vector>

namespace repose {

struct PocketReport {
  std::int64_t filled = 0;        // voxels given a tissue label
  std::int64_t keptCavities = 0;  // enclosed background voxels that come from rest cavities
};

// posedLabels: the posed label map (layer 0 is examined and filled). restLabels: the rest map it
// was posed from. displacement: the inverse map on the posed grid, as rasterizeDisplacement
// gives it (3 floats per voxel, RAS mm to the rest position). posedParts, when given, is filled in
// the same voxels with its own neighbours' labels.
PocketReport fillPosePockets(Volume& posedLabels, const Volume& restLabels,
                             const std::vector<float>& displacement, Volume* posedParts = nullptr);

}  // namespace repose
