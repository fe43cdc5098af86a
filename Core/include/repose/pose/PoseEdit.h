// Editing a pose by the rules the workbench uses, for every front end (the module's Logic, Python):
// a group's transform in the frame being edited (its keyframe's, or the base pose's), its turns
// about a joint's axes, its motion in the world as a follower of other groups, new groups from a
// selection of cage vertices or a body part, separations, new poses. Each edit changes a Pose in
// memory and throws repose::Error, one line naming the pose and group, for what it refuses; the
// front end writes the pose where it keeps it (a node, a file) and records undo steps itself.
// Joint groups (posing a limb by its joints) are setJointGroup in Pose.h.
#pragma once

#include "repose/pose/Pose.h"

#include <Eigen/Geometry>

#include <array>
#include <cstddef>
#include <functional>
#include <string>
#include <vector>

namespace repose {

// A new pose named `name` ("pose" when empty) with one group, the fixed rest of the body.
Pose newPose(const std::string& name);

// The group named `group`; throws for an unknown one.
const PoseGroup& poseGroup(const Pose& pose, const std::string& group);

// The group's transform in frame `frame` of the pose: that keyframe's entry for it, or its base
// transform where the keyframe is silent or there are no keyframes (`frame` is clamped to the
// keyframes there are).
PoseTransform groupTransform(const Pose& pose, const std::string& group, std::size_t frame);

// Sets the group's transform in the frame (in the keyframe, or the base pose without keyframes)
// from numbers: the axis made unit length, the angle, pivot and translation finite; the group's
// further turns about a joint's other axes stay as they were. Throws for an unknown or fixed
// group, a zero axis, or values that are not finite.
void setGroupTransform(Pose& pose, const std::string& group, std::size_t frame,
                       const Eigen::Vector3d& axis, double angleDeg, const Eigen::Vector3d& pivot,
                       const Eigen::Vector3d& translation);

// The group's turns in the frame: its first turn, then each "then" turn (a joint group's axes in
// jointTurnAxes' order), with the joint axis's name where the pose names it.
struct GroupTurn {
  std::string axisName;
  Eigen::Vector3d axis;
  double angleDeg = 0;
};
std::vector<GroupTurn> groupTurns(const Pose& pose, const std::string& group, std::size_t frame);
// Sets the angle of turn `turn` (0: the first) of the group in the frame. Throws for a turn it
// does not have or an angle that is not finite.
void setGroupTurnAngle(Pose& pose, const std::string& group, std::size_t frame, int turn,
                       double angleDeg);

// The group's motion in the world in the frame: its own transform carried by the groups it
// follows (identity for a fixed group).
Eigen::Isometry3d groupMotion(const Pose& pose, const std::string& group, std::size_t frame);
// Sets the group's own transform so that its motion in the world is `world` (a drag of the 3D
// view's box): the part of `world` left after the groups it follows, as a rotation about its own
// pivot (the axis keeps the direction it had, so an angle control turns the same way after) and
// a translation. Throws for an unknown or fixed group, a group that turns about several axes of
// its joint (its sliders move it), or a motion that is not rigid.
void setGroupMotion(Pose& pose, const std::string& group, std::size_t frame,
                    const Eigen::Isometry3d& world);

// Adds a group holding the cage vertices `vertices` (or, with bodyPart > 0, selecting that body
// part of S, whose cage vertices `vertices` are), pivoted at their centre at rest (`restCage`,
// the cage's vertices), named "group N" with the first free N. It takes its vertices from the
// groups that had them: from the rest silently, from a group of listed vertices by removing them
// (a group left empty goes, with its keyframe entries). `verticesOf(name)` tells the cage
// vertices a group holds now (the rig resolves them). Throws for an empty selection, a vertex
// beyond the cage, or an overlap with a group that selects by region or body part. Returns the
// new group's name.
std::string addCageGroup(Pose& pose, std::vector<int> vertices, int bodyPart,
                         const Eigen::MatrixX3d& restCage,
                         const std::function<std::vector<int>(const std::string&)>& verticesOf);

// Adds a separation of body parts `partA` and `partB` (a label, or a name of S's label table)
// within `region` (Region::parse's text). Throws for an empty or the same part twice.
void addPoseSeparation(Pose& pose, const std::string& partA, const std::string& partB,
                       const std::string& region);

}  // namespace repose
