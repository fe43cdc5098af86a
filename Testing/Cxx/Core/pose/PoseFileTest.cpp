// Pose files: the pose suite parses, a file survives a write/read round trip, keyframes expand
// into frames, every kind of bad field is refused with a message naming the field, and groups
// resolve to cage vertices and body parts of the phantom.
#include "TestPaths.h"
#include "TestPoses.h"

#include "repose/cage/CageBuilder.h"
#include "repose/mesh/TransferMesh.h"
#include "repose/phantom/Phantom.h"
#include "repose/pose/Pose.h"
#include "repose/util/Error.h"

#include <gtest/gtest.h>

#include <Eigen/Geometry>

#include <filesystem>

using namespace repose;
using namespace repose::test;

namespace {

std::string suite(const std::string& name) {
  return std::string(REPOSE_SOURCE_DIR) + "/bench/poses/" + name + ".pose.json";
}

// The error message parsePose gives for `text`, or "" if it parses.
std::string errorOf(const std::string& text) {
  try {
    parsePose(text, "p.json");
  } catch (const Error& e) {
    return e.what();
  }
  return "";
}

const char* kMinimal = R"({"format":"repose-pose","version":1,"name":"m","groups":[
  {"name":"arm","select":{"parts":[4]},"rotation":{"axis":[0,0,2],"angle_deg":90,"pivot":[1,2,3]},
   "translation":[10,0,0]},
  {"name":"body","select":{"rest":true},"fixed":true}]})";

}  // namespace

TEST(PoseFile, TheSuiteParsesAndSurvivesARoundTrip) {
  ScratchDir dir;
  for (const char* name : {"elbow90", "arm_raise90", "hand_from_hip", "leg_step30", "walk"}) {
    const Pose pose = readPoseFile(suite(name));
    EXPECT_EQ(pose.name, name);
    const std::string copy = dir.file(std::string(name) + ".pose.json");
    writePoseFile(pose, copy);
    EXPECT_EQ(poseToJson(readPoseFile(copy)), poseToJson(pose)) << name;
  }
  // Its joints are named: a skeleton gives them their places, each frame of the phantom's.
  const Pose named = readPoseFile(suite("walk"));
  EXPECT_TRUE(poseNamesJoints(named));
  EXPECT_THROW(named.frames(), Error);
  PhantomOptions po;
  po.voxelMm = 8;
  const Phantom phantom(po);
  const Pose walk = suitePose("walk", phantom);
  EXPECT_FALSE(poseNamesJoints(walk));
  EXPECT_EQ(walk.groups[0].transform.pivot, phantom.joint("hip_left").ras);
  EXPECT_EQ(walk.frames().size(), 7u);
  EXPECT_EQ(readPoseFile(suite("hand_from_hip")).separations.size(), 4u);
}

TEST(PoseFile, TransformsRotateAboutThePivotThenTranslate) {
  const Pose pose = parsePose(kMinimal, "m");
  const auto frames = pose.frames();
  ASSERT_EQ(frames.size(), 1u);
  const Eigen::Isometry3d& m = frames[0].second[0];
  // 90 degrees about z through (1,2,3): (2,2,3) -> (1,3,3), then +10 in x.
  EXPECT_LT((m * Eigen::Vector3d(2, 2, 3) - Eigen::Vector3d(11, 3, 3)).norm(), 1e-12);
  EXPECT_TRUE(frames[0].second[1].isApprox(Eigen::Isometry3d::Identity()));  // fixed
}

TEST(PoseFile, KeyframesChangeOnlyWhatTheyName) {
  std::string text = kMinimal;
  text.insert(text.size() - 1,
              R"(,"keyframes":[{"name":"a","groups":{"arm":{"rotation":{"angle_deg":0}}}},
    {"name":"b","groups":{}}])");
  const auto frames = parsePose(text, "k").frames();
  ASSERT_EQ(frames.size(), 2u);
  EXPECT_EQ(frames[0].first, "a");
  // Angle 0 but the base translation kept.
  EXPECT_LT((frames[0].second[0] * Eigen::Vector3d(2, 2, 3) - Eigen::Vector3d(12, 2, 3)).norm(),
            1e-12);
  EXPECT_LT((frames[1].second[0] * Eigen::Vector3d(2, 2, 3) - Eigen::Vector3d(11, 3, 3)).norm(),
            1e-12);
}

