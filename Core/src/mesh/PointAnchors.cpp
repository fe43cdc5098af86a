// Point anchors in the transfer mesh: containing tet by barycentric coordinates, then posed
// positions as weighted sums of the posed vertices.
#include "repose/mesh/PointAnchors.h"

#include <Eigen/LU>

#include <limits>

namespace repose {
namespace {

// Barycentric coordinates of p in tet t (rest); false for a degenerate tet.
bool barycentric(const TransferMesh& mesh, Eigen::Index t, const Eigen::Vector3d& p,
                 Eigen::Vector4d& w) {
  const Eigen::Vector3d a = mesh.vertices.row(mesh.tets(t, 0)).transpose();
  Eigen::Matrix3d E;
  for (int c = 0; c < 3; ++c) E.col(c) = mesh.vertices.row(mesh.tets(t, c + 1)).transpose() - a;
  Eigen::FullPivLU<Eigen::Matrix3d> lu(E);
  if (!lu.isInvertible()) return false;
  const Eigen::Vector3d b = lu.solve(p - a);
  w << 1 - b.sum(), b;
  return true;
}

}  // namespace

std::vector<PointAnchor> anchorPoints(const TransferMesh& mesh, const Eigen::MatrixX3d& points) {
  std::vector<PointAnchor> anchors(std::size_t(points.rows()));
  const Eigen::Index nt = mesh.tets.rows();
  if (nt == 0) return anchors;
  // Tet boxes once: most tets are skipped by the box test, a solve only for the few that pass.
  Eigen::MatrixX3d lo(nt, 3), hi(nt, 3);
  for (Eigen::Index t = 0; t < nt; ++t) {
    lo.row(t) = mesh.vertices.row(mesh.tets(t, 0));
    hi.row(t) = lo.row(t);
    for (int k = 1; k < 4; ++k) {
      lo.row(t) = lo.row(t).cwiseMin(mesh.vertices.row(mesh.tets(t, k)));
      hi.row(t) = hi.row(t).cwiseMax(mesh.vertices.row(mesh.tets(t, k)));
    }
  }
  constexpr double kInside = -1e-9;
  for (Eigen::Index i = 0; i < points.rows(); ++i) {
    const Eigen::Vector3d p = points.row(i).transpose();
    PointAnchor& anchor = anchors[std::size_t(i)];
    Eigen::Vector4d w;
    for (Eigen::Index t = 0; t < nt && !anchor.inside; ++t) {
      if ((p.transpose().array() < lo.row(t).array() - 1e-9).any() ||
          (p.transpose().array() > hi.row(t).array() + 1e-9).any())
        continue;
      if (barycentric(mesh, t, p, w) && w.minCoeff() >= kInside) anchor = {int(t), w, true};
    }
    if (anchor.inside) continue;
    // Outside every tet: the tet it is least outside of, extrapolated.
    double best = -std::numeric_limits<double>::infinity();
    for (Eigen::Index t = 0; t < nt; ++t)
      if (barycentric(mesh, t, p, w) && w.minCoeff() > best) {
        best = w.minCoeff();
        anchor = {int(t), w, false};
      }
  }
  return anchors;
}

PointAnchor anchorPointInTet(const TransferMesh& mesh, const Eigen::Vector3d& point, int tet) {
  Eigen::Vector4d w;
  if (tet < 0 || tet >= mesh.tets.rows() || !barycentric(mesh, tet, point, w)) return {};
  return {tet, w, w.minCoeff() >= -1e-9};
}

Eigen::MatrixX3d movePoints(const TransferMesh& mesh, const Eigen::MatrixX3d& deformed,
                            const std::vector<PointAnchor>& anchors, const Eigen::MatrixX3d& rest) {
  Eigen::MatrixX3d out = rest;
  for (std::size_t i = 0; i < anchors.size(); ++i) {
    const PointAnchor& a = anchors[i];
    if (a.tet < 0) continue;
    Eigen::RowVector3d p = Eigen::RowVector3d::Zero();
    for (int k = 0; k < 4; ++k) p += a.weights[k] * deformed.row(mesh.tets(a.tet, k));
    out.row(Eigen::Index(i)) = p;
  }
  return out;
}

Eigen::Matrix3d tetDeformationGradient(const TransferMesh& mesh, const Eigen::MatrixX3d& deformed,
                                       int tet) {
  Eigen::Matrix3d rest, posed;
  for (int c = 0; c < 3; ++c) {
    rest.col(c) = (mesh.vertices.row(mesh.tets(tet, c + 1)) - mesh.vertices.row(mesh.tets(tet, 0)))
                      .transpose();
    posed.col(c) =
        (deformed.row(mesh.tets(tet, c + 1)) - deformed.row(mesh.tets(tet, 0))).transpose();
  }
  Eigen::FullPivLU<Eigen::Matrix3d> lu(rest);
  if (!lu.isInvertible()) return Eigen::Matrix3d::Identity();
  return posed * lu.inverse();
}

}  // namespace repose
