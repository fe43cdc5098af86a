// Pockets a pose traps inside the body are filled from their walls; cavities the rest body has
// are kept; background joined to the outside is never touched.
#include "repose/raster/PocketFilling.h"
#include "repose/util/Error.h"
#include "repose/volume/LabelStatistics.h"

#include <gtest/gtest.h>

using namespace repose;

namespace {

Volume block(std::uint8_t inner, std::uint8_t outer) {
  Volume v(VolumeGeometry::make({12, 12, 12}, {2, 2, 2}, {0, 0, 0}), ScalarType::UInt8);
  v.setLabelMap(true);
  for (int k = 2; k < 10; ++k)
    for (int j = 2; j < 10; ++j)
      for (int i = 2; i < 10; ++i)
        v.data<std::uint8_t>()[v.index(i, j, k)] = (i >= 4 && i < 8) ? inner : outer;
  return v;
}

std::uint8_t& at(Volume& v, int i, int j, int k) {
  return v.data<std::uint8_t>()[v.index(i, j, k)];
}

}  // namespace

TEST(PocketFilling, TrappedOutsideAndUncoveredVoxelsAreFilledCavitiesKept) {
  Volume rest = block(5, 1);
  const std::vector<float> identity(3 * rest.numVoxels(), 0.0f);

  // A pocket where the rest body is tissue (the identity field maps it there): filled, with the
  // label its walls have most.
  Volume posed = rest, parts = block(2, 2);
  at(posed, 5, 5, 5) = at(posed, 6, 5, 5) = 0;
  at(parts, 5, 5, 5) = at(parts, 6, 5, 5) = 0;
  PocketReport r = fillPosePockets(posed, rest, identity, &parts);
  EXPECT_EQ(r.filled, 2);
  EXPECT_EQ(at(posed, 5, 5, 5), 5);
  EXPECT_EQ(at(parts, 6, 5, 5), 2);
  EXPECT_EQ(countEnclosedBackground(posed), 0);

  // A cavity of the rest body, posed in place: kept.
  Volume hollow = rest;
  at(hollow, 5, 5, 5) = 0;
  Volume posedHollow = hollow;
  r = fillPosePockets(posedHollow, hollow, identity);
  EXPECT_EQ(r.filled, 0);
  EXPECT_EQ(r.keptCavities, 1);
  EXPECT_EQ(at(posedHollow, 5, 5, 5), 0);

  // A voxel no tet covered (its field points far outside the rest grid): filled.
  std::vector<float> uncovered = identity;
  const std::int64_t c = posedHollow.index(5, 5, 5);
  uncovered[3 * c] = 1e6f;
  r = fillPosePockets(posedHollow, hollow, uncovered);
  EXPECT_EQ(r.filled, 1);
  EXPECT_EQ(at(posedHollow, 5, 5, 5), 5);

  // Background joined to the border is the outside: never filled.
  Volume open = rest;
  for (int i = 0; i < 6; ++i) at(open, i, 5, 5) = 0;  // a tunnel from the border
  r = fillPosePockets(open, rest, identity);
  EXPECT_EQ(r.filled, 0);
  EXPECT_EQ(at(open, 5, 5, 5), 0);

  EXPECT_THROW(fillPosePockets(open, rest, std::vector<float>(3)), Error);
}
