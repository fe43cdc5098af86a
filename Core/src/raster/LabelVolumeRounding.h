// Volume-preserving rounding of a posed label map (RasterOptions::preserveLabelVolumes).
//
// Nearest-neighbour sampling decides each output voxel by the one rest voxel its centre maps to.
// For a structure one or two voxels across, turned onto a grid of other spacing (an arm's vessel
// raised from 4.8 mm slices into the 1.8 mm plane), that decision alone moves the label's voxel
// count by several percent either way, whatever the deformation does (docs/QUALITY.md, the
// resampling floor). The deformation itself gives each label a volume: the sum over its rest
// voxels of det B_t of the tet carrying them. This step relabels voxels on the borders between
// soft labels so each label's count comes to that volume, choosing first the voxels whose rest
// position lies most in the label they go to (its trilinear weight there against the sampled
// label's).
#pragma once

#include <cstdint>
#include <vector>

namespace repose::raster {

struct RoundingCandidate {
  std::int64_t voxel = 0;  // output voxel index
  std::int32_t from = 0;   // its sampled label
  std::int32_t to = 0;     // the neighbouring label it may take
  float score = 0;         // trilinear weight of `to` minus that of `from` at its rest position
};

// Chooses, from `candidates`, the relabellings that bring the counts towards `target` (per label
// value, in output voxels; `count` the sampled counts, updated): best score first, each taken when
// it lowers the sum over labels of ((target - count) / target)^2, the relative misfit, so a
// vessel's few voxels weigh as much as a muscle's many. Each voxel has one candidate. Returns
// the indices into `candidates` taken, in the order taken. Deterministic: ties in score go by
// voxel index.
std::vector<std::size_t> chooseVolumeRounding(std::vector<RoundingCandidate>& candidates,
                                              const std::vector<double>& target,
                                              std::vector<double>& count);

}  // namespace repose::raster
