// The mesh is mapped into continuous voxel index space, where every row (j, k) is the line
// y = j, z = k. Each triangle adds +-1 to the voxels of a row that lie before its crossing point
// (sign from the normal's x component); a running sum gives the winding number.
#include "repose/cage/GridWinding.h"

#include "repose/util/Parallel.h"

#include <Eigen/LU>
#include <algorithm>
#include <cmath>

namespace repose {

std::vector<std::int8_t> windingNumbersOnGrid(const TriangleMesh& mesh, const VolumeGeometry& grid,
                                              int threads) {
  const auto& d = grid.dims;
  std::vector<std::int8_t> out(static_cast<std::size_t>(grid.numVoxels()), 0);
  const Eigen::Matrix3d toIndex = grid.ijkToRas.block<3, 3>(0, 0).inverse();
  const Eigen::Vector3d origin = grid.origin();
  // An affine map with negative determinant mirrors space and flips every winding number.
  const int mirror = toIndex.determinant() < 0 ? -1 : 1;
  // Rows are shifted by an irrational fraction so no row passes exactly through an edge or a
  // vertex of the mesh, whose coordinates are often on the voxel lattice.
  const double dy = 1.3e-7 * std::sqrt(2.0), dz = 1.1e-7 * std::sqrt(3.0);
  Eigen::MatrixX3d v(mesh.vertices.rows(), 3);
  for (Eigen::Index i = 0; i < v.rows(); ++i)
    v.row(i) = (toIndex * (mesh.vertices.row(i).transpose() - origin)).transpose() -
               Eigen::RowVector3d(0, dy, dz);

  // Bucket triangles by the k rows their z-range covers, so each slab of rows visits only its own.
  std::vector<std::vector<Eigen::Index>> byK(static_cast<std::size_t>(d[2]));
  for (Eigen::Index f = 0; f < mesh.faces.rows(); ++f) {
    double lo = 1e300, hi = -1e300;
    for (int c = 0; c < 3; ++c)
      lo = std::min(lo, v(mesh.faces(f, c), 2)), hi = std::max(hi, v(mesh.faces(f, c), 2));
    const std::int64_t k0 = std::max<std::int64_t>(0, static_cast<std::int64_t>(std::ceil(lo)));
    const std::int64_t k1 =
        std::min<std::int64_t>(d[2] - 1, static_cast<std::int64_t>(std::floor(hi)));
    for (std::int64_t k = k0; k <= k1; ++k) byK[k].push_back(f);
  }

  parallelFor(
      d[2], threads,
      [&](std::int64_t kBegin, std::int64_t kEnd) {
        std::vector<int> delta(static_cast<std::size_t>(d[0]) + 1);
        for (std::int64_t k = kBegin; k < kEnd; ++k) {
          for (std::int64_t j = 0; j < d[1]; ++j) {
            std::fill(delta.begin(), delta.end(), 0);
            int before = 0;  // crossings at x < 0: they add to no voxel
            bool any = false;
            for (Eigen::Index f : byK[k]) {
              const Eigen::Vector3d a = v.row(mesh.faces(f, 0)), b = v.row(mesh.faces(f, 1)),
                                    c = v.row(mesh.faces(f, 2));
              // Barycentric coordinates of (y, z) = (j, k) in the triangle's (y, z) projection.
              const double det =
                  (b.y() - a.y()) * (c.z() - a.z()) - (c.y() - a.y()) * (b.z() - a.z());
              if (det == 0) continue;  // edge-on to the row direction: no crossing
              const double py = j - a.y(), pz = k - a.z();
              const double s = (py * (c.z() - a.z()) - (c.y() - a.y()) * pz) / det;
              const double t = ((b.y() - a.y()) * pz - py * (b.z() - a.z())) / det;
              if (s < 0 || t < 0 || s + t > 1) continue;
              const double x = a.x() + s * (b.x() - a.x()) + t * (c.x() - a.x());
              // det > 0 means the normal's x component is positive: leaving the inside towards +x.
              const int sign = det > 0 ? 1 : -1;
              // Voxels i < x see this crossing ahead of them on the +x ray.
              const std::int64_t upto = static_cast<std::int64_t>(std::ceil(x));  // first i >= x
              if (upto <= 0) continue;
              any = true;
              if (upto >= d[0])
                before += sign;
              else
                delta[static_cast<std::size_t>(upto)] -= sign, before += sign;
            }
            if (!any) continue;
            std::int8_t* row = out.data() + d[0] * (j + d[1] * k);
            int w = before;
            for (std::int64_t i = 0; i < d[0]; ++i) {
              w += delta[static_cast<std::size_t>(i)];
              row[i] = static_cast<std::int8_t>(std::clamp(mirror * w, -127, 127));
            }
          }
        }
      },
      1);
  return out;
}

}  // namespace repose
