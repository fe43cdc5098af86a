// eq. 5-7. The rasterization visits each tet's bounding box of voxel centres and keeps those with
// all barycentric coordinates >= 0; it runs once per refinement step, not per frame.
#include "repose/mesh/ErrorMetric.h"

#include "repose/mesh/TetAdjacency.h"
#include "repose/util/Error.h"

#include <Eigen/LU>
#include <algorithm>
#include <cmath>

namespace repose {
namespace {

double volumeOf(const TransferMesh& mesh, Eigen::Index t) {
  Eigen::Matrix3d E;
  for (int c = 0; c < 3; ++c)
    E.col(c) =
        (mesh.vertices.row(mesh.tets(t, c + 1)) - mesh.vertices.row(mesh.tets(t, 0))).transpose();
  return std::fabs(E.determinant()) / 6;
}

}  // namespace

Eigen::VectorXd tetErrors(const TransferMesh& mesh, const std::vector<Eigen::Matrix3d>& B) {
  if (B.size() != static_cast<std::size_t>(mesh.tets.rows()))
    throw Error("tetErrors: one map per tet is needed");
  const TetAdjacency adjacency = TetAdjacency::build(mesh);
  Eigen::VectorXd volume(mesh.tets.rows());
  for (Eigen::Index t = 0; t < mesh.tets.rows(); ++t) volume[t] = volumeOf(mesh, t);
  Eigen::VectorXd e = Eigen::VectorXd::Zero(mesh.tets.rows());
  for (Eigen::Index t = 0; t < mesh.tets.rows(); ++t) {
    const auto& n = adjacency.faceNeighbours[t];
    if (n.empty()) continue;
    Eigen::Matrix3d mean = Eigen::Matrix3d::Zero();
    double total = 0;
    for (int u : n) mean += volume[u] * B[u], total += volume[u];
    e[t] = (B[t] - mean / total).norm();
  }
  return e;
}

Eigen::VectorXd vertexErrors(const TransferMesh& mesh, const Eigen::VectorXd& tetError) {
  Eigen::VectorXd sum = Eigen::VectorXd::Zero(mesh.vertices.rows()), weight = sum;
  for (Eigen::Index t = 0; t < mesh.tets.rows(); ++t) {
    const double v = volumeOf(mesh, t);
    for (int c = 0; c < 4; ++c)
      sum[mesh.tets(t, c)] += v * tetError[t], weight[mesh.tets(t, c)] += v;
  }
  return (weight.array() > 0).select(sum.array() / weight.array().max(1e-300), 0.0).matrix();
}

std::vector<float> rasterizeVertexField(const TransferMesh& mesh, const Eigen::VectorXd& values,
                                        const VolumeGeometry& grid, std::vector<char>* covered) {
  const auto& d = grid.dims;
  std::vector<float> out(static_cast<std::size_t>(grid.numVoxels()), 0.f);
  if (covered) covered->assign(out.size(), 0);
  const Eigen::Matrix3d toIndex = grid.ijkToRas.block<3, 3>(0, 0).inverse();
  const Eigen::Vector3d origin = grid.origin();
  for (Eigen::Index t = 0; t < mesh.tets.rows(); ++t) {
    Eigen::Vector3d p[4];
    for (int c = 0; c < 4; ++c)
      p[c] = toIndex * (mesh.vertices.row(mesh.tets(t, c)).transpose() - origin);
    Eigen::Matrix3d E;
    for (int c = 0; c < 3; ++c) E.col(c) = p[c + 1] - p[0];
    const double det = E.determinant();
    if (std::fabs(det) < 1e-12) continue;
    const Eigen::Matrix3d Einv = E.inverse();
    Eigen::Vector3d lo = p[0], hi = p[0];
    for (int c = 1; c < 4; ++c) lo = lo.cwiseMin(p[c]), hi = hi.cwiseMax(p[c]);
    std::int64_t a[3], b[3];
    for (int c = 0; c < 3; ++c) {
      a[c] = std::max<std::int64_t>(0, static_cast<std::int64_t>(std::ceil(lo[c] - 1e-9)));
      b[c] = std::min<std::int64_t>(d[c] - 1, static_cast<std::int64_t>(std::floor(hi[c] + 1e-9)));
    }
    const double f0 = values[mesh.tets(t, 0)], f1 = values[mesh.tets(t, 1)],
                 f2 = values[mesh.tets(t, 2)], f3 = values[mesh.tets(t, 3)];
    for (std::int64_t k = a[2]; k <= b[2]; ++k)
      for (std::int64_t j = a[1]; j <= b[1]; ++j)
        for (std::int64_t i = a[0]; i <= b[0]; ++i) {
          const Eigen::Vector3d l =
              Einv * (Eigen::Vector3d(double(i), double(j), double(k)) - p[0]);
          const double l0 = 1 - l.sum();
          if (l.minCoeff() < -1e-9 || l0 < -1e-9) continue;
          const std::size_t n = static_cast<std::size_t>(i + d[0] * (j + d[1] * k));
          out[n] = static_cast<float>(l0 * f0 + l[0] * f1 + l[1] * f2 + l[2] * f3);
          if (covered) (*covered)[n] = 1;
        }
  }
  return out;
}

double updateSizingField(SizingField& F, const std::vector<float>& errorGrid,
                         const std::vector<char>& covered) {
  if (errorGrid.size() != F.sizeMm.size() || covered.size() != F.sizeMm.size())
    throw Error("updateSizingField: the error grid must be the sizing field's grid");
  double sum = 0;
  std::size_t n = 0;
  for (std::size_t v = 0; v < covered.size(); ++v)
    if (covered[v]) sum += errorGrid[v], ++n;
  if (n == 0) throw Error("updateSizingField: no voxel is covered by the mesh");
  const double mean = sum / n;
  if (mean <= 0) return 0;  // an exact deformation: nothing to refine
  for (std::size_t v = 0; v < covered.size(); ++v)
    if (covered[v])
      F.sizeMm[v] =
          static_cast<float>(F.sizeMm[v] * std::cbrt(mean / std::max<double>(errorGrid[v], mean)));
  return mean;
}

}  // namespace repose
