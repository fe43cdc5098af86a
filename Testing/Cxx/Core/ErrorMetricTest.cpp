// The error metric (eq. 5-7): zero for affine deformations, large where a limb bends, exact
// barycentric rasterization of linear fields, and the cube-root sizing update.
#include "TestMeshes.h"
#include "TestTetMeshes.h"

#include "repose/mesh/ErrorMetric.h"
#include "repose/mesh/RigiditySolver.h"

#include <gtest/gtest.h>

#include <Eigen/Geometry>

using namespace repose;
using namespace repose::test;

TEST(ErrorMetric, AffineDeformationsHaveNoError) {
  const TransferMesh mesh = tetBox({0, 0, 0}, {60, 30, 30}, {6, 3, 3});
  Eigen::Matrix3d A;
  A << 1.2, 0.1, 0, -0.3, 0.9, 0.2, 0.05, 0, 1.1;
  const std::vector<Eigen::Matrix3d> B(static_cast<std::size_t>(mesh.tets.rows()), A);
  const Eigen::VectorXd et = tetErrors(mesh, B);
  EXPECT_LT(et.cwiseAbs().maxCoeff(), 1e-12);
  EXPECT_LT(vertexErrors(mesh, et).cwiseAbs().maxCoeff(), 1e-12);
}

TEST(ErrorMetric, BendingConcentratesErrorAtTheBend) {
  const TransferMesh mesh = tetBox({0, -20, -20}, {300, 20, 20}, {30, 4, 4});
  const TriangleMesh cage = boxMesh({-15, -35, -35}, {315, 35, 35}, 6);
  const CageDeformation d(mesh, cage);
  const Eigen::Matrix3d R =
      Eigen::AngleAxisd(M_PI / 3, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  Eigen::MatrixX3d bent = cage.vertices;
  for (Eigen::Index v = 0; v < bent.rows(); ++v)
    if (bent(v, 0) > 150)
      bent.row(v) =
          (R * (bent.row(v).transpose() - Eigen::Vector3d(150, 0, 0)) + Eigen::Vector3d(150, 0, 0))
              .transpose();
  std::vector<Eigen::Matrix3d> B;
  d.deform(bent, &B);
  const Eigen::VectorXd ev = vertexErrors(mesh, tetErrors(mesh, B));
  double nearBend = 0, farAway = 0;
  for (Eigen::Index v = 0; v < mesh.vertices.rows(); ++v) {
    if (std::fabs(mesh.vertices(v, 0) - 150) < 40) nearBend = std::max(nearBend, ev[v]);
    if (mesh.vertices(v, 0) < 40) farAway = std::max(farAway, ev[v]);
  }
  EXPECT_GT(nearBend, 10 * farAway + 1e-6);
}

TEST(ErrorMetric, RasterizationInterpolatesLinearFieldsExactly) {
  const TransferMesh mesh = tetBox({2.3, 1.1, -4}, {20.3, 13.1, 8}, {3, 2, 2});
  Eigen::VectorXd f(mesh.vertices.rows());
  for (Eigen::Index v = 0; v < f.size(); ++v)
    f[v] = 3 * mesh.vertices(v, 0) - 2 * mesh.vertices(v, 1) + 0.5 * mesh.vertices(v, 2) + 7;
  const VolumeGeometry grid = VolumeGeometry::make({26, 18, 16}, {1, 1, 1}, {0, 0, -6});
  std::vector<char> covered;
  const std::vector<float> g = rasterizeVertexField(mesh, f, grid, &covered);
  std::int64_t inside = 0;
  for (std::int64_t k = 0; k < 16; ++k)
    for (std::int64_t j = 0; j < 18; ++j)
      for (std::int64_t i = 0; i < 26; ++i) {
        const Eigen::Vector3d p = grid.voxelToRas(i, j, k);
        const bool in = p.x() >= 2.3 - 1e-9 && p.x() <= 20.3 + 1e-9 && p.y() >= 1.1 - 1e-9 &&
                        p.y() <= 13.1 + 1e-9 && p.z() >= -4 && p.z() <= 8;
        const std::size_t n = static_cast<std::size_t>(i + 26 * (j + 18 * k));
        ASSERT_EQ(bool(covered[n]), in) << i << "," << j << "," << k;
        if (in) {
          EXPECT_NEAR(g[n], 3 * p.x() - 2 * p.y() + 0.5 * p.z() + 7, 1e-3);
          ++inside;
        }
      }
  EXPECT_EQ(inside, 18 * 12 * 13);
}

TEST(ErrorMetric, SizingUpdateShrinksOnlyWhereErrorExceedsTheMean) {
  SizingField F;
  F.grid = VolumeGeometry::make({4, 1, 1}, {1, 1, 1}, {0, 0, 0});
  F.sizeMm = {10, 10, 10, 10};
  // errors 1, 1, 10, (uncovered): mean over covered = 4.
  const double mean = updateSizingField(F, {1, 1, 10, 99}, {1, 1, 1, 0});
  EXPECT_DOUBLE_EQ(mean, 4);
  EXPECT_FLOAT_EQ(F.sizeMm[0], 10);
  EXPECT_FLOAT_EQ(F.sizeMm[2], static_cast<float>(10 * std::cbrt(0.4)));
  EXPECT_FLOAT_EQ(F.sizeMm[3], 10);
}
