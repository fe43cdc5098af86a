// vtkSlicerReposeLogic, the pose edits: a group's transform set from the panel's controls or from
// the 3D view's transform widget (a 4x4 motion), new handle groups from a selection of cage
// vertices or a body part, new poses, and the undo/redo stacks they all share. The rules are
// Core's (pose/PoseEdit.h, which Python edits poses by too); here each edit reads the pose node,
// applies the rule, and writes the new pose JSON on the node, so undo is restoring a string and
// the live frame follows the node's Modified.
#include "vtkMRMLReposePoseNode.h"
#include "vtkMRMLReposeScene.h"
#include "vtkSlicerReposeLogic.h"
#include "vtkSlicerReposeLogicGuarded.h"
#include "vtkSlicerReposeLogicRead.h"

#include <repose/pose/Pose.h>
#include <repose/pose/PoseEdit.h>
#include <repose/skeleton/Skeleton.h>
#include <repose/util/Error.h>

#include <vtkMatrix4x4.h>

#include <Eigen/Geometry>

#include <algorithm>

namespace {

// The frame an edit of the node applies to: its current keyframe.
std::size_t editedFrame(vtkMRMLReposePoseNode* node) {
  return std::size_t(std::max(0, node->GetCurrentFrame()));
}

repose::Pose poseOf(vtkMRMLReposePoseNode* node) {
  return repose::parsePose(node->GetPoseJSON(), node->GetName());
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
    repose::Pose pose = poseOf(node);
    repose::setGroupTransform(pose, group, editedFrame(node),
                              Eigen::Vector3d(axis[0], axis[1], axis[2]), angleDeg,
                              Eigen::Vector3d(pivot[0], pivot[1], pivot[2]),
                              Eigen::Vector3d(translation[0], translation[1], translation[2]));
    this->RecordPoseEdit(node, repose::poseToJson(pose));
    return true;
  });
}

std::optional<vtkSlicerReposeLogic::GroupTransform> vtkSlicerReposeLogic::GetPoseGroupTransform(
    vtkMRMLReposePoseNode* node, const std::string& group) const {
  if (!node) return std::nullopt;
  try {
    const repose::Pose pose = poseOf(node);
    if (repose::poseGroup(pose, group).fixed) return std::nullopt;
    const repose::PoseTransform t = repose::groupTransform(pose, group, editedFrame(node));
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

bool vtkSlicerReposeLogic::GetPoseGroupMatrix(vtkMRMLReposePoseNode* node, const std::string& group,
                                              vtkMatrix4x4* matrix) const {
  if (!matrix || !node) return false;
  try {
    const repose::Pose pose = poseOf(node);
    if (repose::poseGroup(pose, group).fixed) return false;
    const Eigen::Matrix4d m = repose::groupMotion(pose, group, editedFrame(node)).matrix();
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
    const repose::Pose pose = poseOf(node);
    if (repose::poseGroup(pose, group).fixed) return {};
    std::vector<GroupTurn> turns;
    for (const repose::GroupTurn& t : repose::groupTurns(pose, group, editedFrame(node)))
      turns.push_back(GroupTurn{t.axisName, {t.axis.x(), t.axis.y(), t.axis.z()}, t.angleDeg});
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
    repose::Pose pose = poseOf(node);
    repose::setGroupTurnAngle(pose, group, editedFrame(node), turn, angleDeg);
    this->RecordPoseEdit(node, repose::poseToJson(pose));
    return true;
  });
}

bool vtkSlicerReposeLogic::SetPoseGroupMatrix(vtkMRMLReposePoseNode* node, const std::string& group,
                                              vtkMatrix4x4* matrix) {
  // The pose is parsed once per call: a drag of the 3D box calls this on every mouse move.
  return this->Guarded<bool>(false, [&]() -> bool {
    if (!node || !matrix)
      throw repose::Error("pose group \"" + group + "\" cannot be moved (unknown or fixed)");
    repose::Pose pose = poseOf(node);
    Eigen::Isometry3d world = Eigen::Isometry3d::Identity();
    for (int r = 0; r < 3; ++r) {
      for (int c = 0; c < 3; ++c) world.matrix()(r, c) = matrix->GetElement(r, c);
      world.matrix()(r, 3) = matrix->GetElement(r, 3);
    }
    repose::setGroupMotion(pose, group, editedFrame(node), world);
    this->RecordPoseEdit(node, repose::poseToJson(pose));
    return true;
  });
}

vtkMRMLReposePoseNode* vtkSlicerReposeLogic::NewPose(const std::string& name) {
  return this->Guarded<vtkMRMLReposePoseNode*>(nullptr, [&]() -> vtkMRMLReposePoseNode* {
    const repose::Pose pose = repose::newPose(name);
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
    repose::Pose pose = poseOf(node);
    const std::vector<std::array<double, 3>> rest = this->GetLiveRestCage();
    Eigen::MatrixX3d restCage(Eigen::Index(rest.size()), 3);
    for (std::size_t v = 0; v < rest.size(); ++v)
      restCage.row(Eigen::Index(v)) = Eigen::RowVector3d(rest[v][0], rest[v][1], rest[v][2]);
    const std::string group = repose::addCageGroup(
        pose, bodyPart > 0 ? this->GetLiveCageVerticesOfPart(bodyPart) : cageVertices, bodyPart,
        restCage, [this](const std::string& name) { return this->GetLiveGroupVertices(name); });
    this->RecordPoseEdit(node, repose::poseToJson(pose));
    return group;
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
    repose::Pose pose = poseOf(node);
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
    repose::Pose pose = poseOf(node);
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
    repose::Pose pose = poseOf(node);
    repose::addPoseSeparation(pose, partA, partB, region);
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
