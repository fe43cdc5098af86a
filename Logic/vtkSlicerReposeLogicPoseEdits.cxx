// vtkSlicerReposeLogic, the pose edits: a group's transform set from the panel's controls or from
// the 3D view's transform widget (a 4x4 motion), new handle groups from a selection of cage
// vertices or a body part, new poses, and the undo/redo stacks they all share. Every edit is a
// new pose JSON on the pose node, so undo is restoring a string and the live frame follows the
// node's Modified.
#include "vtkMRMLReposePoseNode.h"
#include "vtkMRMLReposeScene.h"
#include "vtkSlicerReposeLogic.h"
#include "vtkSlicerReposeLogicGuarded.h"
#include "vtkSlicerReposeLogicRead.h"

#include <repose/pose/Pose.h>
#include <repose/skeleton/Skeleton.h>
#include <repose/util/Error.h>

#include <vtkMatrix4x4.h>

#include <Eigen/Geometry>

#include <algorithm>
#include <cmath>
#include <set>

namespace {

repose::PoseGroup& findGroup(repose::Pose& pose, const std::string& group,
                             const std::string& poseName) {
  const auto it = std::find_if(pose.groups.begin(), pose.groups.end(),
                               [&](const repose::PoseGroup& g) { return g.name == group; });
  if (it == pose.groups.end())
    throw repose::Error("pose " + poseName + ": no group \"" + group + "\"");
  return *it;
}

// A group an edit can move: an unknown or fixed one throws, naming it.
repose::PoseGroup& movableGroup(repose::Pose& pose, const std::string& group,
                                const std::string& poseName) {
  repose::PoseGroup& g = findGroup(pose, group, poseName);
  if (g.fixed) throw repose::Error("pose " + poseName + ": group \"" + group + "\" is fixed");
  return g;
}

// The keyframe an edit applies to: the node's current one, or none (the base pose).
repose::PoseKeyframe* editedKeyframe(repose::Pose& pose, vtkMRMLReposePoseNode* node) {
  if (pose.keyframes.empty()) return nullptr;
  return &pose.keyframes[std::min<std::size_t>(std::size_t(std::max(0, node->GetCurrentFrame())),
                                               pose.keyframes.size() - 1)];
}

// The group's transform in the edited frame (its base transform where the keyframe is silent).
repose::PoseTransform currentTransform(repose::Pose& pose, vtkMRMLReposePoseNode* node,
                                       const repose::PoseGroup& group) {
  if (repose::PoseKeyframe* k = editedKeyframe(pose, node))
    for (const auto& [name, t] : k->transforms)
      if (name == group.name) return t;
  return group.transform;
}

void setCurrentTransform(repose::Pose& pose, vtkMRMLReposePoseNode* node, repose::PoseGroup& group,
                         const repose::PoseTransform& t) {
  repose::PoseKeyframe* k = editedKeyframe(pose, node);
  if (!k) {
    group.transform = t;
    return;
  }
  auto entry = std::find_if(k->transforms.begin(), k->transforms.end(),
                            [&](const auto& e) { return e.first == group.name; });
  if (entry == k->transforms.end())
    k->transforms.emplace_back(group.name, t);
  else
    entry->second = t;
}

// A group's transform from numbers, checked: a rotation axis that is not zero (made unit length),
// a finite angle, pivot and translation. The panel's controls and the 3D box both set one.
repose::PoseTransform checkedTransform(const Eigen::Vector3d& axis, double angleDeg,
                                       const Eigen::Vector3d& pivot,
                                       const Eigen::Vector3d& translation,
                                       const std::string& group) {
  if (!(axis.norm() > 0) || !axis.allFinite()) throw repose::Error("the rotation axis is zero");
  repose::PoseTransform t;
  t.axis = axis.normalized();
  t.angleDeg = angleDeg;
  t.pivot = pivot;
  t.translation = translation;
  if (!std::isfinite(angleDeg) || !pivot.allFinite() || !translation.allFinite())
    throw repose::Error("the transform of group \"" + group + "\" is not finite");
  return t;
}

}  // namespace

void vtkSlicerReposeLogic::RecordPoseEdit(vtkMRMLReposePoseNode* node, const std::string& after) {
  if (this->History.Record(node->GetID(), node->GetPoseJSON(), after)) node->SetPoseJSON(after);
}

void vtkSlicerReposeLogic::BeginPoseInteraction() {
  this->History.BeginInteraction();
}

void vtkSlicerReposeLogic::EndPoseInteraction() {
  this->History.EndInteraction();
  this->Modified();  // the panel shows what it leaves out during a drag (the prediction)
}

