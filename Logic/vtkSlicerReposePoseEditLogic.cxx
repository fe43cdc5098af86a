// vtkSlicerReposePoseEditLogic: a group's transform set from the panel's controls or from the 3D
// view's transform widget (a 4x4 motion), new handle groups from a selection of cage vertices or
// a body part, joints, separations, new poses, and the undo/redo history they all share.
#include "vtkSlicerReposePoseEditLogic.h"

#include "vtkMRMLReposePoseNode.h"
#include "vtkMRMLReposeScene.h"
#include "vtkSlicerReposeLiveLogic.h"
#include "vtkSlicerReposeLogicContext.h"
#include "vtkSlicerReposeLogicInputs.h"
#include "vtkSlicerReposeLogicRead.h"

#include <repose/pose/Pose.h>
#include <repose/pose/PoseEdit.h>
#include <repose/pose/PoseHistory.h>
#include <repose/skeleton/Skeleton.h>
#include <repose/util/Error.h>

#include <vtkObjectFactory.h>

#include <Eigen/Geometry>

#include <algorithm>

namespace Inputs = vtkSlicerReposeLogicInputs;

vtkStandardNewMacro(vtkSlicerReposePoseEditLogic);

vtkSlicerReposePoseEditLogic::vtkSlicerReposePoseEditLogic()
    : History(std::make_unique<repose::PoseHistory>()) {}

vtkSlicerReposePoseEditLogic::~vtkSlicerReposePoseEditLogic() = default;

namespace {

// The frame an edit of the node applies to: its current keyframe.
std::size_t editedFrame(vtkMRMLReposePoseNode* node) {
  return std::size_t(std::max(0, node->GetCurrentFrame()));
}

// The node's pose, or none (a query's answer is then empty, not an error).
std::shared_ptr<const repose::Pose> queried(vtkMRMLReposePoseNode* node) {
  return node ? node->GetPose() : nullptr;
}

}  // namespace

const std::string& vtkSlicerReposePoseEditLogic::GetLastErrorMessage() const {
  return this->Context->LastErrorMessage;
}

void vtkSlicerReposePoseEditLogic::ClearHistory() {
  this->History->clear();
}

namespace {
// Every edit: a copy of the node's pose changed by `rule`, then set on the node as a new snapshot
// and recorded (nothing when the rule changed nothing). Returns what the rule returns.
template <class Rule>
auto editPose(repose::PoseHistory& history, vtkMRMLReposePoseNode* node, Rule&& rule) {
  if (!node) throw repose::Error("no pose");
  repose::Pose pose = Inputs::PoseOf(node);
  auto result = rule(pose);
  auto after = std::make_shared<const repose::Pose>(std::move(pose));
  if (history.record(node->GetID(), node->GetPose(), after)) node->SetPose(after);
  return result;
}
}  // namespace

vtkSlicerReposePoseEditLogic::PoseSummary vtkSlicerReposePoseEditLogic::GetPoseSummary(
    vtkMRMLReposePoseNode* node) const {
  PoseSummary s;
  const std::shared_ptr<const repose::Pose> p = queried(node);
  if (!p) {
    if (node) s.error = "pose " + node->GetName() + " holds no pose";
    return s;
  }
  for (const repose::PoseGroup& g : p->groups)
    if (!g.fixed) s.movableGroups.push_back(g.name);
  s.keyframes = int(p->keyframes.size());
  for (const repose::PoseSeparation& sep : p->separations) {
    auto part = [&](int k) {
      return sep.partNames[std::size_t(k)].empty() ? std::to_string(sep.parts[std::size_t(k)])
                                                   : sep.partNames[std::size_t(k)];
    };
    s.separations.push_back(part(0) + " | " + part(1));
  }
  s.valid = true;
  return s;
}

bool vtkSlicerReposePoseEditLogic::SetPoseGroupTransform(
    vtkMRMLReposePoseNode* node, const std::string& group, const std::array<double, 3>& axis,
    double angleDeg, const std::array<double, 3>& pivot, const std::array<double, 3>& translation) {
  return this->Context->Guarded<bool>(false, [&] {
    return editPose(*this->History, node, [&](repose::Pose& pose) {
      repose::setGroupTransform(pose, group, editedFrame(node),
                                Eigen::Vector3d(axis[0], axis[1], axis[2]), angleDeg,
                                Eigen::Vector3d(pivot[0], pivot[1], pivot[2]),
                                Eigen::Vector3d(translation[0], translation[1], translation[2]));
      return true;
    });
  });
}

