// countLabels against a plain count, on maps large enough for its parallel path: 8-bit maps of
// long runs (where its four histograms per thread matter) and scattered values, 16-bit and
// signed maps, and a map of two layers.
#include "repose/volume/LabelStatistics.h"

#include <gtest/gtest.h>

#include <map>
#include <random>

using namespace repose;

namespace {

VolumeGeometry grid(std::int64_t nx, std::int64_t ny, std::int64_t nz) {
  VolumeGeometry g;
  g.dims = {nx, ny, nz};
  g.ijkToRas = Eigen::Matrix4d::Identity();
  g.ijkToRas(0, 0) = 0.5;  // 0.5 mm3 voxels
  return g;
}

template <class T>
std::map<std::pair<int, int>, std::int64_t> plainCount(const Volume& v) {
  std::map<std::pair<int, int>, std::int64_t> out;
  for (int layer = 0; layer < v.layers(); ++layer)
    for (std::int64_t i = 0; i < v.numVoxels(); ++i)
      if (const T x = v.data<T>(layer)[i]; x != 0) ++out[{layer, int(x)}];
  return out;
}

std::map<std::pair<int, int>, std::int64_t> counted(const Volume& v) {
  std::map<std::pair<int, int>, std::int64_t> out;
  for (const LabelCount& c : countLabels(v)) {
    EXPECT_DOUBLE_EQ(c.volumeMm3, 0.5 * double(c.voxels));
    out[{c.layer, c.value}] = c.voxels;
  }
  return out;
}

}  // namespace

TEST(LabelStatistics, CountsEqualAPlainCountOnLargeMapsOfEveryIntegerType) {
  std::mt19937 random(3);
  // 4.2M voxels (above the size counted on all cores), an odd count so the threads' ranges and
  // the groups of four end unevenly.
  Volume runs(grid(211, 160, 125), ScalarType::UInt8, 2);
  for (int layer = 0; layer < 2; ++layer) {
    std::uint8_t* v = runs.data<std::uint8_t>(layer);
    for (std::int64_t i = 0; i < runs.numVoxels();) {
      const std::int64_t length = std::uniform_int_distribution<std::int64_t>(1, 5000)(random);
      const auto label = std::uint8_t(std::uniform_int_distribution<int>(0, 255)(random) % 7 * 37);
      for (std::int64_t e = std::min(runs.numVoxels(), i + length); i < e; ++i) v[i] = label;
    }
  }
  EXPECT_EQ(counted(runs), plainCount<std::uint8_t>(runs));
  Volume scattered(grid(211, 160, 125), ScalarType::UInt8);
  for (std::int64_t i = 0; i < scattered.numVoxels(); ++i)
    scattered.data<std::uint8_t>()[i] = std::uint8_t(random());
  EXPECT_EQ(counted(scattered), plainCount<std::uint8_t>(scattered));
  Volume wide(grid(211, 160, 125), ScalarType::UInt16);
  for (std::int64_t i = 0; i < wide.numVoxels(); ++i)
    wide.data<std::uint16_t>()[i] = std::uint16_t(random() % 3 == 0 ? random() : 0);
  EXPECT_EQ(counted(wide), plainCount<std::uint16_t>(wide));
  Volume small(grid(7, 5, 3), ScalarType::Int16);
  for (std::int64_t i = 0; i < small.numVoxels(); ++i)
    small.data<std::int16_t>()[i] = std::int16_t(int(random() % 9) - 4);
  EXPECT_EQ(counted(small), plainCount<std::int16_t>(small));
}
