// The pose report's counts of the posed maps, slab by slab (PosedTally): the same label voxels,
// Dice counts per group and holes for every slab size and thread count as over the whole maps,
// and each figure what a plain count of the maps gives.
#include "repose/pose/PosedTally.h"
#include "repose/util/Error.h"
#include "repose/volume/LabelStatistics.h"

#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <random>

using namespace repose;

namespace {

// A rest body of blocks of labels in two parts (S 1 on the left, 2 on the right) with holes,
// and a posed copy on another grid: part 2 turned by `motion`, sampled nearest-neighbour, with
// noise (voxels relabelled) so the posed and the expected copies differ.
struct Scene {
  Volume G, S, PG, PS;
  std::vector<RigidHandle> handles;
};

Scene scene() {
  Scene s;
  const VolumeGeometry rest = VolumeGeometry::make({20, 16, 18}, {2, 2, 3}, {-20, -16, -27});
  s.G = Volume(rest, ScalarType::UInt16);
  s.S = Volume(rest, ScalarType::UInt8);
  std::mt19937 random(3);
  std::uniform_int_distribution<int> label(1, 9);
  for (std::int64_t k = 2; k < 16; ++k)
    for (std::int64_t j = 2; j < 14; ++j)
      for (std::int64_t i = 2; i < 18; ++i) {
        const std::int64_t v = s.G.index(i, j, k);
        // Blocks of 4 voxels of one label, and a hole in every block of 5 slices.
        s.G.data<std::uint16_t>()[v] =
            k % 5 == 2 && j == 7 && i % 4 == 1 ? 0 : std::uint16_t(1 + (i / 4 + j / 4 + k / 4) % 7);
        s.S.data<std::uint8_t>()[v] = i < 10 ? 1 : 2;
      }
  RigidHandle left, right;
  left.parts = {1};
  right.parts = {2};
  right.motion = Eigen::Translation3d(2, -1, 3) * Eigen::AngleAxisd(0.2, Eigen::Vector3d::UnitZ());
  s.handles = {left, right};
  const VolumeGeometry posed = VolumeGeometry::make({23, 19, 25}, {1.9, 1.9, 2.5}, {-21, -18, -30});
  s.PG = Volume(posed, ScalarType::UInt16);
  s.PS = Volume(posed, ScalarType::UInt8);
  const auto d = posed.dims;
  for (std::int64_t k = 0; k < d[2]; ++k)
    for (std::int64_t j = 0; j < d[1]; ++j)
      for (std::int64_t i = 0; i < d[0]; ++i) {
        const Eigen::Vector3d x = posed.voxelToRas(i, j, k);
        for (const RigidHandle* h : {&right, &left}) {
          const Eigen::Vector3d r = h->motion.inverse() * x;
          const Eigen::Vector3d u = rest.rasToVoxel(r);
          const std::int64_t ri = std::llround(u.x()), rj = std::llround(u.y()),
                             rk = std::llround(u.z());
          if (ri < 0 || rj < 0 || rk < 0 || ri >= 20 || rj >= 16 || rk >= 18) continue;
          const std::int64_t q = s.G.index(ri, rj, rk);
          if (s.S.data<std::uint8_t>()[q] != h->parts[0]) continue;
          const std::int64_t o = s.PG.index(i, j, k);
          s.PG.data<std::uint16_t>()[o] =
              random() % 11 == 0 ? std::uint16_t(label(random)) : s.G.data<std::uint16_t>()[q];
          s.PS.data<std::uint8_t>()[o] = s.S.data<std::uint8_t>()[q];
          break;
        }
      }
  return s;
}

void expectSame(const PosedTally& a, const PosedTally& b, const std::string& at) {
  EXPECT_EQ(a.labelVoxels(), b.labelVoxels()) << at;
  EXPECT_EQ(a.enclosedBackground(), b.enclosedBackground()) << at;
  ASSERT_EQ(a.groups().size(), b.groups().size()) << at;
  for (std::size_t g = 0; g < a.groups().size(); ++g) {
    EXPECT_EQ(a.groups()[g].posed, b.groups()[g].posed) << at << ", group " << g;
    EXPECT_EQ(a.groups()[g].expected, b.groups()[g].expected) << at << ", group " << g;
    EXPECT_EQ(a.groups()[g].both, b.groups()[g].both) << at << ", group " << g;
    EXPECT_EQ(a.groups()[g].rest, b.groups()[g].rest) << at << ", group " << g;
  }
}

}  // namespace

