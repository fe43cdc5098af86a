// vtkSlicerReposeLogic, the scene half: segmentation and pose nodes from files, and scene folders
// (saved with the parameter node, opened so the panel is as it was saved).
#include "vtkSlicerReposeLogic.h"

#include "vtkMRMLReposeCageNode.h"
#include "vtkMRMLReposeParametersNode.h"
#include "vtkMRMLReposePoseNode.h"
#include "vtkMRMLReposeScene.h"
#include "vtkMRMLReposeSegmentationNode.h"
#include "vtkMRMLReposeTransferMeshNode.h"
#include "vtkSlicerReposeLogicContext.h"
#include "vtkSlicerReposeLogicInputs.h"
#include "vtkSlicerReposeLogicRead.h"
#include "vtkSlicerReposeSceneIO.h"
#include "vtkSlicerReposeVolumeConversion.h"

#include <repose/pose/Pose.h>
#include <repose/pose/PoseRun.h>
#include <repose/rig/Rig.h>
#include <repose/schema/SceneSchema.h>
#include <repose/skeleton/Skeleton.h>
#include <repose/util/Error.h>

#include <nlohmann/json.hpp>
#include <vtkMatrix4x4.h>

#include <algorithm>
#include <array>
#include <filesystem>

namespace fs = std::filesystem;
using Conversion = vtkSlicerReposeVolumeConversion;

void vtkSlicerReposeLogic::SetScene(vtkMRMLReposeScene* scene) {
  if (!scene || scene == this->Context->Scene) return;
  this->Live->StopLivePose();  // its nodes were the old scene's
  this->Context->Scene = scene;
  this->PoseEdits->ClearHistory();
  this->Modified();
}
vtkMRMLReposeScene* vtkSlicerReposeLogic::GetScene() const {
  return this->Context->Scene;
}

vtkMRMLReposeSegmentationNode* vtkSlicerReposeLogic::AddSegmentation(const std::string& labels,
                                                                     const std::string& parts,
                                                                     const std::string& image) {
  return this->Context->Guarded<vtkMRMLReposeSegmentationNode*>(
      nullptr, [&]() -> vtkMRMLReposeSegmentationNode* {
        // Stamped before reading: a file changed during the read is read again next time.
        const std::string stamp = vtkSlicerReposeLogicRead::FilesStamp({labels, parts, image});
        std::vector<std::string> readNotes;
        vtkSmartPointer<vtkImageData> labelMap;
        std::array<int, 3> dims{0, 0, 0};
        Eigen::Matrix4d ijkToRas = Eigen::Matrix4d::Identity();
        if (!labels.empty() && labels == this->VolumePath && this->VolumeImageData &&
            !this->VolumeStamp.empty() &&
            this->VolumeStamp ==
                vtkSlicerReposeLogicRead::FilesStamp({labels, this->Context->TissueTablePath()})) {
          // The file the input box shows, unchanged since, its labels named from the same table:
          // that image is G as the read below would make it, so the node shares it (as the box
          // shares an opened scene's) instead of reading and holding G a second time.
          labelMap = this->VolumeImageData;
          readNotes = this->VolumeReadNotes;
          labelMap->GetDimensions(dims.data());
          for (int r = 0; r < 4; ++r)
            for (int c = 0; c < 4; ++c)
              ijkToRas(r, c) = this->VolumeIJKToRASMatrix->GetElement(r, c);
        } else {
          repose::Volume G = vtkSlicerReposeLogicRead::ReadVolume(labels, &readNotes);
          repose::requirePoseableLabels(G, labels);  // the rule of every front end
          // Names and colours the file left out, so the views and the probe tell labels apart.
          vtkSlicerReposeLogicRead::NameLabels(G, this->Context->TissueTablePath(), labels);
          labelMap = Conversion::ToImageData(G);
          for (int a = 0; a < 3; ++a) dims[std::size_t(a)] = int(G.dims()[std::size_t(a)]);
          ijkToRas = G.geometry().ijkToRas;
        }
        auto node = vtkSmartPointer<vtkMRMLReposeSegmentationNode>::New();
        node->SetName(vtkSlicerReposeLogicRead::FileStem(labels));
        node->SetLabelMap(labelMap);
        node->SetLabelMapReadNotes(readNotes);
        node->SetSourceStamp(stamp);
        for (const auto& [path, setter] :
             {std::pair{parts, &vtkMRMLReposeSegmentationNode::SetBodyPartMap},
              std::pair{image, &vtkMRMLReposeSegmentationNode::SetImage}}) {
          if (path.empty()) continue;
          repose::Volume v = vtkSlicerReposeLogicRead::ReadVolume(path);
          if (v.dims()[0] != dims[0] || v.dims()[1] != dims[1] || v.dims()[2] != dims[2] ||
              !v.geometry().ijkToRas.isApprox(ijkToRas, 1e-6))
            throw repose::Error(path + ": not on the grid of " + labels);
          // An S without part names (a NIfTI `repose rig` wrote, then converted) gets the rig's
          // names, so the panel's part list is not empty.
          if (setter == &vtkMRMLReposeSegmentationNode::SetBodyPartMap)
            repose::nameBodyPartsByRigConvention(v, path);
          (node->*setter)(Conversion::ToImageData(v));
        }
        // The joints pose files name: the skeleton beside S, as `repose pose` finds it.
        if (const std::string skeleton = repose::findSkeletonBeside(parts); !skeleton.empty())
          node->SetSkeletonJSON(vtkSlicerReposeLogicRead::ReadText(skeleton));
        this->Context->Scene->AddNode(node);
        return node;
      });
}

