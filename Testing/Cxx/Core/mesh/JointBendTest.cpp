// The analytic bend of a hinge (mesh/JointBend.h): volume kept pointwise (the Jacobian's
// determinant is 1 wherever the bend acts), no fold (the determinant stays positive), the distal
// side turned rigidly by the whole angle and the proximal side left where it was.
#include "repose/mesh/JointBend.h"

#include <gtest/gtest.h>

#include <Eigen/Geometry>

#include <cmath>
#include <random>

using namespace repose;

namespace {

constexpr double kPi = 3.14159265358979323846;

Eigen::Matrix3d jacobian(const Eigen::Vector3d& p, const Eigen::Vector3d& c,
                         const Eigen::Vector3d& axis, const Eigen::Vector3d& distal, double angle) {
  Eigen::Matrix3d J;
  const double h = 1e-5;
  for (int k = 0; k < 3; ++k) {
    const Eigen::Vector3d dp = Eigen::Vector3d::Unit(k) * h;
    J.col(k) =
        (bendPoint(p + dp, c, axis, distal, angle) - bendPoint(p - dp, c, axis, distal, angle)) /
        (2 * h);
  }
  return J;
}

}  // namespace

TEST(JointBend, KeepsVolumeAndNeverFoldsForTurnsUpTo150Degrees) {
  const Eigen::Vector3d c(10, -20, 300), axis = Eigen::Vector3d(1, 0.2, 0).normalized();
  const Eigen::Vector3d distal = Eigen::Vector3d(0, 0.1, -1).normalized();
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> u(-60, 60);
  for (const double deg : {-90.0, 15.0, 45.0, 90.0, 120.0, -150.0}) {
    const double angle = deg * kPi / 180;
    double worst = 0, smallest = 1e9;
    for (int n = 0; n < 4000; ++n) {
      const Eigen::Vector3d p = c + Eigen::Vector3d(u(rng), u(rng), u(rng));
      // Not on the axis itself, where the cylindrical coordinates have no angle.
      const Eigen::Vector3d r = (p - c) - (p - c).dot(axis) * axis;
      if (r.norm() < 2) continue;
      const double det = jacobian(p, c, axis, distal, angle).determinant();
      worst = std::max(worst, std::fabs(det - 1));
      smallest = std::min(smallest, det);
    }
    EXPECT_LT(worst, 1e-4) << deg << " degrees";
    EXPECT_GT(smallest, 0) << deg << " degrees";
  }
}

TEST(JointBend, TurnsTheDistalSideWholeAndLeavesTheProximalSide) {
  const Eigen::Vector3d c(0, 0, 0), axis(1, 0, 0), distal(0, 0, -1);
  const double angle = 70 * kPi / 180;
  const Eigen::AngleAxisd turn(angle, axis);
  // Straight along the distal part (phi = 0) and straight along the proximal part (phi = 180).
  for (const double d : {5.0, 30.0, 80.0}) {
    double s = -1;
    const Eigen::Vector3d along = c + d * distal + Eigen::Vector3d(12, 0, 0);
    EXPECT_LT((bendPoint(along, c, axis, distal, angle, &s) - (c + turn * (along - c))).norm(),
              1e-9);
    EXPECT_DOUBLE_EQ(s, 1);
    const Eigen::Vector3d above = c - d * distal + Eigen::Vector3d(-7, 0, 0);
    EXPECT_LT((bendPoint(above, c, axis, distal, angle, &s) - above).norm(), 1e-9);
    EXPECT_DOUBLE_EQ(s, 0);
  }
  // In the band the share falls monotonically from the distal side to the proximal side.
  double last = 2;
  for (double phi = 0; phi <= kPi; phi += 0.05) {
    double s = 0;
    const Eigen::Vector3d w = 20 * (std::cos(phi) * distal + std::sin(phi) * axis.cross(distal));
    bendPoint(c + w, c, axis, distal, angle, &s);
    EXPECT_LE(s, last + 1e-12);
    last = s;
  }
}
