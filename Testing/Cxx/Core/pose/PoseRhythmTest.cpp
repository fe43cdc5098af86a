// The scapulohumeral and lumbopelvic rhythms (pose/PoseRhythm.h) on a skeleton made by hand: the
// girdle and the pelvis turn by their published shares about their own joints, the limb keeps the
// orientation the pose gives it with its joint carried along, every keyframe gets its own share,
// a pose can switch either off, and turns beyond a joint's range of motion are warned of.
#include "repose/pose/PoseRhythm.h"

#include <gtest/gtest.h>

#include <Eigen/Geometry>

#include <cmath>

using namespace repose;

namespace {

constexpr double kDeg = 3.14159265358979323846 / 180;

// RAS: the left arm hangs at -x from a shoulder at (-150, 0, 1000); the left hip at (-80, 0, 700).
Skeleton body() {
  Skeleton s;
  auto joint = [&](const std::string& name, Eigen::Vector3d centre, JointKind kind,
                   Eigen::Vector3d distal, std::array<std::string, 2> parts, int side) {
    SkeletonJoint j;
    j.name = name;
    j.centre = centre;
    j.axes = jointAxes(kind, distal, Eigen::Vector3d::UnitY(), Eigen::Vector3d::UnitZ(), side);
    j.parts = parts;
    j.radiusMm = 50;
    s.joints.push_back(j);
  };
  joint("sternoclavicular_left", {-20, 40, 1010}, JointKind::Sternoclavicular, {-1, 0, 0.1},
        {"torso", "shoulder_girdle_left"}, -1);
  joint("shoulder_left", {-150, 0, 1000}, JointKind::Shoulder, {0, 0, -1},
        {"shoulder_girdle_left", "upper_arm_left"}, -1);
  joint("lumbosacral", {0, -50, 760}, JointKind::Lumbosacral, {0, 0, -1}, {"torso", "pelvis"}, 0);
  joint("hip_left", {-80, 0, 700}, JointKind::Hip, {0, 0, -1}, {"pelvis", "thigh_left"}, -1);
  joint("hip_right", {80, 0, 700}, JointKind::Hip, {0, 0, -1}, {"pelvis", "thigh_right"}, 1);
  return s;
}

LabelTable parts() {
  LabelTable t;
  int v = 1;
  for (const char* name : {"torso", "shoulder_girdle_left", "upper_arm_left", "forearm_left",
                           "pelvis", "thigh_left", "thigh_right"}) {
    Label l;
    l.value = v++;
    l.name = name;
    t.set(l);
  }
  return t;
}

PoseGroup limb(const std::string& name, std::vector<std::string> parts, const SkeletonJoint& j,
               const std::string& axis, double angle) {
  PoseGroup g;
  g.name = name;
  g.select.partNames = std::move(parts);
  g.transform.pivot = j.centre;
  g.transform.axis = *j.axis(axis);
  g.transform.angleDeg = angle;
  return g;
}

PoseGroup rest() {
  PoseGroup g;
  g.name = "body";
  g.select.rest = true;
  g.fixed = true;
  return g;
}

const PoseGroup* groupNamed(const Pose& p, const std::string& name) {
  for (const PoseGroup& g : p.groups)
    if (g.name == name) return &g;
  return nullptr;
}

// The world motion of a group in frame f.
Eigen::Isometry3d motion(const Pose& p, const std::string& name, std::size_t f = 0) {
  const auto frames = p.frames();
  for (std::size_t g = 0; g < p.groups.size(); ++g)
    if (p.groups[g].name == name) return frames.at(f).second[g];
  ADD_FAILURE() << "no group " << name;
  return Eigen::Isometry3d::Identity();
}

}  // namespace

TEST(PoseRhythm, TheSharesFollowThePublishedRatios) {
  EXPECT_EQ(girdleTurnDeg(60), 0);
  EXPECT_EQ(girdleTurnDeg(90), 0);
  EXPECT_NEAR(girdleTurnDeg(150), 20, 1e-12);  // 2 degrees at the shoulder for 1 of the girdle
  EXPECT_NEAR(girdleTurnDeg(180), 30, 1e-12);
  EXPECT_EQ(pelvisTiltDeg(45), 0);
  EXPECT_EQ(pelvisTiltDeg(60), 0);
  EXPECT_NEAR(pelvisTiltDeg(90), 25, 1e-12);   // sitting: the hip itself flexes 65
  EXPECT_NEAR(pelvisTiltDeg(120), 30, 1e-12);  // at most 30
}