bool vtkSlicerReposeLogic::IsSegmentationOf(vtkMRMLReposeSegmentationNode* seg,
                                            const std::string& labels, const std::string& parts,
                                            const std::string& image) const {
  if (!seg || seg->GetSourceStamp().empty()) return false;
  return seg->GetSourceStamp() == vtkSlicerReposeLogicRead::FilesStamp({labels, parts, image});
}

vtkMRMLReposePoseNode* vtkSlicerReposeLogic::AddPose(const std::string& path) {
  return this->Context->Guarded<vtkMRMLReposePoseNode*>(nullptr, [&]() -> vtkMRMLReposePoseNode* {
    repose::Pose pose = repose::readPoseFile(path);
    // Named joints become numbers with the skeleton of the newest segmentation that has one;
    // without one they stay named until the rig is built for a segmentation (StartBuildRig).
    if (repose::poseNamesJoints(pose)) {
      const auto segs = this->Context->Scene->GetNodesByClass("vtkMRMLReposeSegmentationNode");
      for (auto it = segs.rbegin(); it != segs.rend(); ++it)
        if (auto* seg = vtkMRMLReposeSegmentationNode::SafeDownCast(*it);
            seg && !seg->GetSkeletonJSON().empty()) {
          repose::resolvePoseJoints(
              pose, repose::parseSkeleton(seg->GetSkeletonJSON(), seg->GetName() + " skeleton"));
          break;
        }
    }
    const std::string name =
        pose.name.empty() ? vtkSlicerReposeLogicRead::FileStem(path) : pose.name;
    return vtkSlicerReposeLogicInputs::AddPoseNode(this->Context->Scene, name, std::move(pose));
  });
}

bool vtkSlicerReposeLogic::SaveScene(const std::string& folder) {
  return this->Context->Guarded<bool>(false, [&] {
    vtkSlicerReposeSceneIO::Save(this->Context->Scene, folder,
                                 this->Context->ParameterNode->WriteJSON());
    return true;
  });
}

bool vtkSlicerReposeLogic::LoadScene(const std::string& folder) {
  return this->LoadSceneFolder(folder, nullptr);
}

bool vtkSlicerReposeLogic::LoadSceneFolder(const std::string& folder, std::string* parameters) {
  return this->Context->Guarded<bool>(false, [&] {
    const vtkSlicerReposeSceneIO::Loaded loaded = vtkSlicerReposeSceneIO::Load(folder);
    this->Live->StopLivePose();  // its nodes are gone
    this->Context->Scene->Clear();
    for (int n = 0; n < loaded.scene->GetNumberOfNodes(); ++n)
      this->Context->Scene->AddNode(loaded.scene->GetNthNode(n));
    this->PoseEdits->ClearHistory();
    // The last export's node was the old scene's.
    this->Context->ParameterNode->SetOutputSegmentationNodeID("");
    if (parameters) *parameters = loaded.parameters;
    this->Modified();
    return true;
  });
}

