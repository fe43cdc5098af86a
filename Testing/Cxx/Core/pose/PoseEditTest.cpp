// Editing a pose by the workbench's rules (pose/PoseEdit.h), which the Logic and Python share:
// transforms per frame, turns, a follower's motion in the world, groups from a selection, and
// separations — each against motions and selections worked out by hand.
#include "repose/pose/PoseEdit.h"
#include "repose/util/Error.h"

#include <gtest/gtest.h>

#include <cmath>

using namespace repose;

namespace {

// An upper arm turning about the shoulder, a forearm following it and turning about the elbow,
// the rest fixed; two keyframes, the second turning the upper arm only.
Pose armPose() {
  Pose pose = newPose("arm");
  PoseGroup upper;
  upper.name = "upper";
  upper.select.cageVertices = {0, 1};
  upper.transform.axis = Eigen::Vector3d::UnitY();
  upper.transform.angleDeg = 30;
  upper.transform.pivot = Eigen::Vector3d(100, 0, 1400);
  PoseGroup fore;
  fore.name = "fore";
  fore.select.cageVertices = {2, 3};
  fore.follows = "upper";
  fore.transform.axis = Eigen::Vector3d::UnitX();
  fore.transform.angleDeg = 45;
  fore.transform.pivot = Eigen::Vector3d(100, 0, 1100);
  pose.groups.push_back(upper);
  pose.groups.push_back(fore);
  PoseKeyframe a, b;
  a.name = "a";
  b.name = "b";
  PoseTransform turned = upper.transform;
  turned.angleDeg = 60;
  b.transforms.emplace_back("upper", turned);
  pose.keyframes = {a, b};
  return pose;
}

bool near(const Eigen::Isometry3d& a, const Eigen::Isometry3d& b) {
  return (a.matrix() - b.matrix()).cwiseAbs().maxCoeff() < 1e-9;
}

std::string refusal(const std::function<void()>& edit) {
  try {
    edit();
  } catch (const Error& e) {
    return e.what();
  }
  return "";
}

}  // namespace

TEST(PoseEdit, ANewPoseHoldsTheFixedRestOfTheBody) {
  const Pose pose = newPose("");
  EXPECT_EQ(pose.name, "pose");
  ASSERT_EQ(pose.groups.size(), 1u);
  EXPECT_TRUE(pose.groups[0].fixed);
  EXPECT_TRUE(pose.groups[0].select.rest);
  EXPECT_EQ(poseToJson(parsePose(poseToJson(pose), "new")), poseToJson(pose));
}

TEST(PoseEdit, ATransformIsSetInTheFrameEditedAndKeepsItsFurtherTurns) {
  Pose pose = armPose();
  // Frame 0's keyframe says nothing of "upper": its base transform; frame 1 has its own.
  EXPECT_EQ(groupTransform(pose, "upper", 0).angleDeg, 30);
  EXPECT_EQ(groupTransform(pose, "upper", 1).angleDeg, 60);
  EXPECT_EQ(groupTransform(pose, "upper", 7).angleDeg, 60);  // clamped to the last keyframe
  setGroupTransform(pose, "upper", 0, Eigen::Vector3d(0, 0, 2), 10, Eigen::Vector3d(1, 2, 3),
                    Eigen::Vector3d(4, 5, 6));
  const PoseTransform t = groupTransform(pose, "upper", 0);
  EXPECT_TRUE(t.axis.isApprox(Eigen::Vector3d::UnitZ()));  // made unit length
  EXPECT_EQ(t.angleDeg, 10);
  EXPECT_EQ(pose.groups[1].transform.angleDeg, 30);          // the base pose is untouched
  EXPECT_EQ(groupTransform(pose, "upper", 1).angleDeg, 60);  // and so is the other keyframe
  // A joint group's further turns stay as they were.
  pose.groups[2].transform.then = {PoseTurn{Eigen::Vector3d::UnitZ(), 20, ""}};
  pose.keyframes.clear();
  setGroupTransform(pose, "fore", 0, Eigen::Vector3d::UnitX(), 50, Eigen::Vector3d::Zero(),
                    Eigen::Vector3d::Zero());
  ASSERT_EQ(groupTransform(pose, "fore", 0).then.size(), 1u);
  EXPECT_EQ(groupTransform(pose, "fore", 0).then[0].angleDeg, 20);
  // Refused, naming what: the fixed rest, an unknown group, a zero axis, a value not finite.
  EXPECT_NE(refusal([&] {
              setGroupTransform(pose, "rest", 0, Eigen::Vector3d::UnitX(), 1,
                                Eigen::Vector3d::Zero(), Eigen::Vector3d::Zero());
            }).find("\"rest\" is fixed"),
            std::string::npos);
  EXPECT_NE(refusal([&] { groupTransform(pose, "leg", 0); }).find("no group \"leg\""),
            std::string::npos);
  EXPECT_NE(refusal([&] {
              setGroupTransform(pose, "fore", 0, Eigen::Vector3d::Zero(), 1,
                                Eigen::Vector3d::Zero(), Eigen::Vector3d::Zero());
            }).find("axis is zero"),
            std::string::npos);
  EXPECT_NE(refusal([&] {
              setGroupTransform(pose, "fore", 0, Eigen::Vector3d::UnitX(), NAN,
                                Eigen::Vector3d::Zero(), Eigen::Vector3d::Zero());
            }).find("not finite"),
            std::string::npos);
}

