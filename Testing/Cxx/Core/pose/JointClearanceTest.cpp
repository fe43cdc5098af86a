// Bones a joint's turn drives into each other are parted along the distal bone (issue 64, item 4:
// on 8 mm slices a knee's fitted centre is a few millimetres off, and sitting drove each tibia
// into its femur).
#include "repose/pose/JointClearance.h"

#include <gtest/gtest.h>

using namespace repose;

namespace {

// Two rods 4 mm square on 1 mm voxels meeting at a joint at (20, 20, 20): the proximal one above
// it (G 10 in part 1, "upper"), the distal one below (G 11 in part 2, "lower"), 4 mm of joint
// space between their ends; soft tissue (G 1) around both, and the limb's end below them (part 3,
// a group following the distal one).
struct Limb {
  Volume G{VolumeGeometry::make({40, 40, 40}, {1, 1, 1}, {0, 0, 0}), ScalarType::UInt8};
  Volume S{VolumeGeometry::make({40, 40, 40}, {1, 1, 1}, {0, 0, 0}), ScalarType::UInt8};
  Skeleton skeleton;
  Pose pose;
  Limb() {
    for (int k = 2; k < 38; ++k)
      for (int j = 10; j < 30; ++j)
        for (int i = 10; i < 30; ++i) {
          const bool rod = i >= 18 && i < 22 && j >= 18 && j < 22;
          const std::int64_t v = G.index(i, j, k);
          G.data<std::uint8_t>()[v] = rod && k >= 22 && k < 35  ? 10
                                      : rod && k >= 5 && k < 18 ? 11
                                                                : 1;
          S.data<std::uint8_t>()[v] = k >= 20 ? 1 : k >= 4 ? 2 : 3;
        }
    S.labels().set(Label{1, "upper"});
    S.labels().set(Label{2, "lower"});
    S.labels().set(Label{3, "end"});
    SkeletonJoint knee;
    knee.name = "knee";
    knee.centre = Eigen::Vector3d(20, 20, 20);
    knee.parts = {"upper", "lower"};
    knee.radiusMm = 6;
    skeleton.joints.push_back(knee);
    PoseGroup lower, foot, body;
    lower.name = "lower";
    lower.select.parts = {2};
    foot.name = "follower";  // the limb's end, carried by the distal group
    foot.select.parts = {3};
    foot.follows = "lower";
    body.name = "body";
    body.select.rest = true;
    body.fixed = true;
    pose.groups = {lower, foot, body};
  }
  // The distal group turned 90 degrees about x through `pivot`; the follower with it.
  std::vector<Eigen::Isometry3d> turnedAbout(const Eigen::Vector3d& pivot) const {
    const Eigen::Isometry3d turn = Eigen::Translation3d(pivot) *
                                   Eigen::AngleAxisd(M_PI / 2, Eigen::Vector3d::UnitX()) *
                                   Eigen::Translation3d(-pivot);
    return {turn, turn, Eigen::Isometry3d::Identity()};
  }
};

}  // namespace

TEST(JointClearance, ATurnAboutTheTrueCentreIsLeftAsPosed) {
  const Limb limb;
  const JointClearance clearance(limb.pose, limb.skeleton, limb.G, limb.S, {10, 11});
  ASSERT_FALSE(clearance.empty());
  std::vector<Eigen::Isometry3d> motions = limb.turnedAbout({20, 20, 20});
  const std::vector<Eigen::Isometry3d> before = motions;
  EXPECT_TRUE(clearance.apply(motions).empty());
  for (std::size_t g = 0; g < motions.size(); ++g) EXPECT_TRUE(motions[g].isApprox(before[g])) << g;
}

TEST(JointClearance, ATurnAboutAPivotOffTheCentrePartsTheBonesAlongTheDistalOne) {
  const Limb limb;
  const JointClearance clearance(limb.pose, limb.skeleton, limb.G, limb.S, {10, 11});
  // 4 mm behind the centre: the distal rod swings into the proximal one.
  std::vector<Eigen::Isometry3d> motions = limb.turnedAbout({20, 16, 20});
  const std::vector<Eigen::Isometry3d> before = motions;
  const std::vector<JointClearance::Shift> shifts = clearance.apply(motions);
  ASSERT_EQ(shifts.size(), 1u);
  const JointClearance::Shift& s = shifts[0];
  EXPECT_EQ(s.joint, "knee");
  EXPECT_EQ(s.group, 0);
  EXPECT_GT(s.voxelsBefore, 0);
  EXPECT_EQ(s.voxelsAfter, 0);
  // Along the turned distal rod (+y), by the least whole step that parts them: the rods' overlap
  // is under 4 mm deep.
  EXPECT_GT(s.shiftMm.normalized().y(), 0.99);
  EXPECT_LE(s.shiftMm.norm(), 4.0 + 1e-9);
  EXPECT_GE(s.shiftMm.norm(), JointClearance::kStepMm);
  // The distal group and its follower moved by it; the proximal group not.
  for (const int g : {0, 1})
    EXPECT_TRUE(
        motions[std::size_t(g)].isApprox(Eigen::Translation3d(s.shiftMm) * before[std::size_t(g)]))
        << g;
  EXPECT_TRUE(motions[2].isApprox(before[2]));
  // A second pass finds nothing left to part.
  EXPECT_TRUE(clearance.apply(motions).empty());
}

TEST(JointClearance, NoRigidLabelsOrNoSeparateGroupsPartNothing) {
  const Limb limb;
  EXPECT_TRUE(JointClearance(limb.pose, limb.skeleton, limb.G, limb.S, {}).empty());
  Pose one = limb.pose;
  one.groups[0].select.parts = {1, 2};  // both parts in one group: the joint does not bend
  EXPECT_TRUE(JointClearance(one, limb.skeleton, limb.G, limb.S, {10, 11}).empty());
}
