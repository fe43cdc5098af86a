// Automatic contact separation (pose/ContactSeparation.h) pinned on the cut itself, not only on
// what a pose then measures: two blocks of S a few voxels of air apart, along each axis and on
// anisotropic grids, against a plain count, computed here voxel pair by voxel pair, of the voxels
// of either part within the reach of the other; the gap reported in mm; a contact only across
// slices; tissue of the same group between two parts is no gap; and a jointed pair counts only
// beyond its joint's sphere grown by the reach.
#include "repose/pose/ContactSeparation.h"
#include "repose/util/Error.h"

#include <gtest/gtest.h>

#include <cmath>
#include <set>

using namespace repose;

namespace {

// S on a grid of `spacing`, labels a (1), b (2) and c (3) with names.
Volume emptyParts(const std::array<std::int64_t, 3>& dims, const Eigen::Vector3d& spacing) {
  Volume s(VolumeGeometry::make(dims, spacing, Eigen::Vector3d(-7, 3, 11)), ScalarType::UInt8);
  s.setLabelMap(true);
  for (const auto& [value, name] : {std::pair{1, "a"}, {2, "b"}, {3, "c"}}) {
    Label l;
    l.value = value;
    l.name = name;
    s.labels().set(l);
  }
  return s;
}

void fill(Volume& s, std::array<std::int64_t, 3> lo, std::array<std::int64_t, 3> hi,
          std::uint8_t label) {
  for (std::int64_t k = lo[2]; k < hi[2]; ++k)
    for (std::int64_t j = lo[1]; j < hi[1]; ++j)
      for (std::int64_t i = lo[0]; i < hi[0]; ++i) s.data<std::uint8_t>()[s.index(i, j, k)] = label;
}

// Part a moves, everything else stays (the "rest" group, fixed).
Pose aMoves() {
  Pose p;
  p.name = "test";
  PoseGroup moving;
  moving.name = "a";
  moving.select.parts = {1};
  moving.transform.angleDeg = 10;
  PoseGroup rest;
  rest.name = "rest";
  rest.select.rest = true;
  rest.fixed = true;
  p.groups = {moving, rest};
  return p;
}

// The plain count: voxels of a or b with a voxel of the other across a face, or within `reach`
// mm (centre to centre) across air (the segment between the centres passes a background voxel);
// and the air between the nearest two voxels' boxes.
struct Plain {
  std::int64_t voxels = 0;
  double gapMm = 1e300;
};
Plain plainCount(const Volume& s, double reach) {
  Plain out;
  const auto& d = s.dims();
  const Eigen::Vector3d sp = s.geometry().spacing();
  const std::uint8_t* v = s.data<std::uint8_t>();
  std::set<std::int64_t> near;
  std::int64_t grow[3];
  for (int c = 0; c < 3; ++c) grow[c] = std::int64_t(std::ceil(reach / sp[c]));
  for (std::int64_t k = 0; k < d[2]; ++k)
    for (std::int64_t j = 0; j < d[1]; ++j)
      for (std::int64_t i = 0; i < d[0]; ++i) {
        if (v[s.index(i, j, k)] != 1) continue;
        for (std::int64_t dk = -grow[2]; dk <= grow[2]; ++dk)
          for (std::int64_t dj = -grow[1]; dj <= grow[1]; ++dj)
            for (std::int64_t di = -grow[0]; di <= grow[0]; ++di) {
              const std::int64_t x = i + di, y = j + dj, z = k + dk;
              if (x < 0 || y < 0 || z < 0 || x >= d[0] || y >= d[1] || z >= d[2]) continue;
              if (v[s.index(x, y, z)] != 2) continue;
              const Eigen::Vector3d centres(di * sp[0], dj * sp[1], dk * sp[2]);
              if (centres.norm() > reach + 1e-9) continue;
              const bool face = std::abs(di) + std::abs(dj) + std::abs(dk) == 1;
              bool acrossAir = false;
              for (double t = 0.02; t < 1 && !acrossAir; t += 0.02)
                acrossAir = v[s.index(std::llround(double(i) + t * double(di)),
                                      std::llround(double(j) + t * double(dj)),
                                      std::llround(double(k) + t * double(dk)))] == 0;
              if (!face && !acrossAir) continue;
              near.insert(s.index(i, j, k));
              near.insert(s.index(x, y, z));
              const Eigen::Vector3d air(std::max<double>(0, std::abs(double(di)) - 1) * sp[0],
                                        std::max<double>(0, std::abs(double(dj)) - 1) * sp[1],
                                        std::max<double>(0, std::abs(double(dk)) - 1) * sp[2]);
              out.gapMm = std::min(out.gapMm, air.norm());
            }
      }
  out.voxels = std::int64_t(near.size());
  return out;
}

}  // namespace