bool vtkSlicerReposeLogic::SetPoseGroupTransform(vtkMRMLReposePoseNode* node,
                                                 const std::string& group,
                                                 const std::array<double, 3>& axis, double angleDeg,
                                                 const std::array<double, 3>& pivot,
                                                 const std::array<double, 3>& translation) {
  return this->Guarded<bool>(false, [&]() -> bool {
    if (!node) throw repose::Error("no pose");
    repose::Pose pose = repose::parsePose(node->GetPoseJSON(), node->GetName());
    repose::PoseGroup& g = movableGroup(pose, group, node->GetName());
    repose::PoseTransform t =
        checkedTransform(Eigen::Vector3d(axis[0], axis[1], axis[2]), angleDeg,
                         Eigen::Vector3d(pivot[0], pivot[1], pivot[2]),
                         Eigen::Vector3d(translation[0], translation[1], translation[2]), group);
    t.then = currentTransform(pose, node, g).then;  // a joint group's other axes stay turned
    setCurrentTransform(pose, node, g, t);
    this->RecordPoseEdit(node, repose::poseToJson(pose));
    return true;
  });
}

std::optional<vtkSlicerReposeLogic::GroupTransform> vtkSlicerReposeLogic::GetPoseGroupTransform(
    vtkMRMLReposePoseNode* node, const std::string& group) const {
  if (!node) return std::nullopt;
  try {
    repose::Pose pose = repose::parsePose(node->GetPoseJSON(), node->GetName());
    const repose::PoseGroup& g = findGroup(pose, group, node->GetName());
    if (g.fixed) return std::nullopt;
    const repose::PoseTransform t = currentTransform(pose, node, g);
    GroupTransform out;
    out.axis = {t.axis.x(), t.axis.y(), t.axis.z()};
    out.angleDeg = t.angleDeg;
    out.pivot = {t.pivot.x(), t.pivot.y(), t.pivot.z()};
    out.translation = {t.translation.x(), t.translation.y(), t.translation.z()};
    return out;
  } catch (const std::exception&) {
    return std::nullopt;  // a query: an unknown group is an answer, not an error to report
  }
}

namespace {
// The motion of the groups a group follows, in the edited frame (identity for none): what its
// own transform is carried by.
Eigen::Isometry3d carriedBy(repose::Pose& pose, vtkMRMLReposePoseNode* node,
                            const repose::PoseGroup& group) {
  Eigen::Isometry3d m = Eigen::Isometry3d::Identity();
  std::size_t steps = 0;
  for (std::string up = group.follows; !up.empty() && steps++ <= pose.groups.size();) {
    const repose::PoseGroup& g = findGroup(pose, up, node->GetName());
    m = (g.fixed ? Eigen::Isometry3d::Identity() : currentTransform(pose, node, g).isometry()) * m;
    up = g.follows;
  }
  return m;
}
}  // namespace

bool vtkSlicerReposeLogic::GetPoseGroupMatrix(vtkMRMLReposePoseNode* node, const std::string& group,
                                              vtkMatrix4x4* matrix) const {
  if (!matrix || !node) return false;
  try {
    repose::Pose pose = repose::parsePose(node->GetPoseJSON(), node->GetName());
    const repose::PoseGroup& g = findGroup(pose, group, node->GetName());
    if (g.fixed) return false;
    const Eigen::Matrix4d m =
        (carriedBy(pose, node, g) * currentTransform(pose, node, g).isometry()).matrix();
    for (int r = 0; r < 4; ++r)
      for (int c = 0; c < 4; ++c) matrix->SetElement(r, c, m(r, c));
    return true;
  } catch (const std::exception&) {
    return false;  // a query, as GetPoseGroupTransform
  }
}

std::vector<vtkSlicerReposeLogic::GroupTurn> vtkSlicerReposeLogic::GetPoseGroupTurns(
    vtkMRMLReposePoseNode* node, const std::string& group) const {
  if (!node) return {};
  try {
    repose::Pose pose = repose::parsePose(node->GetPoseJSON(), node->GetName());
    const repose::PoseGroup& g = findGroup(pose, group, node->GetName());
    if (g.fixed) return {};
    const repose::PoseTransform t = currentTransform(pose, node, g);
    auto turn = [](const std::string& name, const Eigen::Vector3d& axis, double angle) {
      return GroupTurn{name, {axis.x(), axis.y(), axis.z()}, angle};
    };
    std::vector<GroupTurn> turns{turn(t.axisName, t.axis, t.angleDeg)};
    for (const repose::PoseTurn& u : t.then) turns.push_back(turn(u.axisName, u.axis, u.angleDeg));
    return turns;
  } catch (const std::exception&) {
    return {};
  }
}