std::optional<vtkSlicerReposePoseEditLogic::GroupTransform>
vtkSlicerReposePoseEditLogic::GetPoseGroupTransform(vtkMRMLReposePoseNode* node,
                                                    const std::string& group) const {
  const std::shared_ptr<const repose::Pose> pose = queried(node);
  if (!pose) return std::nullopt;
  try {
    if (repose::poseGroup(*pose, group).fixed) return std::nullopt;
    const repose::PoseTransform t = repose::groupTransform(*pose, group, editedFrame(node));
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

bool vtkSlicerReposePoseEditLogic::GetPoseGroupMatrix(vtkMRMLReposePoseNode* node,
                                                      const std::string& group,
                                                      vtkMatrix4x4* matrix) const {
  const std::shared_ptr<const repose::Pose> pose = queried(node);
  if (!matrix || !pose) return false;
  try {
    if (repose::poseGroup(*pose, group).fixed) return false;
    const Eigen::Matrix4d m = repose::groupMotion(*pose, group, editedFrame(node)).matrix();
    for (int r = 0; r < 4; ++r)
      for (int c = 0; c < 4; ++c) matrix->SetElement(r, c, m(r, c));
    return true;
  } catch (const std::exception&) {
    return false;  // a query, as GetPoseGroupTransform
  }
}

std::vector<vtkSlicerReposePoseEditLogic::GroupTurn>
vtkSlicerReposePoseEditLogic::GetPoseGroupTurns(vtkMRMLReposePoseNode* node,
                                                const std::string& group) const {
  const std::shared_ptr<const repose::Pose> pose = queried(node);
  if (!pose) return {};
  try {
    if (repose::poseGroup(*pose, group).fixed) return {};
    std::vector<GroupTurn> turns;
    for (const repose::GroupTurn& t : repose::groupTurns(*pose, group, editedFrame(node)))
      turns.push_back(GroupTurn{t.axisName, {t.axis.x(), t.axis.y(), t.axis.z()}, t.angleDeg});
    return turns;
  } catch (const std::exception&) {
    return {};
  }
}

bool vtkSlicerReposePoseEditLogic::SetPoseGroupTurnAngle(vtkMRMLReposePoseNode* node,
                                                         const std::string& group, int turn,
                                                         double angleDeg) {
  return this->Context->Guarded<bool>(false, [&] {
    return editPose(*this->History, node, [&](repose::Pose& pose) {
      repose::setGroupTurnAngle(pose, group, editedFrame(node), turn, angleDeg);
      return true;
    });
  });
}

bool vtkSlicerReposePoseEditLogic::SetPoseGroupMatrix(vtkMRMLReposePoseNode* node,
                                                      const std::string& group,
                                                      vtkMatrix4x4* matrix) {
  return this->Context->Guarded<bool>(false, [&] {
    if (!matrix) throw repose::Error("pose group \"" + group + "\" cannot be moved (no matrix)");
    return editPose(*this->History, node, [&](repose::Pose& pose) {
      Eigen::Isometry3d world = Eigen::Isometry3d::Identity();
      for (int r = 0; r < 3; ++r) {
        for (int c = 0; c < 3; ++c) world.matrix()(r, c) = matrix->GetElement(r, c);
        world.matrix()(r, 3) = matrix->GetElement(r, 3);
      }
      repose::setGroupMotion(pose, group, editedFrame(node), world);
      return true;
    });
  });
}

vtkMRMLReposePoseNode* vtkSlicerReposePoseEditLogic::NewPose(const std::string& name) {
  return this->Context->Guarded<vtkMRMLReposePoseNode*>(nullptr, [&] {
    repose::Pose pose = repose::newPose(name);
    const std::string poseName = pose.name;
    return Inputs::AddPoseNode(this->Context->Scene, poseName, std::move(pose));
  });
}

std::string vtkSlicerReposePoseEditLogic::AddPoseGroup(vtkMRMLReposePoseNode* node,
                                                       const std::vector<int>& cageVertices,
                                                       int bodyPart) {
  return this->Context->Guarded<std::string>("", [&]() -> std::string {
    vtkSlicerReposeLiveLogic* live = this->Context->Live;
    if (!node) throw repose::Error("no pose");
    if (node != live->GetLivePose())
      throw repose::Error("pose " + node->GetName() +
                          " is not being posed live (build the cage and mesh first)");
    const std::vector<std::array<double, 3>> rest = live->GetLiveRestCage();
    Eigen::MatrixX3d restCage(Eigen::Index(rest.size()), 3);
    for (std::size_t v = 0; v < rest.size(); ++v)
      restCage.row(Eigen::Index(v)) = Eigen::RowVector3d(rest[v][0], rest[v][1], rest[v][2]);
    return editPose(*this->History, node, [&](repose::Pose& pose) {
      return repose::addCageGroup(
          pose, bodyPart > 0 ? live->GetLiveCageVerticesOfPart(bodyPart) : cageVertices, bodyPart,
          restCage, [live](const std::string& name) { return live->GetLiveGroupVertices(name); });
    });
  });
}

std::vector<vtkSlicerReposePoseEditLogic::JointInfo> vtkSlicerReposePoseEditLogic::GetJointsBeside(
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

std::string vtkSlicerReposePoseEditLogic::SetPoseJoint(vtkMRMLReposePoseNode* node,
                                                       const std::string& partsPath,
                                                       const std::string& joint) {
  return this->Context->Guarded<std::string>("", [&]() -> std::string {
    if (!node) throw repose::Error("no pose");
    const repose::Skeleton skeleton = skeletonBeside(partsPath);
    // Parts by label: S's names, to tell which groups select the joint's parts.
    const repose::LabelTable partLabels = vtkSlicerReposeLogicRead::ReadVolume(partsPath).labels();
    repose::Pose pose = Inputs::PoseOf(node);
    const std::string group = repose::setJointGroup(pose, skeleton, joint, partLabels);
    // The joint's group changes the rig itself (its contacts are cut in the cage and the mesh),
    // which re-preparing the live pose on the old cage would not do: posing stops until it is
    // built again (StartBuildRig).
    if (this->Context->Live->GetLivePose() == node) this->Context->Live->StopLivePose();
    auto after = std::make_shared<const repose::Pose>(std::move(pose));
    if (this->History->record(node->GetID(), node->GetPose(), after)) node->SetPose(after);
    return group;
  });
}

bool vtkSlicerReposePoseEditLogic::WritePoseFile(vtkMRMLReposePoseNode* node,
                                                 const std::string& partsPath,
                                                 const std::string& path) {
  return this->Context->Guarded<bool>(false, [&] {
    if (!node) throw repose::Error("no pose");
    repose::Pose pose = Inputs::PoseOf(node);
    if (const std::string skeleton = partsPath.empty() ? "" : repose::findSkeletonBeside(partsPath);
        !skeleton.empty())
      repose::nameJointGroups(pose, repose::readSkeleton(skeleton));
    repose::writePoseFile(pose, path);
    return true;
  });
}

bool vtkSlicerReposePoseEditLogic::AddPoseSeparation(vtkMRMLReposePoseNode* node,
                                                     const std::string& partA,
                                                     const std::string& partB,
                                                     const std::string& region) {
  return this->Context->Guarded<bool>(false, [&] {
    return editPose(*this->History, node, [&](repose::Pose& pose) {
      repose::addPoseSeparation(pose, partA, partB, region);
      return true;
    });
  });
}

void vtkSlicerReposePoseEditLogic::BeginPoseInteraction() {
  this->History->beginInteraction();
}

void vtkSlicerReposePoseEditLogic::EndPoseInteraction() {
  this->History->endInteraction();
  this->Modified();  // the panel shows what it leaves out during a drag (the prediction)
}

bool vtkSlicerReposePoseEditLogic::IsPoseInteractionActive() const {
  return this->History->interacting();
}

bool vtkSlicerReposePoseEditLogic::CanUndo() const {
  return this->History->canUndo();
}

bool vtkSlicerReposePoseEditLogic::CanRedo() const {
  return this->History->canRedo();
}

bool vtkSlicerReposePoseEditLogic::Undo() {
  const auto step = this->History->undo();
  if (!step) return false;
  if (auto* node =
          vtkMRMLReposePoseNode::SafeDownCast(this->Context->Scene->GetNodeByID(step->target)))
    node->SetPose(step->before);
  return true;
}

bool vtkSlicerReposePoseEditLogic::Redo() {
  const auto step = this->History->redo();
  if (!step) return false;
  if (auto* node =
          vtkMRMLReposePoseNode::SafeDownCast(this->Context->Scene->GetNodeByID(step->target)))
    node->SetPose(step->after);
  return true;
}
