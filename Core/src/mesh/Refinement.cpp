// The refinement loop; each step rebuilds the mesh from the updated field (CGAL Mesh_3 takes a
// field, not a mesh to split), re-embeds it and measures the metric for the same pose.
#include "repose/mesh/Refinement.h"

#include "repose/mesh/ErrorMetric.h"
#include "repose/util/Error.h"

#include <algorithm>
#include <cmath>

namespace repose {

SizingField initialSizingField(const Volume& parts, double sizeMm) {
  const VolumeGeometry& g = parts.geometry();
  std::int64_t factor = 1;
  while (g.numVoxels() / (factor * factor * factor) > 8'000'000) ++factor;
  VolumeGeometry coarse;
  for (int c = 0; c < 3; ++c) coarse.dims[c] = (g.dims[c] + factor - 1) / factor;
  coarse.ijkToRas = g.ijkToRas;
  coarse.ijkToRas.block<3, 3>(0, 0) *= static_cast<double>(factor);
  // Coarse voxel centres sit at the centre of their block of fine voxels.
  const double shift = (factor - 1) / 2.0;
  coarse.ijkToRas.block<3, 1>(0, 3) = g.voxelToRas(shift, shift, shift);
  if (sizeMm <= 0) {
    const auto [lo, hi] = g.rasBounds();
    sizeMm = 0.05 * (hi - lo).norm();
  }
  return SizingField::uniform(coarse, sizeMm);
}

RefinementStep measureDeformationError(const TransferMesh& mesh, const TriangleMesh& cage,
                                       const Eigen::MatrixX3d& deformedCage,
                                       const VolumeGeometry& grid, int threads,
                                       std::vector<float>* errorGrid, std::vector<char>* covered) {
  const CageDeformation deformation(mesh, cage, threads);
  std::vector<Eigen::Matrix3d> B;
  deformation.deform(deformedCage, &B);
  const Eigen::VectorXd et = tetErrors(mesh, B);
  std::vector<char> inside;
  const std::vector<float> values =
      rasterizeVertexField(mesh, vertexErrors(mesh, et), grid, &inside);
  RefinementStep step;
  step.vertices = static_cast<int>(mesh.vertices.rows());
  step.tets = static_cast<int>(mesh.tets.rows());
  step.maxTetError = et.size() ? et.maxCoeff() : 0;
  double sum = 0;
  std::int64_t n = 0;
  for (std::size_t v = 0; v < values.size(); ++v)
    if (inside[v])
      step.maxError = std::max(step.maxError, double(values[v])), sum += values[v], ++n;
  step.meanError = n ? sum / n : 0;
  if (errorGrid) *errorGrid = values;
  if (covered) *covered = std::move(inside);
  return step;
}

RefinementResult refineTransferMesh(const Volume& parts, const TriangleMesh& cage,
                                    const Eigen::MatrixX3d& deformedCage,
                                    const RefinementOptions& options) {
  RefinementResult result;
  SizingField field = initialSizingField(parts, options.initialSizeMm);
  for (int it = 0; it < options.maxIterations; ++it) {
    reportProgress(options.progress, double(it) / options.maxIterations, "refinement");
    TransferMeshOptions tmo;
    tmo.sizing = &field;
    tmo.rigidTissue = options.rigidTissue;
    TransferMesh mesh = buildTransferMesh(parts, tmo);
    if (mesh.vertices.rows() > options.maxVertices && it > 0)
      break;  // keep the last mesh in budget
    std::vector<float> grid;
    std::vector<char> covered;
    RefinementStep step = measureDeformationError(mesh, cage, deformedCage, field.grid,
                                                  options.threads, &grid, &covered);
    // The result always pairs a mesh with the field that built it; the update is for the next step.
    result.mesh = std::move(mesh);
    result.sizing = field;
    step.meanError = updateSizingField(field, grid, covered);
    result.steps.push_back(step);
    if (step.meanError <= 0 || step.maxError <= options.uniformity * step.meanError) break;
  }
  reportProgress(options.progress, 1.0, "refinement");
  return result;
}

}  // namespace repose