bool vtkSlicerReposeLogic::SetPoseGroupTurnAngle(vtkMRMLReposePoseNode* node,
                                                 const std::string& group, int turn,
                                                 double angleDeg) {
  return this->Guarded<bool>(false, [&]() -> bool {
    if (!node) throw repose::Error("no pose");
    repose::Pose pose = repose::parsePose(node->GetPoseJSON(), node->GetName());
    repose::PoseGroup& g = movableGroup(pose, group, node->GetName());
    repose::PoseTransform t = currentTransform(pose, node, g);
    if (turn < 0 || std::size_t(turn) > t.then.size())
      throw repose::Error("group \"" + group + "\" has no turn " + std::to_string(turn));
    if (!std::isfinite(angleDeg)) throw repose::Error("the angle is not finite");
    (turn == 0 ? t.angleDeg : t.then[std::size_t(turn - 1)].angleDeg) = angleDeg;
    setCurrentTransform(pose, node, g, t);
    this->RecordPoseEdit(node, repose::poseToJson(pose));
    return true;
  });
}

bool vtkSlicerReposeLogic::SetPoseGroupMatrix(vtkMRMLReposePoseNode* node, const std::string& group,
                                              vtkMatrix4x4* matrix) {
  this->LastErrorMessage.clear();
  // The pose is parsed once per call: a drag of the 3D box calls this on every mouse move, and
  // asking the group's transform, turns and carrier apart had parsed it four times.
  std::optional<repose::Pose> pose;
  repose::PoseGroup* g = nullptr;
  if (node) {
    try {
      pose = repose::parsePose(node->GetPoseJSON(), node->GetName());
      g = &findGroup(*pose, group, node->GetName());
    } catch (const std::exception&) {
      g = nullptr;
    }
  }
  if (!matrix || !g || g->fixed) {
    this->LastErrorMessage = "pose group \"" + group + "\" cannot be moved (unknown or fixed)";
    return false;
  }
  const repose::PoseTransform old = currentTransform(*pose, node, *g);
  if (!old.then.empty()) {
    this->LastErrorMessage =
        "pose group \"" + group + "\" turns about several axes of its joint: its sliders move it";
    return false;
  }
  Eigen::Matrix3d R;
  Eigen::Vector3d shift;
  for (int r = 0; r < 3; ++r) {
    for (int c = 0; c < 3; ++c) R(r, c) = matrix->GetElement(r, c);
    shift[r] = matrix->GetElement(r, 3);
  }
  if (!R.allFinite() || !shift.allFinite() ||
      !(R.transpose() * R).isApprox(Eigen::Matrix3d::Identity(), 1e-6) || R.determinant() < 0) {
    this->LastErrorMessage = "pose group \"" + group + "\": the motion is not a rigid one";
    return false;
  }
  // A follower's own part of the motion: what is left after the groups it follows.
  {
    Eigen::Isometry3d world = Eigen::Isometry3d::Identity();
    world.linear() = R;
    world.translation() = shift;
    const Eigen::Isometry3d own = carriedBy(*pose, node, *g).inverse() * world;
    R = own.linear();
    shift = own.translation();
  }
  // x' = R (x - p) + p + T with the group's own pivot p: T = shift + R p - p. The axis keeps the
  // direction it had, so the panel's angle control still turns the same way after a drag.
  const Eigen::Vector3d& p = old.pivot;
  Eigen::AngleAxisd aa(R);
  Eigen::Vector3d axis = aa.axis();
  double angle = aa.angle() * 180.0 / M_PI;
  if (std::abs(angle) < 1e-9) {
    axis = old.axis;
    angle = 0;
  } else if (axis.dot(old.axis) < 0) {
    axis = -axis;
    angle = -angle;
  }
  return this->Guarded<bool>(false, [&]() -> bool {
    // A new transform about the old pivot, as numbers (the box's motion is no joint's named
    // axis); it has no further turns (checked above).
    setCurrentTransform(*pose, node, *g,
                        checkedTransform(axis, angle, old.pivot, shift + R * p - p, group));
    this->RecordPoseEdit(node, repose::poseToJson(*pose));
    return true;
  });
}

vtkMRMLReposePoseNode* vtkSlicerReposeLogic::NewPose(const std::string& name) {
  return this->Guarded<vtkMRMLReposePoseNode*>(nullptr, [&]() -> vtkMRMLReposePoseNode* {
    repose::Pose pose;
    pose.name = name.empty() ? "pose" : name;
    repose::PoseGroup rest;
    rest.name = "rest";
    rest.select.rest = true;
    rest.fixed = true;
    pose.groups.push_back(rest);
    return this->AddPoseNode(pose.name, repose::poseToJson(pose));
  });
}

