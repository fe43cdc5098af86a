// The undo history of pose edits (pose/PoseHistory.h): steps of snapshots, a drag as one step,
// redo forgotten by a new edit, nothing recorded for an edit that changes nothing; samePose
// telling every field a pose file holds.
#include "repose/pose/PoseEdit.h"
#include "repose/pose/PoseHistory.h"

#include <gtest/gtest.h>

namespace {

using Snapshot = repose::PoseHistory::Snapshot;

// A pose whose "arm" group is turned by `deg`.
Snapshot turned(double deg) {
  repose::Pose pose = repose::newPose("p");
  repose::PoseGroup arm;
  arm.name = "arm";
  arm.select.cageVertices = {1, 2};
  arm.transform.angleDeg = deg;
  pose.groups.push_back(arm);
  return std::make_shared<const repose::Pose>(pose);
}

}  // namespace

TEST(PoseHistory, UndoesRedoesAndKeepsADragAsOneStep) {
  repose::PoseHistory h;
  const Snapshot a = turned(0), b = turned(10), c = turned(20), x = turned(99);
  EXPECT_FALSE(h.canUndo());
  EXPECT_FALSE(h.undo());
  EXPECT_FALSE(h.record("pose1", a, turned(0)));  // the same pose, another copy: no step
  EXPECT_FALSE(h.record("pose1", a, nullptr));
  EXPECT_FALSE(h.canUndo());
  ASSERT_TRUE(h.record("pose1", a, b));
  ASSERT_TRUE(h.record("pose1", b, c));  // outside a drag: a second step
  // A drag: three edits, one step from its first pose to its last.
  h.beginInteraction();
  EXPECT_TRUE(h.interacting());
  const Snapshot d1 = turned(21), d2 = turned(22), d3 = turned(23);
  ASSERT_TRUE(h.record("pose1", c, d1));
  ASSERT_TRUE(h.record("pose1", d1, d2));
  ASSERT_TRUE(h.record("pose1", d2, d3));
  h.endInteraction();
  auto step = h.undo();
  ASSERT_TRUE(step);
  EXPECT_EQ(step->before, c);  // the snapshot itself, shared, not a copy
  EXPECT_EQ(step->after, d3);
  EXPECT_TRUE(h.canRedo());
  step = h.redo();
  ASSERT_TRUE(step);
  EXPECT_EQ(step->after, d3);
  // Two undos back to b then a; a new edit forgets the redo side.
  h.undo();
  EXPECT_EQ(h.undo()->before, b);
  ASSERT_TRUE(h.record("pose1", b, x));
  EXPECT_FALSE(h.canRedo());
  EXPECT_EQ(h.undo()->after, x);
  EXPECT_EQ(h.undo()->before, a);
  EXPECT_FALSE(h.undo());
  // A drag that moves to another pose starts its own step there.
  h.beginInteraction();
  h.record("pose1", a, b);
  h.record("pose2", c, x);
  h.endInteraction();
  EXPECT_EQ(h.undo()->target, "pose2");
  EXPECT_EQ(h.undo()->target, "pose1");
  h.clear();
  EXPECT_FALSE(h.canUndo() || h.canRedo());
}

TEST(PoseHistory, SamePoseTellsEveryFieldOfAPoseFile) {
  const repose::Pose base = *turned(5);
  EXPECT_TRUE(repose::samePose(base, base));
  // Each change of one field makes another pose.
  std::vector<std::function<void(repose::Pose&)>> changes = {
      [](repose::Pose& p) { p.name = "q"; },
      [](repose::Pose& p) { p.description = "d"; },
      [](repose::Pose& p) { p.jointRings = 2; },
      [](repose::Pose& p) { p.scapulohumeralRhythm = false; },
      [](repose::Pose& p) { p.groups[1].transform.pivot.x() = 1; },
      [](repose::Pose& p) { p.groups[1].transform.translation.z() = 1; },
      [](repose::Pose& p) { p.groups[1].transform.then.push_back({}); },
      [](repose::Pose& p) { p.groups[1].transform.axisName = "elbow_left.flexion"; },
      [](repose::Pose& p) { p.groups[1].follows = "rest"; },
      [](repose::Pose& p) { p.groups[1].select.cageVertices.push_back(3); },
      [](repose::Pose& p) {
        p.keyframes.push_back({"k", {}});
      },
      [](repose::Pose& p) { repose::addPoseSeparation(p, "hand", "thigh", "box:0,0,0,1,1,1"); },
  };
  for (std::size_t c = 0; c < changes.size(); ++c) {
    repose::Pose changed = base;
    changes[c](changed);
    EXPECT_FALSE(repose::samePose(base, changed)) << "change " << c;
  }
}