TEST(ContactSeparation, NearPartsAreCutAsAPlainCountFindsThemAlongEveryAxisAndGrid) {
  for (const Eigen::Vector3d& spacing :
       {Eigen::Vector3d(1, 1, 1), Eigen::Vector3d(1.8, 1.8, 4.8), Eigen::Vector3d(4.8, 2, 1.5)})
    for (int axis = 0; axis < 3; ++axis)
      for (const int gapVoxels : {0, 1, 3}) {
        // Two 6-voxel blocks along `axis`, gapVoxels of air between them (0: touching).
        std::array<std::int64_t, 3> dims{14, 14, 14};
        dims[std::size_t(axis)] = 4 + 6 + gapVoxels + 6 + 4;
        Volume s = emptyParts(dims, spacing);
        std::array<std::int64_t, 3> lo{4, 4, 4}, hi{10, 10, 10};
        lo[std::size_t(axis)] = 4, hi[std::size_t(axis)] = 10;
        fill(s, lo, hi, 1);
        lo[std::size_t(axis)] = 10 + gapVoxels, hi[std::size_t(axis)] = 16 + gapVoxels;
        fill(s, lo, hi, 2);
        const double reach = 2.5 * spacing.maxCoeff() + gapVoxels * spacing[axis];
        ContactOptions options;
        options.reachMm = reach;
        const ContactSeparations cuts = findContactSeparations(s, aMoves(), nullptr, options);
        const std::string what = "spacing " + std::to_string(spacing[0]) + "," +
                                 std::to_string(spacing[1]) + "," + std::to_string(spacing[2]) +
                                 " axis " + std::to_string(axis) + " gap " +
                                 std::to_string(gapVoxels);
        ASSERT_EQ(cuts.made.size(), 1u) << what;
        const ContactSeparation& c = cuts.made[0];
        EXPECT_EQ(c.separation.labelA, 1) << what;
        EXPECT_EQ(c.separation.labelB, 2) << what;
        EXPECT_EQ(c.separation.region.shape, Region::Shape::Everywhere) << what;
        const Plain plain = plainCount(s, reach);
        EXPECT_EQ(c.contactVoxels, plain.voxels) << what;
        EXPECT_NEAR(c.gapMm, gapVoxels * spacing[axis], 1e-6) << what;
        EXPECT_NEAR(c.gapMm, plain.gapMm, 1e-6) << what;
        // Touching: the two facing layers, 36 voxels each; apart: none.
        EXPECT_EQ(c.touchingVoxels, gapVoxels == 0 ? 72 : 0) << what;
        // Without a reach only touching parts are cut.
        const ContactSeparations touching = findContactSeparations(s, aMoves(), nullptr);
        EXPECT_EQ(touching.made.size(), gapVoxels == 0 ? 1u : 0u) << what;
        // Beyond the reach nothing is near.
        options.reachMm = 0.99 * (gapVoxels + 1) * spacing[axis];
        if (gapVoxels > 0) {
          EXPECT_TRUE(findContactSeparations(s, aMoves(), nullptr, options).made.empty()) << what;
        }
      }
}

TEST(ContactSeparation, APartTouchingAnotherOnlyAcrossSlicesIsCut) {
  // 4.8 mm slices: a above b, their only faces shared across one slice boundary.
  Volume s = emptyParts({12, 12, 12}, Eigen::Vector3d(1.8, 1.8, 4.8));
  fill(s, {3, 3, 6}, {9, 9, 8}, 1);
  fill(s, {3, 3, 4}, {9, 9, 6}, 2);
  ContactOptions options;
  options.reachMm = 5;
  const ContactSeparations cuts = findContactSeparations(s, aMoves(), nullptr, options);
  ASSERT_EQ(cuts.made.size(), 1u);
  EXPECT_EQ(cuts.made[0].touchingVoxels, 72);
  EXPECT_EQ(cuts.made[0].gapMm, 0);
  EXPECT_EQ(cuts.made[0].contactVoxels, plainCount(s, 5).voxels);
  EXPECT_NE(cuts.json().find("\"gap_mm\":0"), std::string::npos) << cuts.json();
}