std::string vtkSlicerReposeLogic::AddPoseGroup(vtkMRMLReposePoseNode* node,
                                               const std::vector<int>& cageVertices, int bodyPart) {
  return this->Guarded<std::string>("", [&]() -> std::string {
    if (!node) throw repose::Error("no pose");
    if (node != this->GetLivePose())
      throw repose::Error("pose " + node->GetName() +
                          " is not being posed live (build the cage and mesh first)");
    repose::Pose pose = repose::parsePose(node->GetPoseJSON(), node->GetName());
    const std::vector<std::array<double, 3>> rest = this->GetLiveRestCage();
    std::vector<int> vertices =
        bodyPart > 0 ? this->GetLiveCageVerticesOfPart(bodyPart) : cageVertices;
    std::sort(vertices.begin(), vertices.end());
    vertices.erase(std::unique(vertices.begin(), vertices.end()), vertices.end());
    if (vertices.empty()) throw repose::Error("the selection has no cage vertex");
    for (int v : vertices)
      if (v < 0 || std::size_t(v) >= rest.size())
        throw repose::Error("cage vertex " + std::to_string(v) + " out of range (the cage has " +
                            std::to_string(rest.size()) + ")");
    // The new group takes its vertices from the groups that had them: from "the rest" silently,
    // from a group of listed vertices by removing them (a group left empty goes, with its
    // keyframe entries). A group that selects by region or body part cannot give some away.
    const std::set<int> taken(vertices.begin(), vertices.end());
    std::vector<std::string> emptied;
    for (std::size_t g = 0; g < pose.groups.size(); ++g) {
      repose::PoseGroup& group = pose.groups[g];
      if (group.select.rest) continue;
      const std::vector<int> owned = this->GetLiveGroupVertices(group.name);
      const bool overlaps =
          std::any_of(owned.begin(), owned.end(), [&](int v) { return taken.count(v) > 0; });
      if (!overlaps) continue;
      if (group.select.region || !group.select.parts.empty() || !group.select.partNames.empty())
        throw repose::Error("the selection overlaps group \"" + group.name +
                            "\", which selects by region or body part; edit that group instead");
      auto& own = group.select.cageVertices;
      own.erase(std::remove_if(own.begin(), own.end(), [&](int v) { return taken.count(v) > 0; }),
                own.end());
      if (own.empty()) emptied.push_back(group.name);
    }
    for (const std::string& name : emptied) {
      pose.groups.erase(std::find_if(pose.groups.begin(), pose.groups.end(),
                                     [&](const repose::PoseGroup& g) { return g.name == name; }));
      for (repose::PoseKeyframe& k : pose.keyframes)
        k.transforms.erase(std::remove_if(k.transforms.begin(), k.transforms.end(),
                                          [&](const auto& e) { return e.first == name; }),
                           k.transforms.end());
    }
    repose::PoseGroup group;
    for (int n = 1; group.name.empty(); ++n) {
      const std::string candidate = "group " + std::to_string(n);
      if (std::none_of(pose.groups.begin(), pose.groups.end(),
                       [&](const repose::PoseGroup& g) { return g.name == candidate; }))
        group.name = candidate;
    }
    if (bodyPart > 0)
      group.select.parts = {bodyPart};
    else
      group.select.cageVertices = vertices;
    // Pivot: the selection's centre at rest, where a rotation of the handle turns it in place.
    Eigen::Vector3d centre = Eigen::Vector3d::Zero();
    for (int v : vertices) centre += Eigen::Vector3d(rest[v][0], rest[v][1], rest[v][2]);
    group.transform.pivot = centre / double(vertices.size());
    group.transform.axis = Eigen::Vector3d::UnitX();
    pose.groups.push_back(group);
    this->RecordPoseEdit(node, repose::poseToJson(pose));
    return group.name;
  });
}

std::vector<vtkSlicerReposeLogic::JointInfo> vtkSlicerReposeLogic::GetJointsBeside(
    const std::string& partsPath) {
  std::vector<JointInfo> out;
  const std::string path = partsPath.empty() ? "" : repose::findSkeletonBeside(partsPath);
  if (path.empty()) return out;
  try {
    const repose::Skeleton skeleton = repose::readSkeleton(path);
    for (const repose::SkeletonJoint& j : skeleton.joints) {
      JointInfo info;
      info.name = j.name;
      for (const std::string& axis : repose::jointTurnAxes(j)) {  // a joint group's turns' order
        const Eigen::Vector3d v = *j.axis(axis);
        info.axes.push_back(axis);
        info.axisVectors.push_back({v.x(), v.y(), v.z()});
        info.rangesDeg.push_back(repose::jointRangeDeg(j.name, axis));
      }
      info.distalParts = repose::jointDistalParts(skeleton, j.name);
      out.push_back(info);
    }
  } catch (const repose::Error&) {
    out.clear();  // a broken skeleton offers no joint (StartBuildRig names the problem)
  }
  return out;
}