TEST(PosedTally, SlabsGiveTheWholeMapsCounts) {
  const Scene s = scene();
  PosedTally whole(s.G, s.S, &s.handles, s.PG.geometry(), 1);
  whole.addWhole(s.PG, s.PS);
  ASSERT_TRUE(whole.complete());
  // Each figure is what a plain count gives.
  std::map<int, std::int64_t> labels;
  for (const LabelCount& c : countLabels(s.PG)) labels[c.value] = c.voxels;
  EXPECT_EQ(whole.labelVoxels(), labels);
  EXPECT_EQ(whole.enclosedBackground(), countEnclosedBackground(s.PG));
  EXPECT_GT(whole.enclosedBackground(), 0);
  std::int64_t posedRight = 0;
  for (std::int64_t v = 0; v < s.PG.numVoxels(); ++v)
    posedRight += s.PS.data<std::uint8_t>()[v] == 2 && s.PG.data<std::uint16_t>()[v] != 0;
  std::int64_t tallied = 0, both = 0, expected = 0;
  for (const auto& [label, n] : whole.groups()[1].posed) tallied += n;
  for (const auto& [label, n] : whole.groups()[1].both) both += n;
  for (const auto& [label, n] : whole.groups()[1].expected) expected += n;
  EXPECT_EQ(tallied, posedRight);
  // The noise relabels about one voxel in eleven: most agree, not all.
  EXPECT_GT(both, tallied * 8 / 10);
  EXPECT_LT(both, tallied);
  EXPECT_GT(expected, tallied * 9 / 10);

  const std::int64_t nz = s.PG.dims()[2], plane = s.PG.dims()[0] * s.PG.dims()[1];
  for (const int threads : {1, 2})
    for (const std::int64_t size : {1, 3, 7}) {
      PosedTally slabs(s.G, s.S, &s.handles, s.PG.geometry(), threads);
      for (std::int64_t k0 = 0; k0 < nz; k0 += size) {
        EXPECT_FALSE(slabs.complete());
        slabs.add(s.PG.data<std::uint16_t>() + k0 * plane, s.PS.data<std::uint8_t>() + k0 * plane,
                  k0, std::min(nz, k0 + size));
      }
      expectSame(slabs, whole,
                 "slabs of " + std::to_string(size) + ", " + std::to_string(threads) + " threads");
    }
  PosedTally out(s.G, s.S, &s.handles, s.PG.geometry());
  EXPECT_THROW(out.add(s.PG.layerData(0), s.PS.layerData(0), 1, 2), Error);  // not from slice 0
  EXPECT_THROW(out.addWhole(s.PS, s.PS), Error);                             // a map of S's type
}