TEST(PoseRhythm, AnArmRaisedBeyond90TurnsItsGirdleAndKeepsItsOrientation) {
  const Skeleton s = body();
  const SkeletonJoint& shoulder = *s.find("shoulder_left");
  Pose pose;
  pose.name = "raise";
  pose.groups = {limb("left arm", {"upper_arm_left", "forearm_left"}, shoulder, "abduction", 60),
                 rest()};
  PoseKeyframe half, up;
  half.name = "half";
  half.transforms.emplace_back("left arm", pose.groups[0].transform);
  up.name = "up";
  PoseTransform t150 = pose.groups[0].transform;
  t150.angleDeg = 150;
  up.transforms.emplace_back("left arm", t150);
  pose.keyframes = {half, up};
  const PoseRhythms rhythms(s, parts());
  ASSERT_FALSE(rhythms.empty());
  std::vector<std::string> notes;
  const Pose applied = rhythms.apply(pose, &notes);
  ASSERT_EQ(applied.groups.size(), 3u);
  const PoseGroup* girdle = groupNamed(applied, "shoulder_girdle_left (scapulohumeral rhythm)");
  ASSERT_NE(girdle, nullptr);
  EXPECT_EQ(girdle->select.partNames, std::vector<std::string>{"shoulder_girdle_left"});
  EXPECT_EQ(groupNamed(applied, "left arm")->follows, girdle->name);
  ASSERT_EQ(notes.size(), 1u);
  EXPECT_NE(notes[0].find("20.0 deg"), std::string::npos) << notes[0];

  const Eigen::Vector3d d = *shoulder.axis("rotation");
  for (const auto& [frame, elevation] : {std::pair{std::size_t(0), 60.0}, {1, 150.0}}) {
    const Eigen::Isometry3d g = motion(applied, girdle->name, frame);
    const Eigen::Isometry3d arm = motion(applied, "left arm", frame);
    const Eigen::Isometry3d asPosed = motion(pose, "left arm", frame);
    // The girdle turns about the sternoclavicular joint by its share.
    const Eigen::Vector3d sc = s.find("sternoclavicular_left")->centre;
    EXPECT_LT((g * sc - sc).norm(), 1e-9);
    EXPECT_NEAR(Eigen::AngleAxisd(g.linear()).angle() / kDeg, girdleTurnDeg(elevation), 1e-9);
    // The arm points where the pose points it, its shoulder carried with the girdle, and the
    // glenohumeral joint turns the rest.
    EXPECT_LT((arm.linear() * d - asPosed.linear() * d).norm(), 1e-9) << frame;
    EXPECT_LT((arm * shoulder.centre - g * shoulder.centre).norm(), 1e-9) << frame;
    const Eigen::Matrix3d glenohumeral = g.linear().transpose() * arm.linear();
    EXPECT_NEAR(Eigen::AngleAxisd(glenohumeral).angle() / kDeg,
                elevation - girdleTurnDeg(elevation), 1e-6);
  }
  // The girdle's share raises the shoulder: at 150 degrees it rides up.
  EXPECT_GT((motion(applied, girdle->name, 1) * shoulder.centre).z(), shoulder.centre.z() + 10);

  // Switched off, or a pose that moves the girdle itself: nothing changes.
  Pose off = pose;
  off.scapulohumeralRhythm = false;
  EXPECT_EQ(rhythms.apply(off).groups.size(), 2u);
  Pose own = pose;
  PoseGroup girdleByHand;
  girdleByHand.name = "girdle";
  girdleByHand.select.partNames = {"shoulder_girdle_left"};
  own.groups.insert(own.groups.begin() + 1, girdleByHand);
  EXPECT_EQ(rhythms.apply(own).groups.size(), 3u);
}

// Straight up (180 degrees) the arm's rest and posed directions are opposite and say no plane of
// elevation; the girdle then turns in the plane of the turn's own path, as it does a hair below
// (arms_up180.pose.json turned both girdles 30 degrees down into the ribs and organs before).
TEST(PoseRhythm, AnArmStraightUpTurnsItsGirdleUpAsJustBelowIt) {
  // An arm that hangs a little forward and out, as a fitted one does (the fallback of old picked
  // an axis square to it, which only an arm hanging straight down along z made the right one).
  Skeleton s = body();
  for (SkeletonJoint& j : s.joints)
    if (j.name == "shoulder_left")
      j.axes = jointAxes(JointKind::Shoulder, Eigen::Vector3d(-0.3, 0.2, -1).normalized(),
                         Eigen::Vector3d::UnitY(), Eigen::Vector3d::UnitZ(), -1);
  const SkeletonJoint& shoulder = *s.find("shoulder_left");
  const PoseRhythms rhythms(s, parts());
  auto girdleAt = [&](double angle) {
    Pose pose;
    pose.name = "up";
    pose.groups = {
        limb("left arm", {"upper_arm_left", "forearm_left"}, shoulder, "abduction", angle), rest()};
    const Pose applied = rhythms.apply(pose);
    return motion(applied, "shoulder_girdle_left (scapulohumeral rhythm)");
  };
  const Eigen::Isometry3d up = girdleAt(180), below = girdleAt(179.99);
  EXPECT_NEAR(Eigen::AngleAxisd(up.linear()).angle() / kDeg, 30, 1e-9);
  EXPECT_LT((up.linear() - below.linear()).norm(), 1e-3);
  // The shoulder rides up with its girdle, as at 150 degrees.
  EXPECT_GT((up * shoulder.centre).z(), shoulder.centre.z() + 10);
}