namespace {
repose::Skeleton skeletonBeside(const std::string& partsPath) {
  const std::string path = partsPath.empty() ? "" : repose::findSkeletonBeside(partsPath);
  if (path.empty())
    throw repose::Error("no skeleton.json beside the body-part map " +
                        (partsPath.empty() ? std::string("(none given)") : partsPath) +
                        ": rig from the organ map first");
  return repose::readSkeleton(path);
}
}  // namespace

std::string vtkSlicerReposeLogic::SetPoseJoint(vtkMRMLReposePoseNode* node,
                                               const std::string& partsPath,
                                               const std::string& joint) {
  return this->Guarded<std::string>("", [&]() -> std::string {
    if (!node) throw repose::Error("no pose");
    const repose::Skeleton skeleton = skeletonBeside(partsPath);
    repose::Pose pose = repose::parsePose(node->GetPoseJSON(), node->GetName());
    // Parts by label: S's names, to tell which groups select the joint's parts.
    const repose::LabelTable partLabels = vtkSlicerReposeLogicRead::ReadVolume(partsPath).labels();
    const std::string group = repose::setJointGroup(pose, skeleton, joint, partLabels);
    // The joint's group changes the rig itself (its contacts are cut in the cage and the mesh),
    // which re-preparing the live pose on the old cage would not do: posing stops until it is
    // built again (StartBuildRig).
    if (this->GetLivePose() == node) this->StopLivePose();
    this->RecordPoseEdit(node, repose::poseToJson(pose));
    return group;
  });
}

bool vtkSlicerReposeLogic::WritePoseFile(vtkMRMLReposePoseNode* node, const std::string& partsPath,
                                         const std::string& path) {
  return this->Guarded<bool>(false, [&]() -> bool {
    if (!node) throw repose::Error("no pose");
    repose::Pose pose = repose::parsePose(node->GetPoseJSON(), node->GetName());
    if (const std::string skeleton = partsPath.empty() ? "" : repose::findSkeletonBeside(partsPath);
        !skeleton.empty())
      repose::nameJointGroups(pose, repose::readSkeleton(skeleton));
    repose::writePoseFile(pose, path);
    return true;
  });
}

bool vtkSlicerReposeLogic::AddPoseSeparation(vtkMRMLReposePoseNode* node, const std::string& partA,
                                             const std::string& partB, const std::string& region) {
  return this->Guarded<bool>(false, [&]() -> bool {
    if (!node) throw repose::Error("no pose");
    repose::Pose pose = repose::parsePose(node->GetPoseJSON(), node->GetName());
    repose::PoseSeparation separation;
    const std::string names[2] = {partA, partB};
    for (int k = 0; k < 2; ++k) {
      const std::string& n = names[k];
      if (n.empty()) throw repose::Error("a separation needs two body parts");
      if (n.find_first_not_of("0123456789") == std::string::npos)
        separation.parts[std::size_t(k)] = std::stoi(n);
      else
        separation.partNames[std::size_t(k)] = n;
    }
    if (names[0] == names[1]) throw repose::Error("a part cannot be separated from itself");
    separation.region = repose::Region::parse(region);
    pose.separations.push_back(separation);
    this->RecordPoseEdit(node, repose::poseToJson(pose));
    return true;
  });
}

bool vtkSlicerReposeLogic::CanUndo() const {
  return this->History.CanUndo();
}
bool vtkSlicerReposeLogic::CanRedo() const {
  return this->History.CanRedo();
}

bool vtkSlicerReposeLogic::Undo() {
  const auto step = this->History.Undo();
  if (!step) return false;
  if (auto* node = vtkMRMLReposePoseNode::SafeDownCast(this->Scene->GetNodeByID(step->nodeID)))
    node->SetPoseJSON(step->before);
  return true;
}

bool vtkSlicerReposeLogic::Redo() {
  const auto step = this->History.Redo();
  if (!step) return false;
  if (auto* node = vtkMRMLReposePoseNode::SafeDownCast(this->Scene->GetNodeByID(step->nodeID)))
    node->SetPoseJSON(step->after);
  return true;
}