TEST(PoseFile, BadFieldsAreRefusedByName) {
  auto with = [](const std::string& from, const std::string& to) {
    std::string t = kMinimal;
    const auto at = t.find(from);
    EXPECT_NE(at, std::string::npos) << from;
    return t.replace(at, from.size(), to);
  };
  const std::pair<std::string, std::string> cases[] = {
      {"{", "p.json: not valid JSON"},
      {with("\"version\":1", "\"version\":2"), "p.json: version: expected 1"},
      {with("repose-pose", "other"), "p.json: format:"},
      {with("\"angle_deg\":90", "\"angle_deg\":\"90\""),
       "p.json: groups[0].rotation.angle_deg: expected a number"},
      {with("\"axis\":[0,0,2]", "\"axis\":[0,0,0]"), "p.json: groups[0].rotation.axis: zero"},
      {with("\"axis\":[0,0,2]", "\"axis\":[0,0]"), "p.json: groups[0].rotation.axis: expected"},
      {with("\"parts\":[4]", "\"parts\":[-4]"), "p.json: groups[0].select.parts[0]:"},
      {with("\"parts\":[4]", "\"cage_vertices\":[1.5]"),
       "p.json: groups[0].select.cage_vertices[0]: expected an integer"},
      {with("\"parts\":[4]", "\"region\":{\"box\":[0,0,0,1,1]}"),
       "p.json: groups[0].select.region.box"},
      {with("\"name\":\"body\"", "\"name\":\"arm\""), "p.json: groups[1].name: empty or used"},
      {with("\"fixed\":true", "\"fixed\":true,\"translation\":[1,1,1]"),
       "p.json: groups[1]: a fixed group"},
      {with("\"translation\":[10,0,0]", "\"translaton\":[10,0,0]"),
       "p.json: groups[0].translaton: unknown field"},
      {with("\"rest\":true", "\"rest\":true,\"parts\":[3]"), "p.json: groups[1].select: rest"},
      // Found by the PoseJson fuzzer: a number beyond double threw json::out_of_range past the
      // parse_error handler and terminated the process.
      {with("\"angle_deg\":90", "\"angle_deg\":2222222222222222e22222"), "p.json: not valid JSON"},
      {with("\"angle_deg\":90", "\"angle_deg\":-1e99999"), "p.json: not valid JSON"},
      // An index an int cannot hold is refused, not wrapped (4294967297 would become 1).
      {with("\"parts\":[4]", "\"cage_vertices\":[4294967297]"),
       "p.json: groups[0].select.cage_vertices[0]: integer out of range"},
      {with("\"version\":1", "\"version\":18446744073709551615"),
       "p.json: version: integer out of range"},
  };
  for (const auto& [text, message] : cases) {
    const std::string e = errorOf(text);
    EXPECT_EQ(e.rfind(message, 0), 0u) << "got: " << e << "\nwanted: " << message;
  }
  EXPECT_EQ(errorOf(kMinimal), "");
  EXPECT_THROW(readPoseFile("/nonexistent/x.pose.json"), Error);
}

