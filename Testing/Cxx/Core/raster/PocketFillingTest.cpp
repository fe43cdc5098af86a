// Pockets a pose traps inside the body are filled from their walls; cavities the rest body has
// are kept; background joined to the outside is never touched.
#include "repose/raster/PocketFilling.h"
#include "repose/util/Error.h"
#include "repose/volume/LabelStatistics.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <random>

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

// A frame made slab by slab (PosePockets): the same pockets filled with the same labels in G and
// S, the same cavities kept, for every slab size; pockets and cavities span slab borders, and
// walls relabelled after sampling (label-volume rounding) vote with their final labels.
TEST(PocketFilling, SlabsFillTheWholeGridsPockets) {
  const VolumeGeometry grid = VolumeGeometry::make({14, 12, 19}, {2, 2, 2}, {0, 0, 0});
  Volume rest(grid, ScalarType::UInt16), parts(grid, ScalarType::UInt8);
  for (int k = 1; k < 18; ++k)
    for (int j = 1; j < 11; ++j)
      for (int i = 1; i < 13; ++i) {
        rest.data<std::uint16_t>()[rest.index(i, j, k)] =
            std::uint16_t(1 + (i + 2 * j + 3 * k) % 5);
        parts.data<std::uint8_t>()[parts.index(i, j, k)] = k < 9 ? 1 : 2;
      }
  // Rest cavities: a column of 5 slices at (3, 3); kept where the pose leaves it in place.
  for (int k = 6; k < 11; ++k) rest.data<std::uint16_t>()[rest.index(3, 3, k)] = 0;
  // The posed map: the rest one with pockets punched through slab borders (0 in G and S), one
  // voxel whose field points far off the grid (uncovered), the cavity posed in place.
  Volume posed = rest, posedParts = parts;
  std::mt19937 random(11);
  std::uniform_int_distribution<int> x(2, 11), y(2, 9), z(2, 16), length(1, 6);
  for (int pocket = 0; pocket < 25; ++pocket) {
    const int i = x(random), j = y(random), k0 = z(random), n = length(random);
    if (i == 3 && j == 3) continue;
    for (int k = k0; k < std::min(17, k0 + n); ++k)
      posed.data<std::uint16_t>()[posed.index(i, j, k)] = 0,
                                                    posedParts.data<std::uint8_t>()[posed.index(
                                                        i, j, k)] = 0;
  }
  std::vector<float> field(std::size_t(3 * grid.numVoxels()), 0.0f);
  field[std::size_t(3 * posed.index(8, 6, 9))] = 1e6f;
  posed.data<std::uint16_t>()[posed.index(8, 6, 9)] = 0;
  // A relabelling after sampling: every seventh voxel of label 2 becomes 9.
  auto relabel = [](std::int64_t voxel, std::int64_t sampled) {
    return sampled == 2 && voxel % 7 == 0 ? std::int64_t(9) : sampled;
  };
  Volume wholeG = posed, wholeS = posedParts;
  for (std::int64_t v = 0; v < wholeG.numVoxels(); ++v)
    wholeG.data<std::uint16_t>()[v] = std::uint16_t(relabel(v, wholeG.data<std::uint16_t>()[v]));
  const PocketReport whole = fillPosePockets(wholeG, rest, field, &wholeS);
  ASSERT_GT(whole.filled, 20);
  EXPECT_EQ(whole.keptCavities, 5);

  const std::int64_t nz = grid.dims[2], plane = grid.dims[0] * grid.dims[1];
  for (const std::int64_t size : {std::int64_t(1), std::int64_t(4), nz}) {
    PosePockets pockets(rest, grid);
    Volume G = posed, S = posedParts;
    const std::uint16_t* g = G.data<std::uint16_t>();
    const std::uint8_t* s = S.data<std::uint8_t>();
    for (std::int64_t k0 = 0; k0 < nz; k0 += size) {
      const std::int64_t k1 = std::min(nz, k0 + size);
      pockets.addSlab(k0, k1, k0 > 0 ? g + (k0 - 1) * plane : nullptr, g + k0 * plane,
                      k1 < nz ? g + k1 * plane : nullptr, k0 > 0 ? s + (k0 - 1) * plane : nullptr,
                      s + k0 * plane, k1 < nz ? s + k1 * plane : nullptr, ScalarType::UInt8,
                      field.data() + 3 * k0 * plane);
    }
    const PocketReport report = pockets.fill(relabel);
    EXPECT_EQ(report.filled, whole.filled) << "slabs of " << size;
    EXPECT_EQ(report.keptCavities, whole.keptCavities) << "slabs of " << size;
    for (std::int64_t v = 0; v < G.numVoxels(); ++v)
      G.data<std::uint16_t>()[v] = std::uint16_t(relabel(v, G.data<std::uint16_t>()[v]));
    for (std::int64_t k0 = 0; k0 < nz; k0 += size)
      pockets.apply(k0, std::min(nz, k0 + size), G.data<std::uint16_t>() + k0 * plane,
                    S.data<std::uint8_t>() + k0 * plane);
    EXPECT_TRUE(std::equal(g, g + G.numVoxels(), wholeG.data<std::uint16_t>()))
        << "slabs of " << size;
    EXPECT_TRUE(std::equal(s, s + S.numVoxels(), wholeS.data<std::uint8_t>()))
        << "slabs of " << size;
  }
  // A slab inside the grid without the slices beside it is refused.
  PosePockets pockets(rest, grid);
  EXPECT_THROW(pockets.addSlab(0, 2, nullptr, posed.layerData(0), nullptr, nullptr, nullptr,
                               nullptr, ScalarType::UInt8, field.data()),
               Error);
  EXPECT_THROW(pockets.fill(), Error);
}

