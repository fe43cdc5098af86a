// Geometry properties: voxel<->RAS round trips, axis codes as nibabel computes them, bounds.
#include "repose/volume/VolumeGeometry.h"
#include "repose/util/Error.h"

#include <gtest/gtest.h>

#include <Eigen/Geometry>

using namespace repose;

TEST(VolumeGeometry, VoxelToRasRoundTripsForObliqueGrids) {
  for (double angle : {0.0, 0.3, 1.2, 3.0}) {
    const Eigen::Matrix3d rot =
        Eigen::AngleAxisd(angle, Eigen::Vector3d(1, 2, 3).normalized()).toRotationMatrix();
    const VolumeGeometry g =
        VolumeGeometry::make({10, 20, 30}, {0.5, 1.3, 7.2}, {-100, 20, 3}, rot);
    for (const Eigen::Vector3d& ijk :
         {Eigen::Vector3d(0, 0, 0), Eigen::Vector3d(9, 19, 29), Eigen::Vector3d(3.5, -2, 100)}) {
      const Eigen::Vector3d ras = g.voxelToRas(ijk.x(), ijk.y(), ijk.z());
      EXPECT_LT((g.rasToVoxel(ras) - ijk).norm(), 1e-9);
    }
    EXPECT_LT((g.spacing() - Eigen::Vector3d(0.5, 1.3, 7.2)).norm(), 1e-12);
    EXPECT_LT((g.directions() - rot).norm(), 1e-12);
  }
}

TEST(VolumeGeometry, AxisCodesNameTheDirectionEachAxisPointsTo) {
  EXPECT_EQ(VolumeGeometry::make({2, 2, 2}, {1, 1, 1}, {0, 0, 0}).axisCodes(), "RAS");
  Eigen::Matrix3d lps = Eigen::Vector3d(-1, -1, 1).asDiagonal();
  EXPECT_EQ(VolumeGeometry::make({2, 2, 2}, {1, 1, 1}, {0, 0, 0}, lps).axisCodes(), "LPS");
  Eigen::Matrix3d coronal;  // i -> L, j -> S, k -> P (a coronal DICOM acquisition)
  coronal << -1, 0, 0, 0, 0, -1, 0, 1, 0;
  EXPECT_EQ(VolumeGeometry::make({2, 2, 2}, {1, 1, 1}, {0, 0, 0}, coronal).axisCodes(), "LSP");
  // Slightly oblique axes keep the code of the axis they are closest to.
  const Eigen::Matrix3d tilt = Eigen::AngleAxisd(0.2, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  EXPECT_EQ(VolumeGeometry::make({2, 2, 2}, {1, 1, 1}, {0, 0, 0}, tilt).axisCodes(), "RAS");
}

TEST(VolumeGeometry, BoundsCoverVoxelCorners) {
  const VolumeGeometry g = VolumeGeometry::make({4, 5, 6}, {2, 2, 2}, {10, 20, 30});
  const auto [lo, hi] = g.rasBounds();
  EXPECT_LT((lo - Eigen::Vector3d(9, 19, 29)).norm(), 1e-12);
  EXPECT_LT((hi - Eigen::Vector3d(17, 29, 41)).norm(), 1e-12);
}

TEST(VolumeGeometry, ValidateRejectsSingularAndEmpty) {
  VolumeGeometry g = VolumeGeometry::make({4, 5, 6}, {1, 1, 1}, {0, 0, 0});
  EXPECT_NO_THROW(g.validate("x"));
  g.ijkToRas(2, 2) = 0;
  EXPECT_THROW(g.validate("x"), Error);
  g = VolumeGeometry::make({0, 5, 6}, {1, 1, 1}, {0, 0, 0});
  EXPECT_THROW(g.validate("x"), Error);
}

TEST(VolumeGeometry, LpsRasFlipIsAnInvolution) {
  Eigen::Matrix4d m = Eigen::Matrix4d::Random();
  m.row(3) << 0, 0, 0, 1;
  EXPECT_LT((flipLpsRas(flipLpsRas(m)) - m).norm(), 1e-15);
  EXPECT_DOUBLE_EQ(flipLpsRas(m)(0, 3), -m(0, 3));
  EXPECT_DOUBLE_EQ(flipLpsRas(m)(2, 3), m(2, 3));
}
