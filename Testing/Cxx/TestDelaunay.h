// Delaunay tetrahedralizations of given points (CGAL) for tests: irregular vertex valences and tet
// shapes (slivers included), as a Mesh_3 mesh has, where the Kuhn boxes of TestTetMeshes.h are
// regular. Include it in few test files: CGAL's triangulation headers are slow to compile.
#pragma once

#include "repose/mesh/TransferMesh.h"

#include <CGAL/Delaunay_triangulation_3.h>
#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>

#include <Eigen/Core>
#include <Eigen/LU>
#include <map>
#include <vector>

namespace repose::test {

// Every finite cell of the points' Delaunay tetrahedralization, positively oriented, label 1.
// Degenerate inputs (points on a lattice, co-spherical sets) get CGAL's symbolic perturbation: the
// cells still tile the convex hull without gaps or overlaps.
inline TransferMesh delaunayMesh(const std::vector<Eigen::Vector3d>& points) {
  using K = CGAL::Exact_predicates_inexact_constructions_kernel;
  using Delaunay = CGAL::Delaunay_triangulation_3<K>;
  Delaunay dt;
  std::map<Delaunay::Vertex_handle, int> index;
  for (std::size_t i = 0; i < points.size(); ++i)
    index[dt.insert(K::Point_3(points[i].x(), points[i].y(), points[i].z()))] = int(i);
  TransferMesh m;
  m.vertices.resize(Eigen::Index(points.size()), 3);
  for (std::size_t i = 0; i < points.size(); ++i) m.vertices.row(Eigen::Index(i)) = points[i];
  std::vector<Eigen::RowVector4i> tets;
  for (auto c = dt.finite_cells_begin(); c != dt.finite_cells_end(); ++c) {
    Eigen::RowVector4i t;
    for (int k = 0; k < 4; ++k) t[k] = index.at(c->vertex(k));
    Eigen::Matrix3d E;
    for (int k = 0; k < 3; ++k) E.col(k) = (points[t[k + 1]] - points[t[0]]);
    if (E.determinant() < 0) std::swap(t[2], t[3]);
    tets.push_back(t);
  }
  m.tets.resize(Eigen::Index(tets.size()), 4);
  for (std::size_t t = 0; t < tets.size(); ++t) m.tets.row(Eigen::Index(t)) = tets[t];
  m.labels = Eigen::VectorXi::Ones(m.tets.rows());
  return m;
}

}  // namespace repose::test
