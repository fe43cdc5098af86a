// vtkSlicerReposePoseEditLogic: editing poses, a part of the module's logic (vtkSlicerReposeLogic::
// GetPoseEdits). The rules are Core's (pose/PoseEdit.h, which Python edits poses by too); each
// edit takes the node's parsed pose, applies the rule to a copy and sets the copy on the node as
// a new snapshot, recorded on one undo history (Core's repose::PoseHistory): undo puts the old
// snapshot back. No edit writes or parses pose text; a live pose follows the node's Modified.
#pragma once

#include "vtkSlicerReposeModuleLogicExport.h"

#include <vtkMatrix4x4.h>
#include <vtkObject.h>

#include <array>
#include <memory>
#include <optional>
#include <string>
#include <utility>
#include <vector>

namespace repose {
class PoseHistory;
}
class vtkMRMLReposePoseNode;
struct vtkSlicerReposeLogicContext;

class VTK_SLICER_REPOSE_MODULE_LOGIC_EXPORT vtkSlicerReposePoseEditLogic : public vtkObject {
 public:
  static vtkSlicerReposePoseEditLogic* New();
  vtkTypeMacro(vtkSlicerReposePoseEditLogic, vtkObject);

  // What a panel shows of a pose node: the groups a user can turn (not fixed, in the file's
  // order), the number of keyframes, the separations as "part A | part B" (names, else label
  // values). `valid` is false, with `error`, for a node that holds no pose.
  struct PoseSummary {
    bool valid = false;
    std::string error;
    std::vector<std::string> movableGroups;
    int keyframes = 0;
    std::vector<std::string> separations;
  };
  PoseSummary GetPoseSummary(vtkMRMLReposePoseNode* pose) const;

  // The group's transform (rotation about `axis` through `pivot` by `angleDeg`, then
  // `translation`) in the pose's current keyframe, or in the pose itself when it has none; a
  // group's further turns (a joint group's other axes) are kept. Undoable. False with a message
  // for an unknown group or a fixed one.
  bool SetPoseGroupTransform(vtkMRMLReposePoseNode* pose, const std::string& group,
                             const std::array<double, 3>& axis, double angleDeg,
                             const std::array<double, 3>& pivot,
                             const std::array<double, 3>& translation);
  struct GroupTransform {
    std::array<double, 3> axis{0, 0, 1};
    double angleDeg = 0;
    std::array<double, 3> pivot{0, 0, 0}, translation{0, 0, 0};
  };
  // The group's transform in the current keyframe. Empty for an unknown or fixed group.
  std::optional<GroupTransform> GetPoseGroupTransform(vtkMRMLReposePoseNode* pose,
                                                      const std::string& group) const;
  // The group's motion as a 4x4 matrix (rest RAS mm -> posed RAS mm, carried along its chain),
  // and setting it from one (the 3D view's transform widget; repose::setGroupMotion's rule).
  // False with a message when the matrix is not a rigid motion, or for a group turning about
  // several axes (a joint's: its sliders move it).
  bool GetPoseGroupMatrix(vtkMRMLReposePoseNode* pose, const std::string& group,
                          vtkMatrix4x4* matrix) const;
  bool SetPoseGroupMatrix(vtkMRMLReposePoseNode* pose, const std::string& group,
                          vtkMatrix4x4* matrix);
  // A group's turns in the current keyframe (repose::groupTurns: its rotation, then each further
  // turn, with the joint axis's name where the pose names it), and setting one's angle
  // (undoable). Empty / false with a message for an unknown group or turn.
  struct GroupTurn {
    std::string axisName;
    std::array<double, 3> axis{1, 0, 0};
    double angleDeg = 0;
  };
  std::vector<GroupTurn> GetPoseGroupTurns(vtkMRMLReposePoseNode* pose,
                                           const std::string& group) const;
  bool SetPoseGroupTurnAngle(vtkMRMLReposePoseNode* pose, const std::string& group, int turn,
                             double angleDeg);
  // A new pose node with the one fixed group "rest" (every cage vertex).
  vtkMRMLReposePoseNode* NewPose(const std::string& name);
  // A new handle group of the live pose, undoable: the given cage vertices, or with bodyPart > 0
  // that part of S (repose::addCageGroup's rule). Returns the new group's name, or "" with a
  // message. The live pose re-prepares itself for the new groups (a job).
  std::string AddPoseGroup(vtkMRMLReposePoseNode* pose, const std::vector<int>& cageVertices,
                           int bodyPart = 0);
  // Posing by joint: the joints of the skeleton beside a body-part map (skeleton.json), each
  // with its axes in its group's turns' order, their ranges (repose::jointRangeDeg) and the
  // parts distal to it. Empty when there is none.
  struct JointInfo {
    std::string name;
    std::vector<std::string> axes;
    std::vector<std::array<double, 3>> axisVectors;    // per axis, unit, RAS
    std::vector<std::pair<double, double>> rangesDeg;  // per axis
    std::vector<std::string> distalParts;
  };
  static std::vector<JointInfo> GetJointsBeside(const std::string& partsPath);
  // The pose's group that turns `joint` about each of its axes (repose::setJointGroup), undoable.
  // Live posing of this pose stops: the rig must be built again for it. Returns the group's
  // name, or "" with a message.
  std::string SetPoseJoint(vtkMRMLReposePoseNode* pose, const std::string& partsPath,
                           const std::string& joint);
  // The pose as a pose file, its joint groups in the named form so it poses any rigged body;
  // written atomically. False with a message.
  bool WritePoseFile(vtkMRMLReposePoseNode* pose, const std::string& partsPath,
                     const std::string& path);
  // A limb separation added to the pose, undoable (repose::addPoseSeparation). False with a
  // message.
  bool AddPoseSeparation(vtkMRMLReposePoseNode* pose, const std::string& partA,
                         const std::string& partB, const std::string& region);
  // A drag: the edits between Begin and End are one undo step (each still re-solves live).
  void BeginPoseInteraction();
  void EndPoseInteraction();
  bool IsPoseInteractionActive() const;
  bool Undo();
  bool Redo();
  bool CanUndo() const;
  bool CanRedo() const;
  const std::string& GetLastErrorMessage() const;

 protected:
  vtkSlicerReposePoseEditLogic();
  ~vtkSlicerReposePoseEditLogic() override;
  friend class vtkSlicerReposeLogic;
  void SetContext(std::shared_ptr<vtkSlicerReposeLogicContext> context) {
    this->Context = std::move(context);
  }
  void ClearHistory();

 private:
  vtkSlicerReposePoseEditLogic(const vtkSlicerReposePoseEditLogic&) = delete;
  void operator=(const vtkSlicerReposePoseEditLogic&) = delete;

  std::shared_ptr<vtkSlicerReposeLogicContext> Context;
  std::unique_ptr<repose::PoseHistory> History;
};