// A gap a pose opens between a bone and the tissue beside it (a scapula lifted off the ribs) is
// filled with the soft tissue, not the bone: a rigid label keeps its count in every posture
// (issue 64). Only a pocket no other label reaches takes a rigid one.
TEST(PocketFilling, RigidLabelsFillOnlyPocketsNoOtherLabelReaches) {
  const std::vector<int> rigid = {5};
  Volume rest = block(5, 1);  // bone 5 in the middle, soft tissue 1 on both sides
  const std::vector<float> identity(3 * rest.numVoxels(), 0.0f);

  // Two voxels walled by more bone than soft tissue: without the rule they took the bone.
  Volume posed = rest;
  at(posed, 4, 5, 5) = at(posed, 5, 5, 5) = 0;  // bone's edge: bone on four, soft on one side
  Volume plain = posed;
  fillPosePockets(plain, rest, identity);
  EXPECT_EQ(at(plain, 5, 5, 5), 5);
  PocketReport r = fillPosePockets(posed, rest, identity, nullptr, rigid);
  EXPECT_EQ(r.filled, 2);
  EXPECT_EQ(at(posed, 4, 5, 5), 1);
  EXPECT_EQ(at(posed, 5, 5, 5), 1);  // reached through the soft voxel filled before it
  EXPECT_EQ(countEnclosedBackground(posed), 0);

  // A pocket inside the bone, walled by nothing else: the bone.
  Volume inside = rest;
  at(inside, 5, 5, 5) = 0;
  r = fillPosePockets(inside, rest, identity, nullptr, rigid);
  EXPECT_EQ(r.filled, 1);
  EXPECT_EQ(at(inside, 5, 5, 5), 5);

  // Slab by slab the same.
  Volume slabbed = rest;
  at(slabbed, 4, 5, 5) = at(slabbed, 5, 5, 5) = 0;
  const auto d = slabbed.dims();
  const std::int64_t plane = d[0] * d[1];
  PosePockets pockets(rest, slabbed.geometry(), rigid);
  const std::uint8_t* g = slabbed.data<std::uint8_t>();
  for (std::int64_t k = 0; k < d[2]; ++k)
    pockets.addSlab(k, k + 1, k > 0 ? g + (k - 1) * plane : nullptr, g + k * plane,
                    k + 1 < d[2] ? g + (k + 1) * plane : nullptr, nullptr, nullptr, nullptr,
                    ScalarType::UInt8, identity.data() + 3 * k * plane);
  EXPECT_EQ(pockets.fill().filled, 2);
  pockets.apply(0, d[2], slabbed.layerData(0), nullptr);
  EXPECT_EQ(at(slabbed, 4, 5, 5), 1);
  EXPECT_EQ(at(slabbed, 5, 5, 5), 1);
}
