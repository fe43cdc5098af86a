// The Logic's undo history of pose edits on its own: steps, drags as one step, redo forgotten
// by a new edit, nothing recorded for an edit that changes nothing.
#include "vtkSlicerReposePoseHistory.h"

#include <gtest/gtest.h>

TEST(vtkSlicerReposePoseHistory, UndoesRedoesAndKeepsADragAsOneStep) {
  vtkSlicerReposePoseHistory h;
  EXPECT_FALSE(h.CanUndo());
  EXPECT_FALSE(h.Undo());
  EXPECT_FALSE(h.Record("pose1", "a", "a"));  // no change, no step
  EXPECT_FALSE(h.CanUndo());
  ASSERT_TRUE(h.Record("pose1", "a", "b"));
  ASSERT_TRUE(h.Record("pose1", "b", "c"));  // outside a drag: a second step
  // A drag: three edits, one step from its first text to its last.
  h.BeginInteraction();
  ASSERT_TRUE(h.Record("pose1", "c", "d1"));
  ASSERT_TRUE(h.Record("pose1", "d1", "d2"));
  ASSERT_TRUE(h.Record("pose1", "d2", "d3"));
  h.EndInteraction();
  auto step = h.Undo();
  ASSERT_TRUE(step);
  EXPECT_EQ(step->before, "c");
  EXPECT_EQ(step->after, "d3");
  EXPECT_TRUE(h.CanRedo());
  step = h.Redo();
  ASSERT_TRUE(step);
  EXPECT_EQ(step->after, "d3");
  // Two undos back to "b" then "a"; a new edit forgets the redo side.
  h.Undo();
  EXPECT_EQ(h.Undo()->before, "b");
  ASSERT_TRUE(h.Record("pose1", "b", "x"));
  EXPECT_FALSE(h.CanRedo());
  EXPECT_EQ(h.Undo()->after, "x");
  EXPECT_EQ(h.Undo()->before, "a");
  EXPECT_FALSE(h.Undo());
  // A drag that moves to another node starts its own step there.
  h.BeginInteraction();
  h.Record("pose1", "a", "p");
  h.Record("pose2", "q", "r");
  h.EndInteraction();
  EXPECT_EQ(h.Undo()->nodeID, "pose2");
  EXPECT_EQ(h.Undo()->nodeID, "pose1");
  h.Clear();
  EXPECT_FALSE(h.CanUndo() || h.CanRedo());
}