// Two bones of two groups, a "femur" above a "tibia" with a 4 mm gap between their ends, and the
// tibia's group turned 90 degrees about the gap's centre, as a knee flexed about a pivot off the
// condyles: the turned tibia's end runs into the femur's back. On a 1 mm grid whose voxel centres
// sit at half millimetres, a quarter turn about the origin maps voxels onto voxels, so the
// collision is exactly the boxes' intersection: x in [-6, 6], y in [2, 6], z in [2, 6] mm, 192
// voxels. The posed maps themselves (empty here) play no part: the tally sees the groups' own
// copies, so a bone carried by another part's tets (the rasterizer's ghosts) is seen too.
TEST(PosedTally, CountsWhereTwoGroupsBonesClaimOneVoxel) {
  const VolumeGeometry grid = VolumeGeometry::make({64, 64, 64}, {1, 1, 1}, {-31.5, -31.5, -31.5});
  Volume G(grid, ScalarType::UInt16), S(grid, ScalarType::UInt8);
  constexpr int kFemur = 5, kTibia = 6, kMuscle = 7;
  for (std::int64_t k = 0; k < 64; ++k)
    for (std::int64_t j = 0; j < 64; ++j)
      for (std::int64_t i = 0; i < 64; ++i) {
        const Eigen::Vector3d x = grid.voxelToRas(i, j, k);
        const std::int64_t v = G.index(i, j, k);
        S.data<std::uint8_t>()[v] = x.z() > 0 ? 1 : 2;
        const bool inBone = std::fabs(x.x()) < 6 && std::fabs(x.y()) < 6;
        const bool femur = inBone && x.z() > 2 && x.z() < 30;
        const bool tibia = inBone && x.z() < -2 && x.z() > -30;
        G.data<std::uint16_t>()[v] = femur ? kFemur : tibia ? kTibia : kMuscle;
      }
  RigidHandle thigh, shank;
  thigh.parts = {1};
  shank.parts = {2};
  const Volume PG(grid, ScalarType::UInt16), PS(grid, ScalarType::UInt8);
  auto collisionsOf = [&](const Eigen::Isometry3d& motion, const std::vector<int>& rigid,
                          std::int64_t slab) {
    shank.motion = motion;
    const std::vector<RigidHandle> handles{thigh, shank};
    PosedTally tally(G, S, &handles, grid, 2);
    if (!rigid.empty()) tally.countCollisions(rigid);
    for (std::int64_t k0 = 0; k0 < 64; k0 += slab)
      tally.add(PG.data<std::uint16_t>() + k0 * 64 * 64, PS.data<std::uint8_t>() + k0 * 64 * 64, k0,
                std::min<std::int64_t>(64, k0 + slab));
    return tally.collisions();
  };
  const Eigen::Isometry3d flexed(Eigen::AngleAxisd(M_PI / 2, Eigen::Vector3d::UnitX()));
  for (const std::int64_t slab : {64, 5, 1}) {
    const std::vector<PieceOverlap> c = collisionsOf(flexed, {kFemur, kTibia}, slab);
    ASSERT_EQ(c.size(), 1u) << "slabs of " << slab;
    EXPECT_EQ(c[0].a, (PieceId{kFemur, 1}));
    EXPECT_EQ(c[0].b, (PieceId{kTibia, 2}));
    EXPECT_EQ(c[0].voxels, 12 * 4 * 4) << "slabs of " << slab;
  }
  // Soft tissue overlapping is not a collision: the muscle of both groups overlaps wherever the
  // shank turns, and a tibia not named rigid does not count either.
  EXPECT_TRUE(collisionsOf(flexed, {kFemur}, 64).empty());
  EXPECT_FALSE(collisionsOf(flexed, {kFemur, kMuscle}, 64).empty())
      << "a label given as rigid is checked, whatever it is";
  // Not asked, nothing counted; the shank moved away, or turned about a pivot 8 mm in front of
  // the gap (its end swings forward and down, clear of the femur), no collision.
  EXPECT_TRUE(collisionsOf(flexed, {}, 64).empty());
  EXPECT_TRUE(collisionsOf(Eigen::Isometry3d(Eigen::Translation3d(0, 0, -3)), {kFemur, kTibia}, 64)
                  .empty());
  Eigen::Isometry3d aboutFront = Eigen::Isometry3d::Identity();
  aboutFront.translate(Eigen::Vector3d(0, 8, 0));
  aboutFront.rotate(flexed.rotation());
  aboutFront.translate(Eigen::Vector3d(0, -8, 0));
  EXPECT_TRUE(collisionsOf(aboutFront, {kFemur, kTibia}, 64).empty());
  // Counted from the first slice only.
  const std::vector<RigidHandle> handles{thigh, shank};
  PosedTally late(G, S, &handles, grid);
  late.add(PG.data<std::uint16_t>(), PS.data<std::uint8_t>(), 0, 1);
  EXPECT_THROW(late.countCollisions({kFemur}), Error);
}
