// The seed's deformation-driven error metric (eq. 5-7): per-tet error |dB_t|, per-vertex mean,
// rasterized onto the sizing field's grid, and the sizing-field update that refines where the
// piecewise-linear transfer mesh approximates the deformation worst.
#pragma once

#include "repose/mesh/TransferMesh.h"

#include <Eigen/Core>
#include <vector>

namespace repose {

// eq. 1 and 5: e_t = |B_t - (volume-weighted mean of B over T1(t))|_F; 0 for a tet with no
// face neighbour. B: one 3x3 map per tet (as RigiditySolver::solve returns them).
Eigen::VectorXd tetErrors(const TransferMesh& mesh, const std::vector<Eigen::Matrix3d>& B);

// eq. 6: e_v = volume-weighted mean of e_t over the tets around v (0 for an unused vertex).
Eigen::VectorXd vertexErrors(const TransferMesh& mesh, const Eigen::VectorXd& tetError);

// Scan-converts every rest tet onto `grid`, interpolating the per-vertex values barycentrically
// at voxel centres. covered (optional) marks the voxels inside some tet; others get 0.
std::vector<float> rasterizeVertexField(const TransferMesh& mesh, const Eigen::VectorXd& values,
                                        const VolumeGeometry& grid,
                                        std::vector<char>* covered = nullptr);

// eq. 7: F[v] *= cbrt(e_mean / max(e^G[v], e_mean)) over covered voxels, e_mean their mean
// error. errorGrid and covered are on F's grid. Returns e_mean.
double updateSizingField(SizingField& F, const std::vector<float>& errorGrid,
                         const std::vector<char>& covered);

}  // namespace repose
