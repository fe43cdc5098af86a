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
// label among their 6 neighbours, layer by layer from the pocket's wall inwards; a rigid label
// (a bone, whose count is exact in every posture) only where no other label reaches the pocket:
// a gap opened between a bone and its neighbour is soft tissue.
#pragma once

#include "repose/volume/Volume.h"

#include <cstdint>
#include <functional>
#include <memory>
#include <vector>

namespace repose {

struct PocketReport {
  std::int64_t filled = 0;        // voxels given a tissue label
  std::int64_t keptCavities = 0;  // enclosed background voxels that come from rest cavities
};

// posedLabels: the posed label map (layer 0 is examined and filled). restLabels: the rest map it
// was posed from. displacement: the inverse map on the posed grid, as rasterizeDisplacement
// gives it (3 floats per voxel, RAS mm to the rest position). posedParts, when given, is filled in
// the same voxels with its own neighbours' labels. rigidLabels: G's labels a pocket takes only
// when no other label walls it.
PocketReport fillPosePockets(Volume& posedLabels, const Volume& restLabels,
                             const std::vector<float>& displacement, Volume* posedParts = nullptr,
                             const std::vector<int>& rigidLabels = {});

// The same for a frame made slab by slab (fillPosePockets is this over one slab): pass 1 traces
// the posed background slab by slab (BackgroundTrace.h) and notes, for each voxel not yet known to
// be outside, where it comes from and its walls' labels; fill() then fills the enclosed ones from
// their walls, and pass 2 writes them into each slab. Memory follows the holes, not the grid.
class PosePockets {
 public:
  // `rest`: G at rest (integer, layer 0 examined); `posed`: the posed grid. Both are kept.
  // `rigidLabels`: G's labels a pocket takes only when no other label walls it.
  PosePockets(const Volume& rest, const VolumeGeometry& posed,
              const std::vector<int>& rigidLabels = {});
  ~PosePockets();
  PosePockets(const PosePockets&) = delete;
  PosePockets& operator=(const PosePockets&) = delete;

  // Pass 1, slabs in order from slice 0: slices [k0, k1) of the posed G (the rest map's type)
  // as sampled, with the slices k0 - 1 and k1 (null at the grid's faces); the posed S likewise
  // when it is filled too (`parts` null: not), of type `partsType`; and the slab's displacement
  // field (3 floats per voxel, rasterizeDisplacement's).
  void addSlab(std::int64_t k0, std::int64_t k1, const void* organsBelow, const void* organs,
               const void* organsAbove, const void* partsBelow, const void* parts,
               const void* partsAbove, ScalarType partsType, const float* field);
  // After the last slab: fills the pockets. `finalOrgan(voxel, sampled)` is the label a voxel of
  // G ends with where it was sampled as `sampled` (label-volume rounding may relabel it; null:
  // as sampled); S's walls are as sampled.
  PocketReport fill(const std::function<std::int64_t(std::int64_t, std::int64_t)>& finalOrgan = {});
  // Pass 2: writes the filled labels of slices [k0, k1) into the slabs (`parts` null: G only).
  void apply(std::int64_t k0, std::int64_t k1, void* organs, void* parts) const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace repose
