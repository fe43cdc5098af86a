// The exact EDT equals brute force on random anisotropic masks, and is a true Euclidean (not
// chamfer or cube) distance: a single seed gives spheres, honouring anisotropic spacing.
#include "repose/volume/DistanceTransform.h"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <random>

using namespace repose;

TEST(DistanceTransform, EqualsBruteForceOnRandomAnisotropicMasks) {
  std::mt19937 rng(3);
  for (int trial = 0; trial < 4; ++trial) {
    const std::array<std::int64_t, 3> dims{11 + trial, 7, 9 - trial};
    const Eigen::Vector3d spacing(1.3, 1.3 + 0.5 * trial, 7.2 / (trial + 1));
    std::vector<std::uint8_t> mask(dims[0] * dims[1] * dims[2]);
    for (auto& m : mask) m = std::uniform_real_distribution<double>(0, 1)(rng) < 0.03;
    const std::vector<float> d = squaredDistanceToMask(mask, dims, spacing, 2);
    for (std::int64_t k = 0; k < dims[2]; ++k)
      for (std::int64_t j = 0; j < dims[1]; ++j)
        for (std::int64_t i = 0; i < dims[0]; ++i) {
          double best = std::numeric_limits<double>::infinity();
          for (std::int64_t c = 0; c < dims[2]; ++c)
            for (std::int64_t b = 0; b < dims[1]; ++b)
              for (std::int64_t a = 0; a < dims[0]; ++a)
                if (mask[a + dims[0] * (b + dims[1] * c)]) {
                  const Eigen::Vector3d delta((i - a) * spacing[0], (j - b) * spacing[1],
                                              (k - c) * spacing[2]);
                  best = std::min(best, delta.squaredNorm());
                }
          const float got = d[i + dims[0] * (j + dims[1] * k)];
          if (std::isinf(best))
            EXPECT_TRUE(std::isinf(got));
          else
            ASSERT_NEAR(got, best, 1e-4 * (1 + best)) << i << "," << j << "," << k;
        }
  }
}

TEST(DistanceTransform, SingleSeedGivesEuclideanBallsInMillimetres) {
  const std::array<std::int64_t, 3> dims{41, 41, 11};
  const Eigen::Vector3d spacing(0.5, 0.5, 2.0);
  std::vector<std::uint8_t> mask(dims[0] * dims[1] * dims[2], 0);
  mask[20 + 41 * (20 + 41 * 5)] = 1;
  const std::vector<float> d = squaredDistanceToMask(mask, dims, spacing);
  // (10, 0, 0) voxels away along i is 5 mm; (0, 0, 3) along k is 6 mm; a diagonal is not a cube.
  EXPECT_FLOAT_EQ(d[30 + 41 * (20 + 41 * 5)], 25.f);
  EXPECT_FLOAT_EQ(d[20 + 41 * (20 + 41 * 8)], 36.f);
  EXPECT_FLOAT_EQ(d[26 + 41 * (28 + 41 * 5)], 9.f + 16.f);
}

TEST(DistanceTransform, EmptyMaskIsInfinitelyFar) {
  const std::vector<float> d =
      squaredDistanceToMask(std::vector<std::uint8_t>(27, 0), {3, 3, 3}, {1, 1, 1});
  for (float v : d) EXPECT_TRUE(std::isinf(v));
}

// The lean transform (floats between the passes, `repose rig`'s depth on 325M-voxel bodies) is
// the exact one to within a few float ulps, on a grid with distances of hundreds of millimetres.
TEST(DistanceTransform, TheLeanTransformAgreesWithTheExactOne) {
  std::mt19937 rng(5);
  const std::array<std::int64_t, 3> dims{60, 45, 70};
  const Eigen::Vector3d spacing(2.137, 2.137, 8.0);
  std::vector<std::uint8_t> mask(std::size_t(dims[0] * dims[1] * dims[2]));
  for (auto& m : mask) m = std::uniform_real_distribution<double>(0, 1)(rng) < 0.00002;
  const std::vector<float> exact = squaredDistanceToMask(mask, dims, spacing, 2);
  const std::vector<float> lean = squaredDistanceToMaskLean(mask, dims, spacing, 2);
  ASSERT_EQ(lean.size(), exact.size());
  float farthest = 0;
  for (std::size_t i = 0; i < exact.size(); ++i) {
    ASSERT_NEAR(lean[i], exact[i], 4e-7f * exact[i]) << i;
    farthest = std::max(farthest, exact[i]);
  }
  EXPECT_GT(farthest, 100.f * 100.f);
}