bool vtkSlicerReposeLogic::OpenScene(const std::string& folder) {
  std::string saved;
  if (!this->LoadSceneFolder(folder, &saved)) return false;
  const auto segs = this->Context->Scene->GetNodesByClass("vtkMRMLReposeSegmentationNode");
  const auto poses = this->Context->Scene->GetNodesByClass("vtkMRMLReposePoseNode");
  auto* seg = segs.empty() ? nullptr : vtkMRMLReposeSegmentationNode::SafeDownCast(segs.front());
  auto* pose = poses.empty() ? nullptr : vtkMRMLReposePoseNode::SafeDownCast(poses.front());
  // The nodes name their files relative to the folder (or absolute, as the command line writes).
  auto inFolder = [&](const std::string& name) {
    return name.empty() || fs::path(name).is_absolute() ? name : (fs::path(folder) / name).string();
  };
  vtkMRMLReposeParametersNode* p = this->Context->ParameterNode;
  const int state = p->StartModify();
  // The panel as it was saved (settings, results, the active group), except the input: the box
  // shows G as the scene holds it (below), not the file it was first read from.
  if (!saved.empty()) {
    nlohmann::json fields = nlohmann::json::parse(saved, nullptr, false);
    std::string error;
    if (fields.is_object()) fields.erase("InputSegmentationPath");
    if (!fields.is_object() || !p->ReadJSON(fields.dump(), &error)) {
      p->EndModify(state);
      this->Context->LastErrorMessage = folder + "/scene.json: parameters: " + error;
      return false;
    }
  }
  // What the saved parameters name must be in the folder; else the folder's first nodes.
  auto inScene = [&](const std::string& id, const char* className) {
    vtkMRMLReposeNode* node = this->Context->Scene->GetNodeByID(id);
    return node && node->GetNodeClassName() == std::string(className);
  };
  if (!inScene(p->GetOutputSegmentationNodeID(), "vtkMRMLReposeSegmentationNode"))
    p->SetOutputSegmentationNodeID("");
  if (inScene(p->GetActivePoseNodeID(), "vtkMRMLReposePoseNode"))
    pose = vtkMRMLReposePoseNode::SafeDownCast(
        this->Context->Scene->GetNodeByID(p->GetActivePoseNodeID()));
  if (inScene(p->GetInputSegmentationNodeID(), "vtkMRMLReposeSegmentationNode"))
    seg = vtkMRMLReposeSegmentationNode::SafeDownCast(
        this->Context->Scene->GetNodeByID(p->GetInputSegmentationNodeID()));
  if (seg) {
    p->SetInputSegmentationNodeID(seg->GetID());
    p->SetBodyPartMapPath(inFolder(seg->GetBodyPartMapFileName()));
    p->SetImagePath(inFolder(seg->GetImageFileName()));
  }
  if (pose) {
    p->SetActivePoseNodeID(pose->GetID());
    p->SetPosePath(inFolder(pose->GetFileName()));
    const std::vector<std::string> groups = this->PoseEdits->GetPoseSummary(pose).movableGroups;
    if (std::find(groups.begin(), groups.end(), p->GetActiveGroup()) == groups.end())
      p->SetActiveGroup(groups.empty() ? std::string() : groups.front());
    // A scene saved without the panel (the command line's) gives the rig's settings its nodes
    // were built with; a saved panel has its own.
    if (auto* cage = !saved.empty() ? nullptr
                                    : vtkMRMLReposeCageNode::SafeDownCast(
                                          this->Context->Scene->GetReferencedNode(
                                              pose, repose::scene_schema::kCageRole))) {
      p->SetCageVertexCount(cage->GetTargetVertexCount());
      p->SetCageDilationMm(cage->GetDilationMm());
    }
    if (auto* mesh = !saved.empty() ? nullptr
                                    : vtkMRMLReposeTransferMeshNode::SafeDownCast(
                                          this->Context->Scene->GetReferencedNode(
                                              pose, repose::scene_schema::kTransferMeshRole)))
      p->SetTransferMeshSizeMm(mesh->GetSizeMm());
  }
  p->EndModify(state);
  // The input box shows G: the voxels and label table the node read, not the file again.
  if (seg && !this->ShowVolume(inFolder(seg->GetLabelMapFileName()), seg->GetLabelMap()))
    return false;
  if (seg) this->VolumeReadNotes = seg->GetLabelMapReadNotes();  // the box says them as a read does
  // A rigged pose goes live (a job: PollJob/WaitForJob commits it).
  if (pose &&
      this->Context->Scene->GetReferencedNode(pose, repose::scene_schema::kTransferMeshRole) &&
      !this->Live->StartLivePose(pose))
    return false;
  this->Modified();
  return true;
}