TEST(PoseFile, GroupsResolveToCageVerticesAndBodyParts) {
  PhantomOptions po;
  po.voxelMm = 8;
  const Phantom phantom(po);
  const auto [organs, parts] = phantom.makeVolumes();
  const TriangleMesh cage = buildCage(parts, {}).mesh;
  const TransferMesh mesh = buildTransferMesh(parts, {});
  const Pose pose = suitePose("elbow90", phantom);
  const std::vector<RigidHandle> handles = resolveHandles(pose, cage, mesh, parts.labels());
  ASSERT_EQ(handles.size(), 2u);
  EXPECT_EQ(handles[0].parts, (std::vector<int>{kPartForearmLeft, kPartHandLeft}));
  EXPECT_EQ(handles[0].cageVertices.size() + handles[1].cageVertices.size(),
            std::size_t(cage.vertices.rows()));  // the rest takes every other vertex
  for (const int v : handles[0].cageVertices)    // over the left forearm or hand: below the elbow
    EXPECT_LT(cage.vertices(v, 2), phantom.joint("elbow_left").ras.z() + 60);
  EXPECT_EQ(std::count(handles[1].parts.begin(), handles[1].parts.end(), kPartForearmLeft), 0);
  EXPECT_GT(handles[1].parts.size(), 5u);

  Pose unknown = pose;
  unknown.groups[0].select.partNames = {"tail"};
  EXPECT_THROW(resolveHandles(unknown, cage, mesh, parts.labels()), Error);
  Pose twice = pose;
  twice.groups[1].select = PoseSelection{};
  twice.groups[1].select.cageVertices = {handles[0].cageVertices[0]};
  EXPECT_THROW(resolveHandles(twice, cage, mesh, parts.labels()), Error);

  // Posing: the group's vertices move exactly, the fixed rest stays.
  std::vector<RigidHandle> posed = handles;
  setMotions(posed, pose.frames()[0].second);
  const Eigen::MatrixX3d c = poseCage(cage, posed);
  for (const int v : posed[1].cageVertices) EXPECT_EQ(c.row(v), cage.vertices.row(v));
  for (const int v : posed[0].cageVertices)
    EXPECT_LT((Eigen::Vector3d(c.row(v)) - posed[0].motion * Eigen::Vector3d(cage.vertices.row(v)))
                  .norm(),
              1e-9);
}

// Posing by joint on the phantom's skeleton: a joint's group selects the parts distal to it,
// turns about its named axis through it, and resolves to the skeleton's numbers; named again, the
// pose file is the suite's named form; an axis the joint does not have is refused by name.
TEST(PoseFile, JointGroupsSelectTheDistalPartsAndNameTheirJointWhenWritten) {
  repose::PhantomOptions po;
  po.voxelMm = 8;
  const repose::Skeleton skeleton =
      repose::parseSkeleton(repose::Phantom(po).skeletonJson(), "skeleton.json");
  using Parts = std::vector<std::string>;
  EXPECT_EQ(repose::jointDistalParts(skeleton, "shoulder_left"),
            (Parts{"upper_arm_left", "forearm_left", "hand_left"}));
  EXPECT_EQ(repose::jointDistalParts(skeleton, "elbow_left"), (Parts{"forearm_left", "hand_left"}));
  EXPECT_EQ(repose::jointDistalParts(skeleton, "knee_right"), (Parts{"shank_right", "foot_right"}));
  EXPECT_EQ(repose::jointDistalParts(skeleton, "ankle_left"), (Parts{"foot_left"}));
  EXPECT_TRUE(repose::jointDistalParts(skeleton, "tail").empty());

  repose::Pose pose;
  pose.name = "by joint";
  pose.groups.push_back(repose::jointGroup(skeleton, "elbow_left", "flexion", 90));
  repose::PoseGroup rest;
  rest.name = "rest";
  rest.select.rest = true;
  rest.fixed = true;
  pose.groups.push_back(rest);
  EXPECT_EQ(pose.groups[0].name, "elbow_left.flexion");
  EXPECT_TRUE(repose::poseNamesJoints(pose));
  repose::Pose resolved = pose;
  repose::resolvePoseJoints(resolved, skeleton);
  const repose::SkeletonJoint* elbow = skeleton.find("elbow_left");
  ASSERT_NE(elbow, nullptr);
  EXPECT_TRUE(resolved.groups[0].transform.pivot.isApprox(elbow->centre));
  EXPECT_TRUE(
      resolved.groups[0].transform.axis.isApprox(skeleton.axis("elbow_left.flexion", "test")));
  EXPECT_FALSE(repose::poseNamesJoints(resolved));
  // Named again: the same text as the pose built by name.
  repose::nameJointGroups(resolved, skeleton);
  EXPECT_EQ(repose::poseToJson(resolved), repose::poseToJson(pose));

  EXPECT_THROW(repose::jointGroup(skeleton, "elbow_left", "abduction", 10), repose::Error);
  EXPECT_THROW(repose::jointGroup(skeleton, "tail", "flexion", 10), repose::Error);
  EXPECT_EQ(repose::jointRangeDeg("elbow_left", "flexion"), std::make_pair(0.0, 150.0));
  EXPECT_EQ(repose::jointRangeDeg("shoulder_right", "abduction"), std::make_pair(-30.0, 180.0));
  EXPECT_EQ(repose::jointRangeDeg("tail", "wag"), std::make_pair(-180.0, 180.0));
}

