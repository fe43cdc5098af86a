#include "repose/pose/PoseEdit.h"

#include "repose/util/Error.h"

#include <algorithm>
#include <cmath>
#include <set>

namespace repose {
namespace {

std::string who(const Pose& pose) {
  return "pose " + (pose.name.empty() ? std::string("(unnamed)") : pose.name);
}

// The group named `group` of a pose, const or not; throws for an unknown one.
template <class P>
auto& findGroup(P& pose, const std::string& group) {
  const auto it = std::find_if(pose.groups.begin(), pose.groups.end(),
                               [&](const PoseGroup& g) { return g.name == group; });
  if (it == pose.groups.end()) throw Error(who(pose) + ": no group \"" + group + "\"");
  return *it;
}

// A group an edit can move: an unknown or fixed one throws, naming it.
PoseGroup& movableGroup(Pose& pose, const std::string& group) {
  PoseGroup& g = findGroup(pose, group);
  if (g.fixed) throw Error(who(pose) + ": group \"" + group + "\" is fixed");
  return g;
}

// The keyframe an edit applies to, none without keyframes (the base pose).
const PoseKeyframe* editedKeyframe(const Pose& pose, std::size_t frame) {
  if (pose.keyframes.empty()) return nullptr;
  return &pose.keyframes[std::min(frame, pose.keyframes.size() - 1)];
}

void setTransformIn(Pose& pose, std::size_t frame, PoseGroup& group, const PoseTransform& t) {
  if (pose.keyframes.empty()) {
    group.transform = t;
    return;
  }
  PoseKeyframe& k = pose.keyframes[std::min(frame, pose.keyframes.size() - 1)];
  auto entry = std::find_if(k.transforms.begin(), k.transforms.end(),
                            [&](const auto& e) { return e.first == group.name; });
  if (entry == k.transforms.end())
    k.transforms.emplace_back(group.name, t);
  else
    entry->second = t;
}

// A transform from numbers, checked: a rotation axis that is not zero (made unit length), a
// finite angle, pivot and translation.
PoseTransform checkedTransform(const Eigen::Vector3d& axis, double angleDeg,
                               const Eigen::Vector3d& pivot, const Eigen::Vector3d& translation,
                               const std::string& group) {
  if (!(axis.norm() > 0) || !axis.allFinite()) throw Error("the rotation axis is zero");
  if (!std::isfinite(angleDeg) || !pivot.allFinite() || !translation.allFinite())
    throw Error("the transform of group \"" + group + "\" is not finite");
  PoseTransform t;
  t.axis = axis.normalized();
  t.angleDeg = angleDeg;
  t.pivot = pivot;
  t.translation = translation;
  return t;
}

// The motion of the groups a group follows, in the frame (identity for none): what its own
// transform is carried by.
Eigen::Isometry3d carriedBy(const Pose& pose, const PoseGroup& group, std::size_t frame) {
  Eigen::Isometry3d m = Eigen::Isometry3d::Identity();
  std::size_t steps = 0;
  for (std::string up = group.follows; !up.empty() && steps++ <= pose.groups.size();) {
    const PoseGroup& g = poseGroup(pose, up);
    m = (g.fixed ? Eigen::Isometry3d::Identity() : groupTransform(pose, g.name, frame).isometry()) *
        m;
    up = g.follows;
  }
  return m;
}

}  // namespace

Pose newPose(const std::string& name) {
  Pose pose;
  pose.name = name.empty() ? "pose" : name;
  PoseGroup rest;
  rest.name = "rest";
  rest.select.rest = true;
  rest.fixed = true;
  pose.groups.push_back(rest);
  return pose;
}

const PoseGroup& poseGroup(const Pose& pose, const std::string& group) {
  return findGroup(pose, group);
}

PoseTransform groupTransform(const Pose& pose, const std::string& group, std::size_t frame) {
  const PoseGroup& g = poseGroup(pose, group);
  if (const PoseKeyframe* k = editedKeyframe(pose, frame))
    for (const auto& [name, t] : k->transforms)
      if (name == g.name) return t;
  return g.transform;
}

void setGroupTransform(Pose& pose, const std::string& group, std::size_t frame,
                       const Eigen::Vector3d& axis, double angleDeg, const Eigen::Vector3d& pivot,
                       const Eigen::Vector3d& translation) {
  PoseGroup& g = movableGroup(pose, group);
  PoseTransform t = checkedTransform(axis, angleDeg, pivot, translation, group);
  t.then = groupTransform(pose, group, frame).then;  // a joint group's other axes stay turned
  setTransformIn(pose, frame, g, t);
}

std::vector<GroupTurn> groupTurns(const Pose& pose, const std::string& group, std::size_t frame) {
  const PoseTransform t = groupTransform(pose, group, frame);
  std::vector<GroupTurn> turns{{t.axisName, t.axis, t.angleDeg}};
  for (const PoseTurn& u : t.then) turns.push_back({u.axisName, u.axis, u.angleDeg});
  return turns;
}

void setGroupTurnAngle(Pose& pose, const std::string& group, std::size_t frame, int turn,
                       double angleDeg) {
  PoseGroup& g = movableGroup(pose, group);
  PoseTransform t = groupTransform(pose, group, frame);
  if (turn < 0 || std::size_t(turn) > t.then.size())
    throw Error(who(pose) + ": group \"" + group + "\" has no turn " + std::to_string(turn));
  if (!std::isfinite(angleDeg)) throw Error("the angle is not finite");
  (turn == 0 ? t.angleDeg : t.then[std::size_t(turn - 1)].angleDeg) = angleDeg;
  setTransformIn(pose, frame, g, t);
}

Eigen::Isometry3d groupMotion(const Pose& pose, const std::string& group, std::size_t frame) {
  const PoseGroup& g = poseGroup(pose, group);
  if (g.fixed) return Eigen::Isometry3d::Identity();
  return carriedBy(pose, g, frame) * groupTransform(pose, group, frame).isometry();
}

void setGroupMotion(Pose& pose, const std::string& group, std::size_t frame,
                    const Eigen::Isometry3d& world) {
  PoseGroup& g = movableGroup(pose, group);
  const PoseTransform old = groupTransform(pose, group, frame);
  if (!old.then.empty())
    throw Error(who(pose) + ": group \"" + group +
                "\" turns about several axes of its joint: its sliders move it");
  const Eigen::Matrix3d W = world.linear();
  if (!W.allFinite() || !world.translation().allFinite() ||
      !(W.transpose() * W).isApprox(Eigen::Matrix3d::Identity(), 1e-6) || W.determinant() < 0)
    throw Error(who(pose) + ": group \"" + group + "\": the motion is not a rigid one");
  // A follower's own part of the motion: what is left after the groups it follows.
  const Eigen::Isometry3d own = carriedBy(pose, g, frame).inverse() * world;
  const Eigen::Matrix3d R = own.linear();
  const Eigen::Vector3d shift = own.translation();
  // x' = R (x - p) + p + T with the group's own pivot p: T = shift + R p - p. The axis keeps the
  // direction it had, so the angle control still turns the same way after a drag.
  const Eigen::Vector3d& p = old.pivot;
  const Eigen::AngleAxisd aa(R);
  Eigen::Vector3d axis = aa.axis();
  double angle = aa.angle() * 180.0 / M_PI;
  if (std::abs(angle) < 1e-9) {
    axis = old.axis;
    angle = 0;
  } else if (axis.dot(old.axis) < 0) {
    axis = -axis;
    angle = -angle;
  }
  // A new transform about the old pivot, in numbers (the box's motion is no joint's named axis).
  setTransformIn(pose, frame, g, checkedTransform(axis, angle, p, shift + R * p - p, group));
}

std::string addCageGroup(Pose& pose, std::vector<int> vertices, int bodyPart,
                         const Eigen::MatrixX3d& restCage,
                         const std::function<std::vector<int>(const std::string&)>& verticesOf) {
  std::sort(vertices.begin(), vertices.end());
  vertices.erase(std::unique(vertices.begin(), vertices.end()), vertices.end());
  if (vertices.empty()) throw Error("the selection has no cage vertex");
  for (int v : vertices)
    if (v < 0 || v >= restCage.rows())
      throw Error("cage vertex " + std::to_string(v) + " out of range (the cage has " +
                  std::to_string(restCage.rows()) + ")");
  // The new group takes its vertices from the groups that had them: from "the rest" silently,
  // from a group of listed vertices by removing them (a group left empty goes, with its keyframe
  // entries). A group that selects by region or body part cannot give some away.
  const std::set<int> taken(vertices.begin(), vertices.end());
  std::vector<std::string> emptied;
  for (PoseGroup& group : pose.groups) {
    if (group.select.rest) continue;
    const std::vector<int> owned = verticesOf(group.name);
    if (std::none_of(owned.begin(), owned.end(), [&](int v) { return taken.count(v) > 0; }))
      continue;
    if (group.select.region || !group.select.parts.empty() || !group.select.partNames.empty())
      throw Error("the selection overlaps group \"" + group.name +
                  "\", which selects by region or body part; edit that group instead");
    auto& own = group.select.cageVertices;
    own.erase(std::remove_if(own.begin(), own.end(), [&](int v) { return taken.count(v) > 0; }),
              own.end());
    if (own.empty()) emptied.push_back(group.name);
  }
  for (const std::string& name : emptied) {
    pose.groups.erase(std::find_if(pose.groups.begin(), pose.groups.end(),
                                   [&](const PoseGroup& g) { return g.name == name; }));
    for (PoseKeyframe& k : pose.keyframes)
      k.transforms.erase(std::remove_if(k.transforms.begin(), k.transforms.end(),
                                        [&](const auto& e) { return e.first == name; }),
                         k.transforms.end());
  }
  PoseGroup group;
  for (int n = 1; group.name.empty(); ++n) {
    const std::string candidate = "group " + std::to_string(n);
    if (std::none_of(pose.groups.begin(), pose.groups.end(),
                     [&](const PoseGroup& g) { return g.name == candidate; }))
      group.name = candidate;
  }
  if (bodyPart > 0)
    group.select.parts = {bodyPart};
  else
    group.select.cageVertices = vertices;
  // Pivot: the selection's centre at rest, where a rotation of the handle turns it in place.
  Eigen::Vector3d centre = Eigen::Vector3d::Zero();
  for (int v : vertices) centre += restCage.row(v).transpose();
  group.transform.pivot = centre / double(vertices.size());
  group.transform.axis = Eigen::Vector3d::UnitX();
  pose.groups.push_back(group);
  return group.name;
}

void addPoseSeparation(Pose& pose, const std::string& partA, const std::string& partB,
                       const std::string& region) {
  PoseSeparation separation;
  const std::string names[2] = {partA, partB};
  for (int k = 0; k < 2; ++k) {
    const std::string& n = names[k];
    if (n.empty()) throw Error("a separation needs two body parts");
    if (n.find_first_not_of("0123456789") == std::string::npos)
      separation.parts[std::size_t(k)] = std::stoi(n);
    else
      separation.partNames[std::size_t(k)] = n;
  }
  if (names[0] == names[1]) throw Error("a part cannot be separated from itself");
  separation.region = Region::parse(region);
  pose.separations.push_back(separation);
}

}  // namespace repose
