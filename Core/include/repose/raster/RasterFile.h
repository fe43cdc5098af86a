// The rasterizer's labels written to a file slab by slab: the out-of-core path of `repose warp`.
// Kept apart from the rasterizer so that the scan itself knows no file format (the folders form a
// ladder, docs/ARCHITECTURE.md): this unit joins the raster step to io's NIfTI slab writer.
#pragma once

#include "repose/raster/Rasterizer.h"

#include <cstddef>
#include <string>

namespace repose {

// Out of core: the same labels, voxel for voxel, for an input read in place through `input` and an
// output written slab by slab to the NIfTI file `path` (.nii or .nii.gz; atomic), holding at most
// `slabBytes` of output at a time. The scan runs on one thread (the cache is not shared).
void rasterizeLabelsToFile(SliceCache& input, const TransferMesh& mesh,
                           const Eigen::MatrixX3d& deformed, const VolumeGeometry& output,
                           const std::string& path, std::size_t slabBytes,
                           const RasterOptions& options = {}, RasterReport* report = nullptr);

}  // namespace repose
