// The error metric (eq. 5-7): zero for affine deformations, large where a limb bends, exact
// barycentric rasterization of linear fields, and the cube-root sizing update.
#include "TestMeshes.h"
#include "TestTetMeshes.h"

#include "repose/mesh/ErrorMetric.h"
#include "repose/mesh/RigiditySolver.h"

#include <gtest/gtest.h>

#include <Eigen/Geometry>

#include <random>

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

// Eq. 5-6 and e^G against values worked out by hand (issue 29, item 2). Five tets in a closed fan
// around the edge a = (0,0,0), b = (0,0,6) through the ring p0..p4; a tet (a, b, p, q) has volume
// |p x q| (6 * |p x q| / 2 / 3): 2, 6, 3, 2, 2. With B_t = s_t I, s = 1..5, eq. 1 gives
// e_t = sqrt(3) |s_t - (V_{t-1} s_{t-1} + V_{t+1} s_{t+1}) / (V_{t-1} + V_{t+1})|:
//   t0: |1 - (2*5 + 6*2) / 8| = 1.75      t1: |2 - (2*1 + 3*3) / 5| = 0.2
//   t2: |3 - (6*2 + 2*4) / 8| = 0.5       t3: |4 - (3*3 + 2*5) / 5| = 0.2
//   t4: |5 - (2*4 + 2*1) / 4| = 2.5
// and eq. 6 e_v = sum V_t e_t / sum V_t over the tets at v:
//   a, b: (2*1.75 + 6*0.2 + 3*0.5 + 2*0.2 + 2*2.5) / 15 = 11.6 / 15
//   p0: (2*1.75 + 2*2.5) / 4 = 2.125    p1: (2*1.75 + 6*0.2) / 8 = 0.5875
//   p2: (6*0.2 + 3*0.5) / 9 = 0.3       p3: (3*0.5 + 2*0.2) / 5 = 0.38    p4: (2*0.2 + 2*2.5) / 4
//   = 1.35
// (all times sqrt 3). e^G at (0.25, 0.5, 1.5), barycentric (1/4, 1/4, 1/4, 1/4) in t0 = (a, b, p0,
// p1): (2 * 11.6/15 + 2.125 + 0.5875) / 4.
TEST(ErrorMetric, HandComputedValuesOnAFiveTetFanAndTwoTets) {
  TransferMesh fan;
  fan.vertices.resize(7, 3);
  fan.vertices << 0, 0, 0, 0, 0, 6, 1, 0, 0, 0, 2, 0, -3, 0, 0, 0, -1, 0, 2, -2, 0;
  fan.tets.resize(5, 4);
  for (int k = 0; k < 5; ++k) {
    fan.tets.row(k) << 0, 1, 2 + k, 2 + (k + 1) % 5;
    if (tetVolume(fan.vertices, fan.tets.row(k)) < 0) std::swap(fan.tets(k, 0), fan.tets(k, 1));
  }
  fan.labels = Eigen::VectorXi::Ones(5);
  const double volumes[5] = {2, 6, 3, 2, 2};
  for (int k = 0; k < 5; ++k)
    ASSERT_NEAR(tetVolume(fan.vertices, fan.tets.row(k)), volumes[k], 1e-12) << k;
  std::vector<Eigen::Matrix3d> B;
  for (int k = 0; k < 5; ++k) B.push_back((k + 1.0) * Eigen::Matrix3d::Identity());
  const double r3 = std::sqrt(3.0);
  const Eigen::VectorXd et = tetErrors(fan, B);
  const double expectedT[5] = {1.75, 0.2, 0.5, 0.2, 2.5};
  for (int k = 0; k < 5; ++k) EXPECT_NEAR(et[k], expectedT[k] * r3, 1e-12) << "e_t of tet " << k;
  const Eigen::VectorXd ev = vertexErrors(fan, et);
  const double expectedV[7] = {11.6 / 15, 11.6 / 15, 2.125, 0.5875, 0.3, 0.38, 1.35};
  for (int v = 0; v < 7; ++v) EXPECT_NEAR(ev[v], expectedV[v] * r3, 1e-12) << "e_v of vertex " << v;
  // e^G on a 0.25 mm grid with a voxel centre at (0.25, 0.5, 1.5).
  const VolumeGeometry grid = VolumeGeometry::make({21, 17, 25}, {0.25, 0.25, 0.25}, {-3, -2, 0});
  std::vector<char> covered;
  const std::vector<float> eG = rasterizeVertexField(fan, ev, grid, &covered);
  const std::size_t at = std::size_t(13 + 21 * (10 + 17 * 6));
  ASSERT_TRUE(grid.voxelToRas(13, 10, 6).isApprox(Eigen::Vector3d(0.25, 0.5, 1.5)));
  EXPECT_TRUE(covered[at]);
  EXPECT_NEAR(eG[at], (2 * 11.6 / 15 + 2.125 + 0.5875) / 4 * r3, 1e-5);  // float grid

  // Two tets sharing a face, a shear between them, and a vertex no tet uses: e_t = |B0 - B1| = 1
  // for both (the only neighbour's mean is its B), e_v = 1 at all five used vertices, 0 unused.
  TransferMesh two;
  two.vertices.resize(6, 3);
  two.vertices << 0, 0, 0, 4, 0, 0, 0, 4, 0, 0, 0, 4, 3, 3, 3, 50, 50, 50;
  two.tets.resize(2, 4);
  two.tets << 0, 1, 2, 3, 1, 2, 3, 4;
  for (int k = 0; k < 2; ++k)
    if (tetVolume(two.vertices, two.tets.row(k)) < 0) std::swap(two.tets(k, 0), two.tets(k, 1));
  two.labels = Eigen::VectorXi::Ones(2);
  Eigen::Matrix3d shear = Eigen::Matrix3d::Identity();
  shear(0, 1) = 1;
  const Eigen::VectorXd e2 = tetErrors(two, {Eigen::Matrix3d::Identity(), shear});
  EXPECT_NEAR(e2[0], 1, 1e-12);
  EXPECT_NEAR(e2[1], 1, 1e-12);
  const Eigen::VectorXd v2 = vertexErrors(two, e2);
  for (int v = 0; v < 5; ++v) EXPECT_NEAR(v2[v], 1, 1e-12) << v;
  EXPECT_EQ(v2[5], 0);
  // A tet with no face neighbour has no error (eq. 1's mean is empty).
  TransferMesh one = two;
  one.tets.conservativeResize(1, 4);
  one.labels.conservativeResize(1);
  EXPECT_EQ(tetErrors(one, {shear})[0], 0);
}