TEST(PoseEdit, TurnsAreListedInOrderAndEachAngleSetAlone) {
  Pose pose = armPose();
  pose.keyframes.clear();
  pose.groups[2].transform.axisName = "elbow.rotation";
  pose.groups[2].transform.then = {PoseTurn{Eigen::Vector3d::UnitY(), 5, "elbow.abduction"},
                                   PoseTurn{Eigen::Vector3d::UnitZ(), 7, "elbow.flexion"}};
  const std::vector<GroupTurn> turns = groupTurns(pose, "fore", 0);
  ASSERT_EQ(turns.size(), 3u);
  EXPECT_EQ(turns[0].axisName, "elbow.rotation");
  EXPECT_EQ(turns[0].angleDeg, 45);
  EXPECT_EQ(turns[2].axisName, "elbow.flexion");
  setGroupTurnAngle(pose, "fore", 0, 2, 90);
  EXPECT_EQ(groupTurns(pose, "fore", 0)[2].angleDeg, 90);
  EXPECT_EQ(groupTurns(pose, "fore", 0)[0].angleDeg, 45);
  EXPECT_NE(refusal([&] { setGroupTurnAngle(pose, "fore", 0, 3, 1); }).find("has no turn 3"),
            std::string::npos);
  // A group turning about several axes is moved by its turns, not by a box's motion.
  EXPECT_NE(refusal([&] {
              setGroupMotion(pose, "fore", 0, Eigen::Isometry3d::Identity());
            }).find("several axes"),
            std::string::npos);
}

TEST(PoseEdit, AFollowersMotionIsItsOwnCarriedByItsChainAndSetsBackExactly) {
  Pose pose = armPose();
  for (std::size_t frame : {0u, 1u}) {
    const Eigen::Isometry3d upper = groupTransform(pose, "upper", frame).isometry();
    const Eigen::Isometry3d fore = groupTransform(pose, "fore", frame).isometry();
    EXPECT_TRUE(near(groupMotion(pose, "fore", frame), upper * fore)) << frame;
    EXPECT_TRUE(near(groupMotion(pose, "rest", frame), Eigen::Isometry3d::Identity()));
  }
  // A drag of the forearm's box to a world motion W: its own transform becomes what is left
  // after the upper arm's, about its own pivot, and its motion in the world is W.
  Eigen::Isometry3d world = Eigen::Isometry3d::Identity();
  world.rotate(Eigen::AngleAxisd(0.7, Eigen::Vector3d(1, 2, -1).normalized()));
  world.pretranslate(Eigen::Vector3d(5, -3, 12));
  const Eigen::Vector3d pivot = groupTransform(pose, "fore", 1).pivot;
  setGroupMotion(pose, "fore", 1, world);
  EXPECT_TRUE(near(groupMotion(pose, "fore", 1), world));
  EXPECT_TRUE(groupTransform(pose, "fore", 1).pivot.isApprox(pivot));
  // In the keyframe only: frame 0 keeps the forearm's base transform.
  EXPECT_EQ(groupTransform(pose, "fore", 0).angleDeg, 45);
  // The axis keeps its direction (a control turning it turns it the same way after): from a turn
  // about +X, a motion turning the other way is a negative angle about +X, not one about -X.
  setGroupTransform(pose, "fore", 1, Eigen::Vector3d::UnitX(), 10, pivot, Eigen::Vector3d::Zero());
  Eigen::Isometry3d back = groupMotion(pose, "upper", 1);
  back.rotate(Eigen::AngleAxisd(-0.2, Eigen::Vector3d::UnitX()));
  setGroupMotion(pose, "fore", 1, back);
  EXPECT_GT(groupTransform(pose, "fore", 1).axis.dot(Eigen::Vector3d::UnitX()), 0.999);
  EXPECT_NEAR(groupTransform(pose, "fore", 1).angleDeg, -0.2 * 180 / M_PI, 1e-9);
  // Not rigid: refused, the pose unchanged.
  const std::string before = poseToJson(pose);
  Eigen::Isometry3d scaled = Eigen::Isometry3d::Identity();
  scaled.linear() *= 1.1;
  EXPECT_NE(refusal([&] { setGroupMotion(pose, "fore", 1, scaled); }).find("not a rigid one"),
            std::string::npos);
  EXPECT_EQ(poseToJson(pose), before);
}