// Several turns about one pivot ("then"): applied in order about the rest axes; written and read
// back the same; keyframes replace the list.
TEST(PoseFile, TurnsComposeInOrderAboutThePivotAndSurviveARoundTrip) {
  const std::string text = R"({"format":"repose-pose","version":1,"name":"t","groups":[
    {"name":"arm","select":{"parts":[4]},
     "rotation":{"axis":[0,0,1],"angle_deg":90,"pivot":[1,2,3],
                 "then":[{"axis":[1,0,0],"angle_deg":90},{"axis":[0,1,0]}]}},
    {"name":"body","select":{"rest":true},"fixed":true}]})";
  const Pose pose = parsePose(text, "t");
  ASSERT_EQ(pose.groups[0].transform.then.size(), 2u);
  EXPECT_EQ(pose.groups[0].transform.then[1].angleDeg, 0);  // an angle left out is 0
  const auto frames = pose.frames();
  // (2,2,3): about z through the pivot to (1,3,3), then about x through it to (1,2,4).
  EXPECT_LT((frames[0].second[0] * Eigen::Vector3d(2, 2, 3) - Eigen::Vector3d(1, 2, 4)).norm(),
            1e-12);
  // A keyframe's list replaces the base's: empty, the first turn only.
  std::string keyed = text;
  keyed.insert(keyed.size() - 1,
               R"(,"keyframes":[{"name":"k","groups":{"arm":{"rotation":{"then":[]}}}}])");
  const auto keyedFrames = parsePose(keyed, "k").frames();
  ASSERT_EQ(keyedFrames.size(), 1u);
  EXPECT_LT((keyedFrames[0].second[0] * Eigen::Vector3d(2, 2, 3) - Eigen::Vector3d(1, 3, 3)).norm(),
            1e-12);
  const Pose again = parsePose(poseToJson(pose), "again");
  EXPECT_EQ(poseToJson(again), poseToJson(pose));
  EXPECT_TRUE(again.frames()[0].second[0].isApprox(frames[0].second[0]));
  // Bad turns are refused by field.
  auto error = [&](const std::string& from, const std::string& to) {
    std::string t = text;
    t.replace(t.find(from), from.size(), to);
    return errorOf(t);
  };
  EXPECT_EQ(error(R"({"axis":[0,1,0]})", R"({"angle_deg":3})")
                .rfind("p.json: groups[0].rotation.then[1].axis: required", 0),
            0u);
  EXPECT_EQ(error(R"({"axis":[0,1,0]})", R"({"axis":[0,0,0]})")
                .rfind("p.json: groups[0].rotation.then[1].axis: zero", 0),
            0u);
  EXPECT_EQ(error(R"([{"axis":[1,0,0],"angle_deg":90},{"axis":[0,1,0]}])", R"({"a":1})")
                .rfind("p.json: groups[0].rotation.then: expected an array", 0),
            0u);
}

