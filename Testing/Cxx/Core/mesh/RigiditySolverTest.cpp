// The tetrahedral solver (seed eq. 1-4): an identity cage leaves the mesh in place, a rigid cage
// motion moves everything rigidly (also what sticks out of the cage), a bent limb's tip outside
// the cage follows its neighbours and keeps its edge lengths, and parts the cage cannot reach
// stay put instead of making the solve fail.
#include "TestMeshes.h"
#include "TestTetMeshes.h"

#include "repose/mesh/RigiditySolver.h"
#include "repose/util/Error.h"

#include <gtest/gtest.h>

#include <Eigen/Geometry>

using namespace repose;
using namespace repose::test;

namespace {

double meshSize(const TransferMesh& m) {
  return (m.vertices.colwise().maxCoeff() - m.vertices.colwise().minCoeff()).norm();
}

}  // namespace

TEST(RigiditySolver, IdentityCageLeavesEveryVertexInPlace) {
  const TransferMesh mesh = cagedLimb();
  const TriangleMesh cage = cagedLimbCage();
  const CageDeformation d(mesh, cage);
  EXPECT_GT(d.embedding().outliers(), 0);
  const Eigen::MatrixX3d out = d.deform(cage.vertices);
  EXPECT_LT((out - mesh.vertices).rowwise().norm().maxCoeff(), 1e-6 * meshSize(mesh));
}

TEST(RigiditySolver, RigidCageMotionMovesOutsideVerticesRigidly) {
  const TransferMesh mesh = cagedLimb();
  const TriangleMesh cage = cagedLimbCage();
  const CageDeformation d(mesh, cage);
  const Eigen::Matrix3d R =
      Eigen::AngleAxisd(0.9, Eigen::Vector3d(0.3, -1, 2).normalized()).toRotationMatrix();
  const Eigen::RowVector3d t(-40, 500, 12);
  std::vector<Eigen::Matrix3d> B;
  const Eigen::MatrixX3d out = d.deform((cage.vertices * R.transpose()).rowwise() + t, &B);
  const Eigen::MatrixX3d expected = (mesh.vertices * R.transpose()).rowwise() + t;
  EXPECT_LT((out - expected).rowwise().norm().maxCoeff(), 1e-5 * meshSize(mesh));
  // Exact frames keep 22 significant bits per coefficient (two halves, CompactGreenMatrix).
  for (const Eigen::Matrix3d& b : B) EXPECT_LT((b - R).norm(), 5e-6);
}