TEST(PoseEdit, ACageGroupTakesItsVerticesFromTheGroupsThatHadThem) {
  Pose pose = armPose();
  Eigen::MatrixX3d cage(8, 3);
  for (int v = 0; v < 8; ++v) cage.row(v) = Eigen::RowVector3d(v, 2 * v, 10);
  auto verticesOf = [&](const std::string& name) {
    for (const PoseGroup& g : pose.groups)
      if (g.name == name) return g.select.cageVertices;
    return std::vector<int>{};
  };
  // Vertices 2 and 3 (all of "fore") and 5 (the rest's): "fore" is left empty and goes, with its
  // keyframe entries; the new group is pivoted at their centre.
  pose.keyframes[0].transforms.emplace_back("fore", pose.groups[2].transform);
  const std::string name = addCageGroup(pose, {3, 2, 5, 3}, 0, cage, verticesOf);
  EXPECT_EQ(name, "group 1");
  EXPECT_EQ(pose.groups.size(), 3u);  // rest, upper, group 1
  EXPECT_EQ(pose.groups.back().select.cageVertices, (std::vector<int>{2, 3, 5}));
  EXPECT_TRUE(pose.groups.back().transform.pivot.isApprox(Eigen::Vector3d(10.0 / 3, 20.0 / 3, 10)));
  for (const PoseKeyframe& k : pose.keyframes)
    for (const auto& [group, t] : k.transforms) EXPECT_NE(group, "fore");
  // One vertex of "upper": it keeps the other; the next name is free.
  EXPECT_EQ(addCageGroup(pose, {1}, 0, cage, verticesOf), "group 2");
  EXPECT_EQ(pose.groups[1].select.cageVertices, (std::vector<int>{0}));
  // A group that selects by region cannot give vertices away; a vertex beyond the cage; none.
  pose.groups[1].select.region = Region::parse("everywhere");
  EXPECT_NE(refusal([&] { addCageGroup(pose, {0}, 0, cage, verticesOf); }).find("by region"),
            std::string::npos);
  EXPECT_NE(refusal([&] { addCageGroup(pose, {8}, 0, cage, verticesOf); }).find("out of range"),
            std::string::npos);
  EXPECT_NE(refusal([&] { addCageGroup(pose, {}, 0, cage, verticesOf); }).find("no cage vertex"),
            std::string::npos);
  // By body part: the group selects the part, pivoted at its vertices' centre.
  const std::string byPart = addCageGroup(pose, {6, 7}, 4, cage, verticesOf);
  EXPECT_EQ(poseGroup(pose, byPart).select.parts, (std::vector<int>{4}));
  EXPECT_TRUE(poseGroup(pose, byPart).select.cageVertices.empty());
}

TEST(PoseEdit, ASeparationTakesLabelsOrNames) {
  Pose pose = newPose("p");
  addPoseSeparation(pose, "7", "hand_left", "sphere:0,0,0,30");
  ASSERT_EQ(pose.separations.size(), 1u);
  EXPECT_EQ(pose.separations[0].parts[0], 7);
  EXPECT_EQ(pose.separations[0].partNames[1], "hand_left");
  EXPECT_EQ(pose.separations[0].region.shape, Region::Shape::Sphere);
  EXPECT_NE(refusal([&] { addPoseSeparation(pose, "7", "7", "everywhere"); }).find("itself"),
            std::string::npos);
  EXPECT_NE(refusal([&] { addPoseSeparation(pose, "", "7", "everywhere"); }).find("two body"),
            std::string::npos);
  EXPECT_EQ(pose.separations.size(), 1u);
}
