// Generated tetrahedral meshes for solver tests: a box of cubes, each split into six tets around
// its main diagonal (a conforming Kuhn triangulation), all positively oriented.
#pragma once

#include "TestMeshes.h"

#include "repose/mesh/TransferMesh.h"

#include <Eigen/LU>

namespace repose::test {

inline TransferMesh tetBox(const Eigen::Vector3d& lo, const Eigen::Vector3d& hi,
                           std::array<int, 3> n, int label = 1) {
  TransferMesh m;
  const int nx = n[0] + 1, ny = n[1] + 1, nz = n[2] + 1;
  m.vertices.resize(nx * ny * nz, 3);
  auto id = [&](int i, int j, int k) { return i + nx * (j + ny * k); };
  for (int k = 0; k < nz; ++k)
    for (int j = 0; j < ny; ++j)
      for (int i = 0; i < nx; ++i)
        m.vertices.row(id(i, j, k)) =
            lo + (hi - lo).cwiseProduct(
                     Eigen::Vector3d(double(i) / n[0], double(j) / n[1], double(k) / n[2]));
  std::vector<Eigen::RowVector4i> tets;
  // The six paths from corner 0 to corner 7 through the cube, one tet each.
  const int paths[6][2] = {{1, 2}, {1, 4}, {2, 1}, {2, 4}, {4, 1}, {4, 2}};
  for (int k = 0; k < n[2]; ++k)
    for (int j = 0; j < n[1]; ++j)
      for (int i = 0; i < n[0]; ++i) {
        auto corner = [&](int bits) {
          return id(i + (bits & 1), j + ((bits >> 1) & 1), k + ((bits >> 2) & 1));
        };
        for (const auto& p : paths) {
          Eigen::RowVector4i t(corner(0), corner(p[0]), corner(p[0] | p[1]), corner(7));
          Eigen::Matrix3d E;
          for (int c = 0; c < 3; ++c)
            E.col(c) = (m.vertices.row(t[c + 1]) - m.vertices.row(t[0])).transpose();
          if (E.determinant() < 0) std::swap(t[2], t[3]);
          tets.push_back(t);
        }
      }
  m.tets.resize(tets.size(), 4);
  for (std::size_t t = 0; t < tets.size(); ++t) m.tets.row(t) = tets[t];
  m.labels = Eigen::VectorXi::Constant(static_cast<Eigen::Index>(tets.size()), label);
  return m;
}

// Two meshes as one (vertex indices of the second shifted).
inline TransferMesh concatenate(const TransferMesh& a, const TransferMesh& b) {
  TransferMesh m;
  m.vertices.resize(a.vertices.rows() + b.vertices.rows(), 3);
  m.vertices << a.vertices, b.vertices;
  m.tets.resize(a.tets.rows() + b.tets.rows(), 4);
  m.tets << a.tets, (b.tets.array() + static_cast<int>(a.vertices.rows())).matrix();
  m.labels.resize(a.labels.size() + b.labels.size());
  m.labels << a.labels, b.labels;
  return m;
}

// A 300 mm limb along x and a cage covering x in [-15, 215]: its last 85 mm stick out of the
// cage (outliers, which the rigidity solver moves), as real meshes have at the crown and soles.
inline TransferMesh cagedLimb() {
  return tetBox({0, -20, -20}, {300, 20, 20}, {30, 4, 4});
}
inline TriangleMesh cagedLimbCage() {
  return boxMesh({-15, -35, -35}, {215, 35, 35}, 4);
}

}  // namespace repose::test