TEST(RigiditySolver, BentLimbTipOutsideTheCageFollowsAndKeepsItsShape) {
  const TransferMesh mesh = cagedLimb();
  const TriangleMesh cage = cagedLimbCage();
  const CageDeformation d(mesh, cage);
  // Bend: cage vertices beyond x = 120 turn 40 degrees about z around (120, 0, 0).
  const Eigen::Matrix3d R =
      Eigen::AngleAxisd(40 * M_PI / 180, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  const Eigen::Vector3d pivot(120, 0, 0);
  Eigen::MatrixX3d bent = cage.vertices;
  for (Eigen::Index v = 0; v < bent.rows(); ++v)
    if (bent(v, 0) > 120) bent.row(v) = (R * (bent.row(v).transpose() - pivot) + pivot).transpose();
  const Eigen::MatrixX3d out = d.deform(bent);
  ASSERT_TRUE(out.allFinite());
  // The tip (outside the cage) turned with the distal cage: its axis points along R * x.
  Eigen::Vector3d tipStart = Eigen::Vector3d::Zero(), tipEnd = Eigen::Vector3d::Zero();
  int ns = 0, ne = 0;
  for (Eigen::Index v = 0; v < mesh.vertices.rows(); ++v) {
    if (std::fabs(mesh.vertices(v, 0) - 230) < 1e-9) tipStart += out.row(v).transpose(), ++ns;
    if (std::fabs(mesh.vertices(v, 0) - 300) < 1e-9) tipEnd += out.row(v).transpose(), ++ne;
  }
  const Eigen::Vector3d axis = (tipEnd / ne - tipStart / ns).normalized();
  EXPECT_GT(axis.dot(R * Eigen::Vector3d::UnitX()), std::cos(10 * M_PI / 180));
  // Edge lengths of tets wholly outside the cage stay within 5%.
  double worst = 0;
  for (Eigen::Index t = 0; t < mesh.tets.rows(); ++t) {
    bool outside = true;
    for (int c = 0; c < 4; ++c) outside = outside && d.embedding().inside[mesh.tets(t, c)] == 0;
    if (!outside) continue;
    for (int a = 0; a < 4; ++a)
      for (int b = a + 1; b < 4; ++b) {
        const double rest =
            (mesh.vertices.row(mesh.tets(t, a)) - mesh.vertices.row(mesh.tets(t, b))).norm();
        const double now = (out.row(mesh.tets(t, a)) - out.row(mesh.tets(t, b))).norm();
        worst = std::max(worst, std::fabs(now / rest - 1));
      }
  }
  EXPECT_LT(worst, 0.05);
}

TEST(RigiditySolver, PreviewFramesStayWithinAThousandthOfTheCageDisplacement) {
  const TransferMesh mesh = cagedLimb();
  const TriangleMesh cage = cagedLimbCage();
  const CageDeformation d(mesh, cage);
  // Undeformed: both precisions give the exact rest image.
  EXPECT_EQ(d.deform(cage.vertices, nullptr, GreenPrecision::Preview),
            d.deform(cage.vertices, nullptr, GreenPrecision::Exact));
  // A rigid motion far from rest and a bend: preview differs from exact by <= 1e-3 of the motion.
  const Eigen::Matrix3d R =
      Eigen::AngleAxisd(1.3, Eigen::Vector3d(1, 2, -0.5).normalized()).toRotationMatrix();
  Eigen::MatrixX3d moved =
      (cage.vertices * R.transpose()).rowwise() + Eigen::RowVector3d(300, -90, 45);
  Eigen::MatrixX3d bent = cage.vertices;
  for (Eigen::Index v = 0; v < bent.rows(); ++v)
    if (bent(v, 0) > 120) bent(v, 1) += 0.4 * (bent(v, 0) - 120);
  for (const Eigen::MatrixX3d& pose : {moved, bent}) {
    const double motion = (pose - cage.vertices).rowwise().norm().maxCoeff();
    const Eigen::MatrixX3d exact = d.greenPositions(pose, GreenPrecision::Exact);
    const Eigen::MatrixX3d preview = d.greenPositions(pose, GreenPrecision::Preview);
    const double error = (preview - exact).rowwise().norm().maxCoeff();
    EXPECT_GT(error, 0);  // the preview really reads fewer bits
    EXPECT_LT(error, 1e-3 * motion);
  }
}

TEST(RigiditySolver, PartsTheCageCannotReachStayAtRest) {
  // A separate block far from the cage: no vertex inside, no edge to one.
  const TransferMesh mesh =
      concatenate(cagedLimb(), tetBox({500, 0, 0}, {540, 40, 40}, {2, 2, 2}, 2));
  const TriangleMesh cage = cagedLimbCage();
  const CageDeformation d(mesh, cage);
  EXPECT_EQ(d.solver().unconstrainedVertices(), 27);
  const Eigen::MatrixX3d moved = cage.vertices.rowwise() + Eigen::RowVector3d(0, 0, 50);
  const Eigen::MatrixX3d out = d.deform(moved);
  ASSERT_TRUE(out.allFinite());
  for (Eigen::Index v = cagedLimb().vertices.rows(); v < mesh.vertices.rows(); ++v)
    EXPECT_LT((out.row(v) - mesh.vertices.row(v)).norm(), 1e-9);
  EXPECT_NEAR(out(0, 2) - mesh.vertices(0, 2), 50, 1e-6);  // the limb moved with the cage
}

TEST(RigiditySolver, RefusesACageAroundNothingAndBadTargets) {
  const TransferMesh mesh = cagedLimb();
  EXPECT_THROW(CageDeformation(mesh, boxMesh({1000, 1000, 1000}, {1100, 1100, 1100}, 1)), Error);
  const CageDeformation d(mesh, cagedLimbCage());
  EXPECT_THROW(d.deform(Eigen::MatrixX3d::Zero(3, 3)), Error);
  Eigen::MatrixX3d nan = cagedLimbCage().vertices;
  nan(0, 0) = std::nan("");
  EXPECT_THROW(d.deform(nan), Error);
}

TEST(RigiditySolver, RefusesAFlatTetNamingIt) {
  TransferMesh mesh = cagedLimb();
  const Eigen::Index t = 5;
  mesh.vertices.row(mesh.tets(t, 3)) = mesh.vertices.row(mesh.tets(t, 0));  // collapse one tet
  try {
    const CageDeformation d(mesh, cagedLimbCage());
    FAIL() << "a flat tet was accepted";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("degenerate or inverted"), std::string::npos) << e.what();
  }
}