// Eq. 7 on a synthetic error field (issue 29, item 2): a smooth bump of error over a 12 x 9 x 7
// grid, a random third of it not covered by the mesh, random sizes. Every covered voxel's new
// size is its old one times cbrt(e_mean / max(e^G, e_mean)) with e_mean the mean over covered
// voxels only (computed here in long double); uncovered voxels and voxels at or below the mean
// keep their size; sizes never grow; the largest error shrinks most.
TEST(ErrorMetric, SizingUpdateFollowsEquationSevenOnASyntheticField) {
  SizingField F;
  F.grid = VolumeGeometry::make({12, 9, 7}, {2, 2, 2}, {0, 0, 0});
  const std::size_t n = 12 * 9 * 7;
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> u(0, 1);
  std::vector<float> error(n), before(n);
  std::vector<char> covered(n);
  F.sizeMm.resize(n);
  std::size_t peak = 0;
  for (std::size_t v = 0; v < n; ++v) {
    const double i = double(v % 12), j = double((v / 12) % 9), k = double(v / 108);
    error[v] = float(
        0.05 + 2 * std::exp(-((i - 8) * (i - 8) + (j - 3) * (j - 3) + (k - 4) * (k - 4)) / 6));
    covered[v] = u(rng) > 1.0 / 3;
    before[v] = F.sizeMm[v] = float(5 + 10 * u(rng));
    if (covered[v] && (!covered[peak] || error[v] > error[peak])) peak = v;
  }
  long double sum = 0;
  std::size_t count = 0;
  for (std::size_t v = 0; v < n; ++v)
    if (covered[v]) sum += error[v], ++count;
  const double mean = double(sum / count);
  EXPECT_NEAR(updateSizingField(F, error, covered), mean, 1e-12 * mean);
  std::size_t shrunk = 0;
  double smallestFactor = 1;
  for (std::size_t v = 0; v < n; ++v) {
    const double factor = covered[v] ? std::cbrt(mean / std::max<double>(error[v], mean)) : 1.0;
    EXPECT_FLOAT_EQ(F.sizeMm[v], float(before[v] * factor)) << v;
    EXPECT_LE(F.sizeMm[v], before[v]) << v;
    shrunk += F.sizeMm[v] < before[v];
    smallestFactor = std::min(smallestFactor, double(F.sizeMm[v]) / before[v]);
  }
  EXPECT_GT(shrunk, 10u);
  EXPECT_NEAR(double(F.sizeMm[peak]) / before[peak], smallestFactor, 1e-6);
}
