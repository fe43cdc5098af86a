// Winding number of a closed triangle mesh at every voxel centre of a grid, by signed ray
// crossings along the grid's i rows: O(voxels + crossings), millions of voxels per second.
#pragma once

#include "repose/cage/TriangleMesh.h"
#include "repose/volume/VolumeGeometry.h"

#include <cstdint>
#include <vector>

namespace repose {

// Integer winding number per voxel (i fastest), exact for closed meshes at voxel centres off the
// surface: 1 inside an outward-oriented mesh, 0 outside, -1 inside an inward-oriented one.
// Mesh in RAS mm; the grid may be oblique.
std::vector<std::int8_t> windingNumbersOnGrid(const TriangleMesh& mesh, const VolumeGeometry& grid,
                                              int threads = 0);

}  // namespace repose
