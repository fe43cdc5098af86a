// Grid winding numbers by ray crossings agree with the solid-angle winding number at every voxel,
// on axis-aligned and oblique, mirrored grids, including meshes whose vertices sit on voxel
// centres.
#include "TestMeshes.h"

#include "repose/cage/GridWinding.h"
#include "repose/cage/WindingNumber.h"

#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <cmath>

using namespace repose;
using namespace repose::test;

namespace {

// The ray rule resolves centres lying exactly on the surface as if they were moved by a tiny
// +i, +j, +k step in index space (rows are offset by ~1e-7 voxel, crossings at i count for i+).
// The reference is evaluated at that moved point, so every voxel, on the surface or not, compares.
void expectAgreesWithSolidAngles(const TriangleMesh& mesh, const VolumeGeometry& g) {
  const std::vector<std::int8_t> fast = windingNumbersOnGrid(mesh, g);
  const Eigen::Vector3d tie(1e-9, 1.3e-7 * std::sqrt(2.0), 1.1e-7 * std::sqrt(3.0));
  Eigen::MatrixX3d centres(g.numVoxels(), 3);
  for (std::int64_t k = 0, n = 0; k < g.dims[2]; ++k)
    for (std::int64_t j = 0; j < g.dims[1]; ++j)
      for (std::int64_t i = 0; i < g.dims[0]; ++i)
        centres.row(n++) = g.voxelToRas(i + tie.x(), j + tie.y(), k + tie.z());
  const Eigen::VectorXd exact = windingNumbers(mesh, centres);
  std::int64_t inside = 0, mismatches = 0;
  for (std::int64_t n = 0; n < g.numVoxels(); ++n) {
    mismatches += fast[n] != std::lround(exact[n]);
    inside += fast[n] == 1;
  }
  EXPECT_EQ(mismatches, 0);
  EXPECT_GT(inside, 0);
}

}  // namespace

TEST(GridWinding, AgreesWithSolidAnglesOnAxisAlignedGrid) {
  const TriangleMesh sphere = sphereMesh({1.2, -3.4, 5.0}, 9.3, 2);
  expectAgreesWithSolidAngles(sphere,
                              VolumeGeometry::make({24, 22, 26}, {1, 1, 1}, {-11, -15, -8}));
}

TEST(GridWinding, VerticesOnVoxelCentresAreHandled) {
  // A box whose corners and edges lie exactly on voxel centres and rows.
  const TriangleMesh box = boxMesh({2, 3, 4}, {12, 9, 10}, 2);
  expectAgreesWithSolidAngles(box, VolumeGeometry::make({16, 14, 14}, {1, 1, 1}, {0, 0, 0}));
}

TEST(GridWinding, ObliqueAnisotropicAndMirroredGrids) {
  const TriangleMesh sphere = sphereMesh({0, 0, 0}, 20, 2);
  const Eigen::Matrix3d rot =
      Eigen::AngleAxisd(0.5, Eigen::Vector3d(1, 2, -1).normalized()).toRotationMatrix();
  expectAgreesWithSolidAngles(
      sphere, VolumeGeometry::make({20, 20, 8}, {2.5, 2.5, 6}, {-25, -25, -25}, rot));
  Eigen::Matrix3d mirrored = Eigen::Vector3d(-1, -1, 1).asDiagonal();  // an LPS-like grid
  expectAgreesWithSolidAngles(
      sphere, VolumeGeometry::make({22, 22, 22}, {2, 2, 2}, {22, 22, -22}, mirrored));
}

TEST(GridWinding, InwardOrientationGivesMinusOne) {
  TriangleMesh box = boxMesh({2, 2, 2}, {8, 8, 8}, 1);
  box.faces.col(1).swap(box.faces.col(2));
  const VolumeGeometry g = VolumeGeometry::make({10, 10, 10}, {1, 1, 1}, {0.5, 0.5, 0.5});
  const auto w = windingNumbersOnGrid(box, g);
  EXPECT_EQ(w[5 + 10 * (5 + 10 * 5)], -1);
  EXPECT_EQ(w[0], 0);
}