TEST(PoseRhythm, HipsFlexedBeyond60TiltThePelvisBackAndTheThighsKeepTheirOrientation) {
  const Skeleton s = body();
  const SkeletonJoint& left = *s.find("hip_left");
  const SkeletonJoint& right = *s.find("hip_right");
  Pose pose;
  pose.name = "sit";
  pose.groups = {limb("left thigh", {"thigh_left"}, left, "flexion", 90),
                 limb("right thigh", {"thigh_right"}, right, "flexion", 30), rest()};
  std::vector<std::string> notes;
  const Pose applied = PoseRhythms(s, parts()).apply(pose, &notes);
  const PoseGroup* pelvis = groupNamed(applied, "pelvis (lumbopelvic rhythm)");
  ASSERT_NE(pelvis, nullptr);
  ASSERT_EQ(notes.size(), 1u);
  const Eigen::Isometry3d p = motion(applied, pelvis->name);
  EXPECT_NEAR(Eigen::AngleAxisd(p.linear()).angle() / kDeg, 25, 1e-9);  // from the larger flexion
  // Tilted back: the pubis (in front of and below the joint) goes forwards and up.
  const Eigen::Vector3d pubis(0, 60, 680);
  EXPECT_GT((p * pubis).y(), pubis.y());
  EXPECT_GT((p * pubis).z(), pubis.z());
  for (const auto& [name, joint] : {std::pair{"left thigh", &left}, {"right thigh", &right}}) {
    EXPECT_EQ(groupNamed(applied, name)->follows, pelvis->name);
    const Eigen::Isometry3d thigh = motion(applied, name), asPosed = motion(pose, name);
    const Eigen::Vector3d d = *joint->axis("rotation");
    EXPECT_LT((thigh.linear() * d - asPosed.linear() * d).norm(), 1e-9) << name;
    EXPECT_LT((thigh * joint->centre - p * joint->centre).norm(), 1e-9) << name;
  }
  // Hips within 60 degrees: the pelvis group is there, still.
  Pose step = pose;
  step.groups[0].transform.angleDeg = 30;
  const Pose stepped = PoseRhythms(s, parts()).apply(step);
  EXPECT_NEAR(Eigen::AngleAxisd(motion(stepped, pelvis->name).linear()).angle(), 0, 1e-12);
}

TEST(PoseRhythm, AGroupSelectingTheTorsoTakesTheTrunksNewParts) {
  const Skeleton s = body();
  Pose pose;
  pose.name = "bow";
  PoseGroup trunk;
  trunk.name = "trunk";
  trunk.select.partNames = {"torso"};
  trunk.transform.angleDeg = 20;
  pose.groups = {trunk, rest()};
  const Pose applied = PoseRhythms(s, parts()).apply(pose);
  const auto& names = applied.groups[0].select.partNames;
  for (const char* part : {"torso", "shoulder_girdle_left", "pelvis"})
    EXPECT_NE(std::find(names.begin(), names.end(), part), names.end()) << part;
}

TEST(PoseRhythm, TurnsBeyondAJointsRangeOfMotionAreWarnedOf) {
  Pose pose;
  pose.name = "p";
  PoseGroup elbow;
  elbow.name = "forearm";
  elbow.transform.axisName = "elbow_left.flexion";
  elbow.transform.pivotJoint = "elbow_left";
  elbow.transform.angleDeg = 90;
  pose.groups = {elbow, rest()};
  EXPECT_TRUE(jointRangeWarnings(pose).empty());
  pose.groups[0].transform.angleDeg = 170;  // the elbow flexes 150 at most
  ASSERT_EQ(jointRangeWarnings(pose).size(), 1u);
  EXPECT_NE(jointRangeWarnings(pose)[0].find("elbow_left.flexion 170.0 deg"), std::string::npos)
      << jointRangeWarnings(pose)[0];
  pose.groups[0].transform.angleDeg = 90;
  PoseTurn turn;
  turn.axisName = "shoulder_left.abduction";
  turn.angleDeg = 200;
  pose.groups[0].transform.then.push_back(turn);  // a further turn, checked too
  EXPECT_EQ(jointRangeWarnings(pose).size(), 1u);
  pose.groups[0].transform.then.clear();
  PoseKeyframe k;
  k.name = "far";
  PoseTransform t = pose.groups[0].transform;
  t.angleDeg = -20;  // no hyperextension of the elbow
  k.transforms.emplace_back("forearm", t);
  pose.keyframes.push_back(k);
  ASSERT_EQ(jointRangeWarnings(pose).size(), 1u);
  EXPECT_NE(jointRangeWarnings(pose)[0].find("keyframe \"far\""), std::string::npos);
}
