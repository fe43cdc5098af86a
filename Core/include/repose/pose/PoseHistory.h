// The undo history of pose edits, for every front end that edits poses (the workbench's Logic;
// a script may keep one too). Each step is one pose's state before and after an edit, held as
// immutable snapshots a front end shares with whatever holds the pose (a node): undo hands back
// the snapshot to put back, with no copy and no text to parse. The edits of a drag (between
// beginInteraction and endInteraction) on one pose are one step, however many there are; an
// edit that changes nothing (samePose) is no step.
#pragma once

#include "repose/pose/Pose.h"

#include <memory>
#include <optional>
#include <string>
#include <vector>

namespace repose {

// Whether two poses are the same in every field a pose file holds (names, groups with their
// selections and transforms, keyframes, separations, rhythms, joint rings).
bool samePose(const Pose& a, const Pose& b);

class PoseHistory {
 public:
  using Snapshot = std::shared_ptr<const Pose>;
  struct Step {
    std::string target;  // which pose (a node's ID)
    Snapshot before, after;
  };
  // Records `target` going from `before` to `after` and forgets what could be redone. False, and
  // nothing recorded, when the two are the same pose (or either is null).
  bool record(const std::string& target, const Snapshot& before, const Snapshot& after);
  void beginInteraction();
  void endInteraction();
  bool interacting() const { return interacting_; }
  // The step to undo (its `before` is to be put back), moved to the redo side; none when empty.
  std::optional<Step> undo();
  // The step to redo (its `after` is to be put back), moved back; none when empty.
  std::optional<Step> redo();
  bool canUndo() const { return !undo_.empty(); }
  bool canRedo() const { return !redo_.empty(); }
  void clear();

 private:
  std::vector<Step> undo_, redo_;
  bool interacting_ = false, interactionRecorded_ = false;
};

}  // namespace repose
