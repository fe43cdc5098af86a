// How far a posed frame's pieces and shell write beyond its tets: the scan's reaches, which the
// DICOM SEG estimate (pose/FrameDicomSegEstimate.cpp) bounds a frame's segments with before the
// work, as the scan itself (raster/RasterScan.h) writes them.
#pragma once

#include "repose/mesh/TransferMesh.h"
#include "repose/raster/Rasterizer.h"
#include "repose/volume/Volume.h"

namespace repose::raster {

// How far beyond its tets a whole piece writes its rim and ghosts (mm): the larger of the input's
// voxel size and the one the mesh was made from (Mesh_3 puts a piece's surface that close).
double pieceReachMm(const TransferMesh& mesh, const VolumeGeometry& input);
// The shell's width (mm): options.shellMm, or when it is < 0 twice pieceReachMm.
double shellWidthMm(const TransferMesh& mesh, const VolumeGeometry& input,
                    const RasterOptions& options);

}  // namespace repose::raster
