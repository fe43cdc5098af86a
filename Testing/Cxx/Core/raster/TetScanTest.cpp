// The scan's integer floor and ceil (raster/TetScan.h), which replace libm's per voxel and per
// row: the same whole number as std::floor / std::ceil wherever a grid index can come from, and
// saturated, never overflowing, beyond.
#include "raster/TetScan.h"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <random>

using repose::raster::ceilToInt;
using repose::raster::floorToInt;

namespace {

void expectLibm(double x) {
  EXPECT_EQ(floorToInt(x), static_cast<std::int64_t>(std::floor(x))) << x;
  EXPECT_EQ(ceilToInt(x), static_cast<std::int64_t>(std::ceil(x))) << x;
}

}  // namespace

TEST(TetScan, FloorAndCeilAgreeWithLibmOnWholeNumbersHalvesAndTheirNeighbours) {
  for (const double w : {0.0, 1.0, 2.0, 7.0, 511.0, 1e6, 4503599627370495.0})
    for (const double s : {1.0, -1.0})
      for (const double x : {s * w, s * (w + 0.5), s * (w - 0.5)}) {
        expectLibm(x);
        expectLibm(std::nextafter(x, std::numeric_limits<double>::infinity()));
        expectLibm(std::nextafter(x, -std::numeric_limits<double>::infinity()));
      }
  expectLibm(-0.0);
  expectLibm(std::numeric_limits<double>::denorm_min());
  expectLibm(-std::numeric_limits<double>::denorm_min());
}

TEST(TetScan, FloorAndCeilAgreeWithLibmOnRandomValuesOfEveryScale) {
  std::mt19937_64 rng(20261125);
  std::uniform_real_distribution<double> mantissa(-1, 1);
  std::uniform_int_distribution<int> exponent(-30, 51);
  for (int n = 0; n < 200000; ++n) expectLibm(std::ldexp(mantissa(rng), exponent(rng)));
}

TEST(TetScan, FloorAndCeilSaturateBeyondTwoToTheFiftyTwo) {
  const std::int64_t limit = std::int64_t(1) << 52;
  for (const double x :
       {4503599627370496.0, 1e20, 1e300, std::numeric_limits<double>::infinity()}) {
    EXPECT_EQ(floorToInt(x), limit);
    EXPECT_EQ(ceilToInt(x), limit);
    EXPECT_EQ(floorToInt(-x), -limit);
    EXPECT_EQ(ceilToInt(-x), -limit);
  }
  EXPECT_EQ(floorToInt(std::nan("")), -limit);  // NaN reads as below every grid
  EXPECT_EQ(ceilToInt(std::nan("")), -limit);
}
