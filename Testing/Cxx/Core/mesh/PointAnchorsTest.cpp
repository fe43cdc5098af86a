// Points carried by the transfer mesh (mesh/PointAnchors.h): anchored in the rest tet that holds
// them, they follow an affine deformation exactly, inside the mesh and (extrapolated) outside it,
// and the anchor tet's gradient is the affine map's matrix.
#include "repose/mesh/PointAnchors.h"

#include "../TestTetMeshes.h"

#include <gtest/gtest.h>

#include <Eigen/Geometry>

#include <random>

using namespace repose;

namespace {

Eigen::MatrixX3d affine(const Eigen::MatrixX3d& points, const Eigen::Matrix3d& A,
                        const Eigen::Vector3d& b) {
  return ((points * A.transpose()).rowwise() + b.transpose()).eval();
}

}  // namespace

TEST(PointAnchors, PointsInsideLieInTheirTetAndFollowAnAffineFrameExactly) {
  const TransferMesh mesh = test::tetBox({0, 0, 0}, {20, 30, 40}, {2, 3, 4});
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> u(0, 1);
  Eigen::MatrixX3d points(200, 3);
  for (Eigen::Index i = 0; i < points.rows(); ++i)
    points.row(i) << 20 * u(rng), 30 * u(rng), 40 * u(rng);
  points.row(0) << 10, 10, 10;  // a vertex shared by many tets
  points.row(1) << 0, 0, 0;     // a corner of the box
  const std::vector<PointAnchor> anchors = anchorPoints(mesh, points);
  ASSERT_EQ(anchors.size(), std::size_t(points.rows()));
  // A rotation, a shear and a stretch, then a shift.
  const Eigen::Matrix3d A =
      Eigen::AngleAxisd(0.7, Eigen::Vector3d(1, 2, 3).normalized()).toRotationMatrix() *
      (Eigen::Matrix3d() << 1.2, 0.3, 0, 0, 0.9, 0.1, 0, 0, 1.1).finished();
  const Eigen::Vector3d b(5, -7, 11);
  const Eigen::MatrixX3d deformed = affine(mesh.vertices, A, b);
  const Eigen::MatrixX3d moved = movePoints(mesh, deformed, anchors, points);
  const Eigen::MatrixX3d expected = affine(points, A, b);
  for (Eigen::Index i = 0; i < points.rows(); ++i) {
    const PointAnchor& a = anchors[std::size_t(i)];
    ASSERT_TRUE(a.inside) << "point " << i;
    EXPECT_GE(a.weights.minCoeff(), -1e-9);
    EXPECT_NEAR(a.weights.sum(), 1, 1e-12);
    // The weights rebuild the point from its tet's rest corners.
    Eigen::RowVector3d p = Eigen::RowVector3d::Zero();
    for (int k = 0; k < 4; ++k) p += a.weights[k] * mesh.vertices.row(mesh.tets(a.tet, k));
    EXPECT_LT((p - points.row(i)).norm(), 1e-9);
    EXPECT_LT((moved.row(i) - expected.row(i)).norm(), 1e-9) << "point " << i;
    EXPECT_LT((tetDeformationGradient(mesh, deformed, a.tet) - A).norm(), 1e-9);
  }
}

TEST(PointAnchors, PointsOutsideAreExtrapolatedFromTheNearestTetAndAMeshWithoutTetsKeepsThem) {
  const TransferMesh mesh = test::tetBox({0, 0, 0}, {10, 10, 10}, {2, 2, 2});
  Eigen::MatrixX3d points(3, 3);
  points << -3, 5, 5, 5, 5, 14, 12, -1, 4;
  const std::vector<PointAnchor> anchors = anchorPoints(mesh, points);
  const Eigen::Matrix3d A = Eigen::AngleAxisd(1.1, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  const Eigen::Vector3d b(1, 2, 3);
  const Eigen::MatrixX3d moved = movePoints(mesh, affine(mesh.vertices, A, b), anchors, points);
  const Eigen::MatrixX3d expected = affine(points, A, b);
  for (Eigen::Index i = 0; i < points.rows(); ++i) {
    EXPECT_FALSE(anchors[std::size_t(i)].inside);
    EXPECT_GE(anchors[std::size_t(i)].tet, 0);
    EXPECT_LT((moved.row(i) - expected.row(i)).norm(), 1e-9);
  }
  // A degenerate rest tet gives the identity gradient, not a division by zero.
  TransferMesh flat = mesh;
  flat.vertices.col(2).setZero();
  EXPECT_TRUE(tetDeformationGradient(flat, flat.vertices, 0).isIdentity());
  // No tets: no anchor, the rest position is kept.
  const TransferMesh empty;
  const std::vector<PointAnchor> none = anchorPoints(empty, points);
  EXPECT_EQ(none[0].tet, -1);
  EXPECT_TRUE(movePoints(empty, empty.vertices, none, points).isApprox(points));
}

TEST(PointAnchors, APointAnchoredToAChosenTetFollowsThatTetsRigidMotionExactly) {
  // A joint's centre anchored to a piece tet of its proximal bone (LiveSession): the tets of one
  // half turn rigidly, the other half stays, and the point, on the border of its chosen tet or
  // outside it, follows the chosen tet's motion and not that of the tet around it.
  const TransferMesh mesh = test::tetBox({0, 0, 0}, {20, 10, 10}, {2, 1, 1});
  const Eigen::Vector3d point(10, 5, 5);  // on the two halves' border
  int chosen = -1;
  for (Eigen::Index t = 0; t < mesh.tets.rows() && chosen < 0; ++t) {
    bool left = true;
    for (int k = 0; k < 4; ++k) left = left && mesh.vertices(mesh.tets(t, k), 0) <= 10;
    if (left) chosen = int(t);
  }
  ASSERT_GE(chosen, 0);
  const PointAnchor anchor = anchorPointInTet(mesh, point, chosen);
  ASSERT_EQ(anchor.tet, chosen);
  EXPECT_NEAR(anchor.weights.sum(), 1, 1e-12);
  // The left half (x <= 10) turns 40 degrees about an axis through (3, 2, 1); the rest stays.
  const Eigen::Matrix3d R =
      Eigen::AngleAxisd(0.7, Eigen::Vector3d(1, -1, 2).normalized()).toRotationMatrix();
  const Eigen::Vector3d pivot(3, 2, 1);
  Eigen::MatrixX3d deformed = mesh.vertices;
  for (Eigen::Index v = 0; v < deformed.rows(); ++v)
    if (mesh.vertices(v, 0) <= 10)
      deformed.row(v) = (R * (mesh.vertices.row(v).transpose() - pivot) + pivot).transpose();
  const Eigen::MatrixX3d moved = movePoints(mesh, deformed, {anchor}, point.transpose());
  EXPECT_LT((moved.row(0).transpose() - (R * (point - pivot) + pivot)).norm(), 1e-9);
  EXPECT_EQ(anchorPointInTet(mesh, point, -1).tet, -1);
  EXPECT_EQ(anchorPointInTet(mesh, point, int(mesh.tets.rows())).tet, -1);
}
