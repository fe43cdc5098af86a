// What a pose node needs from the scene before a job can use it: its segmentation, cage and
// transfer mesh, and the body-part labels S carries. Shared by the pipeline and the live half of
// vtkSlicerReposeLogic, so both refuse an unrigged pose with the same message.
#ifndef vtkSlicerReposeLogicInputs_h
#define vtkSlicerReposeLogicInputs_h

#include <repose/cage/CageLadder.h>
#include <repose/skeleton/Skeleton.h>
#include <repose/volume/LabelTable.h>

#include <memory>
#include <optional>

namespace repose {
class PoseJob;
struct Pose;
class Volume;
}  // namespace repose
class vtkMRMLReposeParametersNode;
class vtkMRMLReposeCageNode;
class vtkMRMLReposePoseNode;
class vtkMRMLReposeScene;
class vtkMRMLReposeSegmentationNode;
class vtkMRMLReposeTransferMeshNode;

namespace vtkSlicerReposeLogicInputs {

struct PoseNodes {
  vtkMRMLReposeSegmentationNode* Segmentation = nullptr;
  vtkMRMLReposeCageNode* Cage = nullptr;
  vtkMRMLReposeTransferMeshNode* TransferMesh = nullptr;
};

// The nodes the pose references; throws repose::Error naming the pose when one is missing.
PoseNodes Resolve(vtkMRMLReposeScene* scene, vtkMRMLReposePoseNode* pose);

// The segmentation's skeleton (its SkeletonJSON), or none.
std::optional<repose::Skeleton> SkeletonOf(vtkMRMLReposeSegmentationNode* seg);

// The setting the cage node's cage was built with (asked, used, tried); a cage from a file, or a
// scene saved before the ladder, has its node's target vertex count and dilation as both.
repose::CageChoice CageChoiceOf(vtkMRMLReposeCageNode* cage);

// S of a segmentation, or the body mask of G (label 1 where G is not 0) when it has none.
repose::Volume PartsOf(vtkMRMLReposeSegmentationNode* seg);

// S's label table, or the one-label table of the body mask when the segmentation has no S.
repose::LabelTable BodyPartLabels(vtkMRMLReposeSegmentationNode* seg);

// The pose job of a segmentation (Core's policy, as `repose pose` and Python use it): its tissue
// table, skeleton and joints, separations, the rig's settings from the parameter node (null:
// the defaults). G and S must outlive it.
std::shared_ptr<const repose::PoseJob> PoseJobFor(vtkMRMLReposeParametersNode* parameters,
                                                  vtkMRMLReposeSegmentationNode* seg,
                                                  const repose::Pose& pose, const repose::Volume& G,
                                                  const repose::Volume& S);

// A new pose node named `name` holding `pose`, added to the scene.
vtkMRMLReposePoseNode* AddPoseNode(vtkMRMLReposeScene* scene, const std::string& name,
                                   repose::Pose pose);

// The pose a pose node holds; throws repose::Error naming the node when it holds none.
const repose::Pose& PoseOf(vtkMRMLReposePoseNode* node);

}  // namespace vtkSlicerReposeLogicInputs

#endif