// A chain: a group that follows another moves by its own transform, then by the other's motion
// (the forearm turned at the elbow goes where the shoulder takes the upper arm); unknown groups,
// cycles and fixed followers are refused.
TEST(PoseFile, AGroupThatFollowsAnotherIsCarriedByItsMotion) {
  const std::string text = R"({"format":"repose-pose","version":1,"name":"c","groups":[
    {"name":"forearm","select":{"parts":[5]},"follows":"upper",
     "rotation":{"axis":[0,1,0],"angle_deg":90,"pivot":[0,0,-30]}},
    {"name":"upper","select":{"parts":[4]},
     "rotation":{"axis":[1,0,0],"angle_deg":90,"pivot":[0,0,0]},"translation":[5,0,0]},
    {"name":"body","select":{"rest":true},"fixed":true}]})";
  const Pose pose = parsePose(text, "c");
  const auto m = pose.frames()[0].second;
  const Eigen::Isometry3d own = pose.groups[0].transform.isometry();
  EXPECT_TRUE(m[0].isApprox(m[1] * own));
  // The wrist at (0,0,-60): about the elbow's y to (-30,0,-30), then the shoulder's x to
  // (-30,30,0), then +5 in x.
  EXPECT_LT((m[0] * Eigen::Vector3d(0, 0, -60) - Eigen::Vector3d(-25, 30, 0)).norm(), 1e-12);
  EXPECT_EQ(poseToJson(parsePose(poseToJson(pose), "again")), poseToJson(pose));
  auto error = [&](const std::string& from, const std::string& to) {
    std::string t = text;
    t.replace(t.find(from), from.size(), to);
    return errorOf(t);
  };
  EXPECT_EQ(error(R"("follows":"upper")", R"("follows":"uper")")
                .rfind("p.json: groups[0].follows: no group is named \"uper\"", 0),
            0u);
  EXPECT_EQ(error(R"("follows":"upper")", R"("follows":"forearm")")
                .rfind("p.json: groups[0].follows: a group cannot follow itself", 0),
            0u);
  EXPECT_EQ(error(R"("select":{"parts":[4]},)", R"("select":{"parts":[4]},"follows":"forearm",)")
                .rfind("p.json: groups[0].follows: the chain", 0),
            0u);
  EXPECT_EQ(error(R"("fixed":true)", R"("fixed":true,"follows":"upper")")
                .rfind("p.json: groups[2].follows: a fixed group", 0),
            0u);
  // Built in code, a cycle is refused by frames() too.
  Pose cycle = pose;
  cycle.groups[1].follows = "forearm";
  EXPECT_THROW(cycle.frames(), Error);
}