TEST(ContactSeparation, TissueOfTheSameGroupBetweenTwoPartsIsNoGap) {
  // a | c | b along x, c (two voxels) moving with a: a and b are within the reach of each other
  // only through c, not across air, so only c and b are cut (where they touch).
  Volume s = emptyParts({22, 10, 10}, Eigen::Vector3d(1, 1, 1));
  fill(s, {3, 2, 2}, {9, 8, 8}, 1);
  fill(s, {9, 2, 2}, {11, 8, 8}, 3);
  fill(s, {11, 2, 2}, {17, 8, 8}, 2);
  Pose pose = aMoves();
  pose.groups[0].select.parts = {1, 3};
  ContactOptions options;
  options.reachMm = 5;
  const ContactSeparations cuts = findContactSeparations(s, pose, nullptr, options);
  ASSERT_EQ(cuts.made.size(), 1u);
  EXPECT_EQ(cuts.made[0].separation.labelA, 2);
  EXPECT_EQ(cuts.made[0].separation.labelB, 3);
  // With air instead of c, a and b are near.
  fill(s, {9, 2, 2}, {11, 8, 8}, 0);
  const ContactSeparations apart = findContactSeparations(s, pose, nullptr, options);
  ASSERT_EQ(apart.made.size(), 1u);
  EXPECT_EQ(apart.made[0].separation.labelA, 1);
  EXPECT_NEAR(apart.made[0].gapMm, 2, 1e-9);
}

TEST(ContactSeparation, AJointedPairIsNearOnlyBeyondItsJointsSphereGrownByTheReach) {
  // a along x, b along x beyond it, and a lip of b folded back over a with a gap of 2 voxels:
  // the lip is near a far from the joint between them (at their shared face).
  Volume s = emptyParts({60, 16, 16}, Eigen::Vector3d(1, 1, 1));
  fill(s, {2, 4, 4}, {30, 10, 10}, 1);
  fill(s, {30, 4, 4}, {50, 10, 10}, 2);
  fill(s, {8, 12, 4}, {30, 14, 10}, 2);   // the lip, y 12..13 over a's top at y 9
  fill(s, {30, 10, 4}, {32, 14, 10}, 2);  // joins the lip to b
  Skeleton skeleton;
  SkeletonJoint j;
  j.name = "knee";
  j.centre = s.geometry().voxelToRas(30, 7, 7);
  j.parts = {"a", "b"};
  j.radiusMm = 6;
  skeleton.joints.push_back(j);
  ContactOptions options;
  options.reachMm = 4;
  const ContactSeparations cuts = findContactSeparations(s, aMoves(), &skeleton, options);
  ASSERT_EQ(cuts.made.size(), 1u);
  const ContactSeparation& c = cuts.made[0];
  EXPECT_EQ(c.joint, "knee");
  EXPECT_EQ(c.separation.region.shape, Region::Shape::OutsideSphere);
  EXPECT_NEAR(c.gapMm, 2, 1e-9);
  // Every voxel counted lies beyond the sphere grown by the reach; a plain count there agrees.
  std::int64_t plain = 0;
  const auto& d = s.dims();
  const std::uint8_t* v = s.data<std::uint8_t>();
  for (std::int64_t k = 0; k < d[2]; ++k)
    for (std::int64_t jj = 0; jj < d[1]; ++jj)
      for (std::int64_t i = 0; i < d[0]; ++i) {
        const std::uint8_t own = v[s.index(i, jj, k)];
        if (own != 1 && own != 2) continue;
        if ((s.geometry().voxelToRas(double(i), double(jj), double(k)) - j.centre).norm() <=
            j.radiusMm + options.reachMm)
          continue;
        bool near = false;
        for (std::int64_t dk = -4; dk <= 4 && !near; ++dk)
          for (std::int64_t dj = -4; dj <= 4 && !near; ++dj)
            for (std::int64_t di = -4; di <= 4 && !near; ++di) {
              const std::int64_t x = i + di, y = jj + dj, z = k + dk;
              if (x < 0 || y < 0 || z < 0 || x >= d[0] || y >= d[1] || z >= d[2]) continue;
              const std::uint8_t other = v[s.index(x, y, z)];
              if (other == 0 || other == own || (other != 1 && other != 2) ||
                  std::sqrt(double(di * di + dj * dj + dk * dk)) > options.reachMm)
                continue;
              // Across air: the segment between the two centres passes a background voxel.
              for (double t = 0.05; t < 1 && !near; t += 0.05)
                near = v[s.index(std::llround(double(i) + t * double(di)),
                                 std::llround(double(jj) + t * double(dj)),
                                 std::llround(double(k) + t * double(dk)))] == 0;
            }
        plain += near;
      }
  EXPECT_EQ(c.contactVoxels, plain);
}
