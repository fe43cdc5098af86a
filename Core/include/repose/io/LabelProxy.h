// The working copy of a label map too large for memory (out-of-core interaction, seed §4.3):
// read through a SliceCache and downsampled by a whole factor per axis, each proxy voxel taking
// the most frequent label of its block. The cage and the transfer mesh are built on it; the
// full-resolution output is still rasterized from the original file.
#pragma once

#include "repose/io/SliceCache.h"
#include "repose/volume/Volume.h"

#include <array>
#include <string>

namespace repose {

// The smallest whole factor (the same on every axis) that brings `voxels` of `bytesPerVoxel`
// down to at most `bytes`.
int proxyFactor(std::int64_t voxels, std::size_t bytesPerVoxel, double bytes);

// Mode of each factor^3 block (blocks at the far edges may be partial). Ties go to the smaller
// non-zero label, so thin tissue is not lost to background on a tie. The proxy's voxel centres
// are the blocks' centres; its label table is the source's. Throws for float voxels.
Volume labelModeProxy(SliceCache& source, int factor, const ProgressFn& progress = {});

}  // namespace repose
