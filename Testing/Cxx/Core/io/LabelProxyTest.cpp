// The out-of-core working copy: mode per block, ties to the smaller non-zero label, voxel centres
// at block centres, partial edge blocks, read through a small slice cache.
#include "TestPaths.h"

#include "repose/io/LabelProxy.h"
#include "repose/io/VolumeIO.h"
#include "repose/util/Error.h"

#include <gtest/gtest.h>

using namespace repose;
using namespace repose::test;

TEST(LabelProxy, ModePerBlockWithTiesToTheSmallerNonZeroLabel) {
  // 5 x 4 x 4 voxels of 1.5 mm: blocks of 2 leave a partial block along x.
  Volume v(VolumeGeometry::make({5, 4, 4}, {1.5, 1.5, 1.5}, {10, 20, 30}), ScalarType::UInt16);
  v.setLabelMap(true);
  Label seven;
  seven.value = 7, seven.name = "seven";
  v.labels().set(seven);
  auto at = [&](int i, int j, int k) -> std::uint16_t& {
    return v.data<std::uint16_t>()[v.index(i, j, k)];
  };
  // Block (0,0,0): four 5s and four 0s -> 5 (label beats background on a tie).
  for (int k = 0; k < 2; ++k)
    for (int j = 0; j < 2; ++j) at(0, j, k) = 5;
  // Block (1,0,0): four 3s and four 7s -> 3 (the smaller label).
  for (int k = 0; k < 2; ++k)
    for (int j = 0; j < 2; ++j) at(2, j, k) = 3, at(3, j, k) = 7;
  // Block (0,1,1): five 9s, three 4s -> 9.
  int n = 0;
  for (int k = 2; k < 4; ++k)
    for (int j = 2; j < 4; ++j)
      for (int i = 0; i < 2; ++i) at(i, j, k) = n++ < 5 ? 9 : 4;
  // Partial block (2,0,0) (x = 4 only): two 6s and two 0s -> 6.
  at(4, 0, 0) = at(4, 1, 0) = 6;
  ScratchDir dir;
  const std::string path = dir.file("v.nii");
  writeVolume(v, path);
  SliceCache cache(path, 3 * 5 * 4 * 2);  // three slices
  const Volume p = labelModeProxy(cache, 2);
  EXPECT_EQ(p.dims(), (std::array<std::int64_t, 3>{3, 2, 2}));
  EXPECT_TRUE(p.geometry().spacing().isApprox(Eigen::Vector3d(3, 3, 3)));
  EXPECT_TRUE(
      p.geometry().voxelToRas(0, 0, 0).isApprox(Eigen::Vector3d(10.75, 20.75, 30.75), 1e-6));
  const auto* q = p.data<std::uint16_t>();
  EXPECT_EQ(q[p.index(0, 0, 0)], 5);
  EXPECT_EQ(q[p.index(1, 0, 0)], 3);
  EXPECT_EQ(q[p.index(0, 1, 1)], 9);
  EXPECT_EQ(q[p.index(2, 0, 0)], 6);
  EXPECT_EQ(q[p.index(2, 1, 1)], 0);
  ASSERT_NE(p.labels().find(7), nullptr);
  EXPECT_EQ(p.labels().find(7)->name, "seven");
  EXPECT_EQ(proxyFactor(1000, 1, 1000), 1);
  EXPECT_EQ(proxyFactor(1000, 1, 999), 2);
  EXPECT_EQ(proxyFactor(1000000, 2, 1000000 * 2 / 27.0), 3);
  EXPECT_THROW(labelModeProxy(cache, 0), Error);
}