// Posing several joints of a limb at once: each joint's group turns about all its axes, the
// shoulder's keeps the upper arm and carries the elbow's (forearm and hand), whichever is set
// first; angles survive setting a joint again; a part's group gives way; the written pose names
// every joint and axis and poses like the numbers.
TEST(PoseFile, JointGroupsChainAlongTheLimbAndTurnAboutEveryAxis) {
  repose::PhantomOptions po;
  po.voxelMm = 8;
  const Skeleton skeleton = parseSkeleton(Phantom(po).skeletonJson(), "skeleton.json");
  LabelTable parts;
  Label handLabel;
  handLabel.value = 7;
  handLabel.name = "hand_left";
  parts.set(handLabel);
  using Parts = std::vector<std::string>;
  auto group = [](const Pose& p, const std::string& name) -> const PoseGroup& {
    for (const PoseGroup& g : p.groups)
      if (g.name == name) return g;
    throw Error("no group " + name);
  };
  for (const bool elbowFirst : {false, true}) {
    Pose pose;
    pose.name = "chain";
    PoseGroup hand;  // a part's group on the hand: the elbow's group takes the hand over
    hand.name = "hand";
    hand.select.parts = {7};
    pose.groups.push_back(hand);
    const std::vector<std::string> order =
        elbowFirst ? std::vector<std::string>{"elbow_left", "shoulder_left"}
                   : std::vector<std::string>{"shoulder_left", "elbow_left"};
    for (const std::string& joint : order)
      EXPECT_EQ(setJointGroup(pose, skeleton, joint, parts), joint);
    ASSERT_EQ(pose.groups.size(), 3u) << poseToJson(pose);  // shoulder, elbow, rest
    EXPECT_EQ(group(pose, "shoulder_left").select.partNames, Parts{"upper_arm_left"});
    EXPECT_EQ(group(pose, "elbow_left").select.partNames, (Parts{"forearm_left", "hand_left"}));
    EXPECT_EQ(group(pose, "elbow_left").follows, "shoulder_left");
    EXPECT_EQ(group(pose, "shoulder_left").follows, "");
    EXPECT_TRUE(group(pose, "rest").fixed);
    // A turn per axis, named.
    const SkeletonJoint& shoulder = *skeleton.find("shoulder_left");
    const PoseTransform& t = group(pose, "shoulder_left").transform;
    ASSERT_EQ(t.then.size() + 1, shoulder.axes.size());
    EXPECT_EQ(t.pivotJoint, "shoulder_left");
    // The limb's rotation first, flexion last, whatever order the file lists them in.
    EXPECT_EQ(t.axisName, "shoulder_left.rotation");
    EXPECT_EQ(t.then.back().axisName, "shoulder_left.flexion");
    EXPECT_EQ(jointTurnAxes(shoulder), (Parts{"rotation", "abduction", "flexion"}));
  }
  // Resolved and posed: abduction 90 at the shoulder, flexion 90 at the elbow.
  Pose pose;
  pose.name = "chain";
  setJointGroup(pose, skeleton, "shoulder_left", parts);
  setJointGroup(pose, skeleton, "elbow_left", parts);
  Pose resolved = pose;
  resolvePoseJoints(resolved, skeleton);
  const SkeletonJoint& shoulder = *skeleton.find("shoulder_left");
  const SkeletonJoint& elbow = *skeleton.find("elbow_left");
  const SkeletonJoint& wrist = *skeleton.find("wrist_left");
  auto axisIndex = [](const SkeletonJoint& j, const std::string& axis) {
    const std::vector<std::string> axes = jointTurnAxes(j);
    return std::size_t(std::find(axes.begin(), axes.end(), axis) - axes.begin());
  };
  auto setAngle = [](PoseGroup& g, std::size_t k, double angle) {
    (k == 0 ? g.transform.angleDeg : g.transform.then[k - 1].angleDeg) = angle;
  };
  for (PoseGroup& g : resolved.groups) {
    if (g.name == "shoulder_left") setAngle(g, axisIndex(shoulder, "abduction"), 90);
    if (g.name == "elbow_left") setAngle(g, axisIndex(elbow, "flexion"), 90);
  }
  const auto m = resolved.frames()[0].second;
  const Eigen::Isometry3d abduct = Eigen::Translation3d(shoulder.centre) *
                                   Eigen::AngleAxisd(M_PI / 2, *shoulder.axis("abduction")) *
                                   Eigen::Translation3d(-shoulder.centre);
  const Eigen::Isometry3d flex = Eigen::Translation3d(elbow.centre) *
                                 Eigen::AngleAxisd(M_PI / 2, *elbow.axis("flexion")) *
                                 Eigen::Translation3d(-elbow.centre);
  EXPECT_LT((m[1] * wrist.centre - abduct * (flex * wrist.centre)).norm(), 1e-9);
  EXPECT_LT((m[1] * elbow.centre - abduct * elbow.centre).norm(), 1e-9);
  // Named again: the same as built by name, angles aside; setting a joint again keeps them.
  Pose named = resolved;
  nameJointGroups(named, skeleton);
  EXPECT_FALSE(named.groups[0].transform.pivotJoint.empty());
  EXPECT_EQ(named.groups[1].transform.axisName, pose.groups[1].transform.axisName);
  for (std::size_t k = 0; k < named.groups[0].transform.then.size(); ++k)
    EXPECT_EQ(named.groups[0].transform.then[k].axisName,
              pose.groups[0].transform.then[k].axisName);
  setJointGroup(named, skeleton, "elbow_left", parts);
  Pose again = named;
  resolvePoseJoints(again, skeleton);
  EXPECT_TRUE(again.frames()[0].second[1].isApprox(m[1], 1e-12));
  // The single-axis form of a joint becomes the joint's group, with its angle.
  Pose single;
  single.groups.push_back(jointGroup(skeleton, "elbow_left", "flexion", 40));
  setJointGroup(single, skeleton, "elbow_left", parts);
  EXPECT_EQ(
      group(single, "elbow_left").transform.angleDeg +
          [&] {
            double sum = 0;
            for (const PoseTurn& u : group(single, "elbow_left").transform.then) sum += u.angleDeg;
            return sum;
          }(),
      40);
  EXPECT_THROW(group(single, "elbow_left.flexion"), Error);
  EXPECT_THROW(setJointGroup(single, skeleton, "tail", parts), Error);
  EXPECT_EQ(jointOfGroup(skeleton, "elbow_left.flexion"), "elbow_left");
  EXPECT_EQ(jointOfGroup(skeleton, "elbow_left"), "elbow_left");
  EXPECT_EQ(jointOfGroup(skeleton, "elbow_left.abduction"), "");
  EXPECT_EQ(jointOfGroup(skeleton, "group 1"), "");
}
