// tetTissues: which labels of G each soft tet holds at rest (VolumeRestoration.h), counted at the
// voxel centres inside it, as the rasterizer's rest scan counts a label's deformation volume.
#include "repose/mesh/VolumeRestoration.h"

#include "repose/util/Parallel.h"

#include <Eigen/LU>

#include <algorithm>
#include <cmath>
#include <map>

namespace repose {

TetTissues tetTissues(const TransferMesh& mesh, const Volume& organs, int threads) {
  const Eigen::Index nt = mesh.tets.rows();
  const VolumeGeometry& g = organs.geometry();
  const auto& d = organs.dims();
  std::vector<std::vector<std::pair<int, int>>> per(static_cast<std::size_t>(nt));
  parallelFor(
      std::int64_t(nt), threads,
      [&](std::int64_t begin, std::int64_t end) {
        std::map<int, int> count;
        for (std::int64_t t = begin; t < end; ++t) {
          if (!mesh.rigid.empty() && mesh.rigid[std::size_t(t)]) continue;  // a piece: rigid
          // The tet in G's index space: corners and the barycentric map.
          Eigen::Vector3d c[4];
          Eigen::Vector3d lo = Eigen::Vector3d::Constant(1e300), hi = -lo;
          for (int k = 0; k < 4; ++k) {
            c[k] = g.rasToVoxel(mesh.vertices.row(mesh.tets(t, k)).transpose());
            lo = lo.cwiseMin(c[k]), hi = hi.cwiseMax(c[k]);
          }
          Eigen::Matrix3d E;
          for (int k = 0; k < 3; ++k) E.col(k) = c[k + 1] - c[0];
          if (std::fabs(E.determinant()) < 1e-12) continue;
          const Eigen::Matrix3d inverse = E.inverse();
          std::int64_t a[3], b[3];
          for (int w = 0; w < 3; ++w) {
            a[w] = std::max<std::int64_t>(0, std::int64_t(std::ceil(lo[w] - 1e-9)));
            b[w] = std::min<std::int64_t>(d[std::size_t(w)] - 1,
                                          std::int64_t(std::floor(hi[w] + 1e-9)));
          }
          count.clear();
          for (std::int64_t k = a[2]; k <= b[2]; ++k)
            for (std::int64_t j = a[1]; j <= b[1]; ++j)
              for (std::int64_t i = a[0]; i <= b[0]; ++i) {
                const Eigen::Vector3d l =
                    inverse * (Eigen::Vector3d(double(i), double(j), double(k)) - c[0]);
                if (l.minCoeff() < 0 || l.sum() > 1) continue;
                const double label = organs.valueAsDouble(organs.index(i, j, k));
                if (label > 0) ++count[int(label)];
              }
          per[std::size_t(t)].assign(count.begin(), count.end());
        }
      },
      256);
  TetTissues out;
  out.offsets.reserve(std::size_t(nt) + 1);
  out.offsets.push_back(0);
  for (const auto& list : per) {
    out.entries.insert(out.entries.end(), list.begin(), list.end());
    out.offsets.push_back(int(out.entries.size()));
  }
  return out;
}

}  // namespace repose
