// What a pose node needs from the scene before a job can use it, and the pose job of a
// segmentation (vtkSlicerReposeLogicInputs.h): shared by the module's logic and its parts.
#include "vtkSlicerReposeLogicInputs.h"

#include "vtkMRMLReposeCageNode.h"
#include "vtkMRMLReposeParametersNode.h"
#include "vtkMRMLReposePoseNode.h"
#include "vtkMRMLReposeScene.h"
#include "vtkMRMLReposeSegmentationNode.h"
#include "vtkMRMLReposeTransferMeshNode.h"
#include "vtkSlicerReposeVolumeConversion.h"

#include <repose/pose/PoseJob.h>
#include <repose/util/Error.h>

using Conversion = vtkSlicerReposeVolumeConversion;

namespace vtkSlicerReposeLogicInputs {

repose::Volume PartsOf(vtkMRMLReposeSegmentationNode* seg) {
  if (seg->GetBodyPartMap()) return Conversion::FromImageData(seg->GetBodyPartMap());
  const repose::Volume G = Conversion::FromImageData(seg->GetLabelMap());
  repose::Volume mask(G.geometry(), repose::ScalarType::UInt8);
  repose::dispatchScalar(G.scalarType(), [&](auto* tag) {
    using T = std::remove_pointer_t<decltype(tag)>;
    for (std::int64_t v = 0; v < G.numVoxels(); ++v)
      mask.data<std::uint8_t>()[v] = G.data<T>()[v] != 0;
  });
  mask.labels() = BodyPartLabels(seg);
  mask.setLabelMap(true);
  return mask;
}

PoseNodes Resolve(vtkMRMLReposeScene* scene, vtkMRMLReposePoseNode* pose) {
  if (!pose) throw repose::Error("no pose");
  PoseNodes nodes;
  nodes.Segmentation =
      vtkMRMLReposeSegmentationNode::SafeDownCast(scene->GetReferencedNode(pose, "segmentation"));
  nodes.Cage = vtkMRMLReposeCageNode::SafeDownCast(scene->GetReferencedNode(pose, "cage"));
  nodes.TransferMesh =
      vtkMRMLReposeTransferMeshNode::SafeDownCast(scene->GetReferencedNode(pose, "transfer_mesh"));
  if (!nodes.Segmentation || !nodes.Segmentation->GetLabelMap() || !nodes.Cage ||
      !nodes.TransferMesh)
    throw repose::Error("pose " + pose->GetName() +
                        " has no segmentation, cage and transfer mesh yet (build the rig)");
  return nodes;
}

std::optional<repose::Skeleton> SkeletonOf(vtkMRMLReposeSegmentationNode* seg) {
  if (!seg || seg->GetSkeletonJSON().empty()) return std::nullopt;
  return repose::parseSkeleton(seg->GetSkeletonJSON(), seg->GetName() + " skeleton");
}

repose::CageChoice CageChoiceOf(vtkMRMLReposeCageNode* cage) {
  if (!cage->GetCageChoice().empty()) {
    try {
      return repose::CageChoice::fromJson(cage->GetCageChoice());
    } catch (const repose::Error&) {
      // edited by hand: the node's own setting below
    }
  }
  return repose::CageChoice::given({cage->GetTargetVertexCount(), cage->GetDilationMm()});
}

repose::LabelTable BodyPartLabels(vtkMRMLReposeSegmentationNode* seg) {
  if (seg->GetBodyPartMap()) return Conversion::GetLabelTable(seg->GetBodyPartMap());
  repose::LabelTable table;
  repose::Label body;
  body.value = 1;
  body.name = "body";
  table.set(body);
  return table;
}

std::shared_ptr<const repose::PoseJob> PoseJobFor(vtkMRMLReposeParametersNode* parameters,
                                                  vtkMRMLReposeSegmentationNode* seg,
                                                  const repose::Pose& pose, const repose::Volume& G,
                                                  const repose::Volume& S) {
  repose::PoseJobRequest request;
  request.organsName =
      seg->GetLabelMapFileName().empty() ? seg->GetName() : seg->GetLabelMapFileName();
  request.partsPath = parameters ? parameters->GetBodyPartMapPath() : std::string();
  request.tissuesPath = parameters ? parameters->GetTissueTablePath() : std::string();
  request.skeleton = SkeletonOf(seg);
  // What G's reader decided (a DICOM SEG's grid...), kept in the export's report.json as the
  // command line keeps it: the segmentation's own, from the file it was read from.
  request.organsNotes = seg->GetLabelMapReadNotes();
  if (parameters) {
    request.settings.cageVertices = parameters->GetCageVertexCount();
    request.settings.dilateMm = parameters->GetCageDilationMm();
    request.settings.meshMm = parameters->GetTransferMeshSizeMm();
  }
  return std::make_shared<const repose::PoseJob>(pose, G, S, std::move(request));
}

vtkMRMLReposePoseNode* AddPoseNode(vtkMRMLReposeScene* scene, const std::string& name,
                                   repose::Pose pose) {
  auto node = vtkSmartPointer<vtkMRMLReposePoseNode>::New();
  node->SetName(name);
  node->SetPose(std::make_shared<const repose::Pose>(std::move(pose)));
  scene->AddNode(node);
  return node;
}

const repose::Pose& PoseOf(vtkMRMLReposePoseNode* node) {
  if (!node) throw repose::Error("no pose");
  if (!node->GetPose()) throw repose::Error("pose " + node->GetName() + " holds no pose");
  return *node->GetPose();
}

}  // namespace vtkSlicerReposeLogicInputs
