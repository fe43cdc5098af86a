// Winding number as the sum of signed solid angles of the faces (Van Oosterom & Strackee),
// divided by 4 pi; exact for closed meshes and well-behaved near the surface.
#include "repose/cage/WindingNumber.h"

#include "repose/util/Parallel.h"

#include <Eigen/Geometry>
#include <cmath>

namespace repose {

Eigen::VectorXd windingNumbers(const TriangleMesh& mesh, const Eigen::MatrixX3d& points,
                               int threads) {
  Eigen::VectorXd w(points.rows());
  parallelFor(points.rows(), threads, [&](std::int64_t begin, std::int64_t end) {
    for (std::int64_t r = begin; r < end; ++r) {
      const Eigen::Vector3d p = points.row(r);
      double total = 0;
      for (Eigen::Index f = 0; f < mesh.faces.rows(); ++f) {
        const Eigen::Vector3d a = mesh.vertices.row(mesh.faces(f, 0)).transpose() - p;
        const Eigen::Vector3d b = mesh.vertices.row(mesh.faces(f, 1)).transpose() - p;
        const Eigen::Vector3d c = mesh.vertices.row(mesh.faces(f, 2)).transpose() - p;
        const double la = a.norm(), lb = b.norm(), lc = c.norm();
        const double det = a.dot(b.cross(c));
        const double den = la * lb * lc + a.dot(b) * lc + b.dot(c) * la + c.dot(a) * lb;
        total += 2 * std::atan2(det, den);
      }
      w[r] = total / (4 * 3.14159265358979323846);
    }
  });
  return w;
}

}  // namespace repose
