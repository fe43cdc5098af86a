// The tissues each soft tet carries at rest, as the rasterizer's rest scan assigns G's voxels to
// tets: the voxel centres inside a tet, and beyond the mesh's outer faces the shell's voxels
// (RasterOptions::shellMm) of the tet whose shell takes them. The label rounding sums each
// label's deformation volume over exactly these voxels (raster/LabelVolumeRounding.h), so the
// volume restoration, holding each tissue's volume over them, holds what the rounding will ask
// for. Counted at the centres alone, a skin one voxel thick on 8 mm slices lay mostly in the
// shell: the restoration held a fraction of it while the rounding's target grew with the outer
// tets a raised arm stretched (+4.8 % on the ICRP grid with the hands 2 mm from the thighs).
#pragma once

#include "repose/mesh/VolumeRestoration.h"
#include "repose/raster/Rasterizer.h"
#include "repose/volume/Volume.h"

namespace repose {

// `organs` (G) and the mesh at rest in the same RAS space; `options`: threads, shellMm,
// outerFaces and restParts (S at rest, on G's grid), as the frame's label scan is given them.
// Whole pieces' tets carry none (they are rigid).
TetTissues restTetTissues(const TransferMesh& mesh, const Volume& organs,
                          const RasterOptions& options);

}  // namespace repose
