// Scene folders on disk for the Logic (docs/FORMATS.md, "Scene folders"): every data file its
// nodes hold written beside scene.json, and read back into a new scene.
#include "vtkSlicerReposeSceneIO.h"

#include "vtkMRMLReposeCageNode.h"
#include "vtkMRMLReposePoseNode.h"
#include "vtkMRMLReposeScene.h"
#include "vtkMRMLReposeSegmentationNode.h"
#include "vtkMRMLReposeTransferMeshNode.h"
#include "vtkSlicerReposeLogicRead.h"
#include "vtkSlicerReposeMeshConversion.h"
#include "vtkSlicerReposeVolumeConversion.h"

#include <repose/io/AtomicOutput.h>
#include <repose/io/ColorTableIO.h>
#include <repose/io/MeshIO.h>
#include <repose/io/VolumeIO.h>
#include <repose/mesh/RigiditySolver.h>
#include <repose/pose/Pose.h>
#include <repose/skeleton/Skeleton.h>
#include <repose/pose/SlicerSceneMrml.h>
#include <repose/schema/SceneSchema.h>
#include <repose/util/Error.h>

#include <nlohmann/json.hpp>
#include <vtkNew.h>

#include <filesystem>
#include <fstream>
#include <sstream>
#include <tuple>

namespace fs = std::filesystem;
using Conversion = vtkSlicerReposeVolumeConversion;

namespace {}  // namespace

namespace vtkSlicerReposeSceneIO {

void Save(vtkMRMLReposeScene* scene, const std::string& folder, const std::string& parameters) {
  if (!fs::is_directory(fs::absolute(folder).parent_path()))
    throw repose::Error(folder + ": its parent folder does not exist");
  fs::create_directories(folder);
  const fs::path dir = folder;
  for (int n = 0; n < scene->GetNumberOfNodes(); ++n) {
    vtkMRMLReposeNode* node = scene->GetNthNode(n);
    const std::string id = node->GetID();
    if (auto* seg = vtkMRMLReposeSegmentationNode::SafeDownCast(node)) {
      const int state = seg->StartModify();
      for (auto [image, setter, suffix] :
           {std::tuple{seg->GetLabelMap(), &vtkMRMLReposeSegmentationNode::SetLabelMapFileName,
                       "_G"},
            std::tuple{seg->GetBodyPartMap(),
                       &vtkMRMLReposeSegmentationNode::SetBodyPartMapFileName, "_S"},
            std::tuple{seg->GetImage(), &vtkMRMLReposeSegmentationNode::SetImageFileName,
                       "_image"}}) {
        const std::string name = image ? id + suffix + ".nii.gz" : "";
        if (image) repose::writeVolume(Conversion::FromImageData(image), (dir / name).string());
        (seg->*setter)(name);
      }
      seg->EndModify(state);
    } else if (auto* cage = vtkMRMLReposeCageNode::SafeDownCast(node)) {
      cage->SetFileName(id + ".vtk");
      repose::writeTriangleMesh(vtkSlicerReposeMeshConversion::FromPolyData(cage->GetMesh()),
                                (dir / cage->GetFileName()).string());
    } else if (auto* tm = vtkMRMLReposeTransferMeshNode::SafeDownCast(node)) {
      tm->SetFileName(id + ".vtu");
      repose::writeTransferMesh(vtkSlicerReposeMeshConversion::FromUnstructuredGrid(tm->GetMesh()),
                                (dir / tm->GetFileName()).string());
      // Its Green coordinates go along (whether they still fit the mesh and its cage is
      // checked where they are read).
      const std::string coordinates =
          repose::greenCoordinatesFileFor((dir / tm->GetFileName()).string());
      const std::string from = tm->GetCoordinatesFile();
      std::error_code ec;
      if (!from.empty() && fs::is_regular_file(from, ec) &&
          !fs::equivalent(from, coordinates, ec)) {
        repose::AtomicOutput copy(coordinates);
        fs::copy_file(from, copy.tempPath(), fs::copy_options::overwrite_existing);
        copy.commit();
        tm->SetCoordinatesFile(coordinates);
      } else if (from.empty() || !fs::is_regular_file(from, ec)) {
        tm->SetCoordinatesFile("");
      }
    } else if (auto* pose = vtkMRMLReposePoseNode::SafeDownCast(node)) {
      pose->SetFileName(id + ".pose.json");
      if (!pose->GetPose()) throw repose::Error("pose node " + id + " holds no pose to save");
      repose::writePoseFile(*pose->GetPose(), (dir / pose->GetFileName()).string());
    }
  }
  // The same scene for 3D Slicer (docs/SLICER.md): the input and the last posed label maps
  // (with a colour table: Slicer ignores a NIfTI's label table), the cage and the mesh.
  repose::SlicerSceneFiles mrml;
  for (int n = 0; n < scene->GetNumberOfNodes(); ++n) {
    vtkMRMLReposeNode* node = scene->GetNthNode(n);
    auto* seg = vtkMRMLReposeSegmentationNode::SafeDownCast(node);
    if (seg && !seg->GetLabelMapFileName().empty()) {
      const bool posed = scene->GetReferencedNode(seg, "source") != nullptr;
      std::string& slot = posed ? mrml.posedLabels : mrml.inputLabels;
      if (slot.empty()) slot = (dir / seg->GetLabelMapFileName()).string();
      if (!posed && mrml.colorTable.empty()) {
        mrml.colorTable = (dir / (std::string(seg->GetID()) + "_G.ctbl")).string();
        repose::writeColorTable(Conversion::FromImageData(seg->GetLabelMap()), mrml.colorTable);
      }
    }
    if (auto* cage = vtkMRMLReposeCageNode::SafeDownCast(node); cage && mrml.cage.empty())
      mrml.cage = (dir / cage->GetFileName()).string();
    if (auto* tm = vtkMRMLReposeTransferMeshNode::SafeDownCast(node);
        tm && mrml.transferMesh.empty())
      mrml.transferMesh = (dir / tm->GetFileName()).string();
  }
  repose::writeTextFileAtomically((dir / "scene.mrml").string(),
                                  repose::formatSlicerScene(mrml, dir.string()));
  nlohmann::ordered_json document = nlohmann::ordered_json::parse(scene->WriteJSON());
  if (!parameters.empty())
    document[repose::scene_schema::kParameters] = nlohmann::ordered_json::parse(parameters);
  repose::writeTextFileAtomically((dir / repose::scene_schema::kDocument).string(),
                                  document.dump(2) + "\n");
}

Loaded Load(const std::string& folder) {
  const fs::path dir = folder;
  auto loaded = vtkSmartPointer<vtkMRMLReposeScene>::New();
  std::string error;
  const std::string document = (dir / repose::scene_schema::kDocument).string();
  const std::string text = vtkSlicerReposeLogicRead::ReadText(document);
  if (!loaded->ReadJSON(text, &error)) throw repose::Error(document + ": " + error);
  std::string parameters;
  if (const nlohmann::json json = nlohmann::json::parse(text, nullptr, false);
      json.is_object() && json.contains(repose::scene_schema::kParameters)) {
    if (!json[repose::scene_schema::kParameters].is_object())
      throw repose::Error(document + ": " + repose::scene_schema::kParameters +
                          ": expected an object");
    parameters = json[repose::scene_schema::kParameters].dump();
  }
  auto need = [&](const std::string& name, vtkMRMLReposeNode* node) {
    if (name.empty())
      throw repose::Error(folder + ": node " + node->GetID() + " names no data file");
    return (dir / name).string();
  };
  for (int n = 0; n < loaded->GetNumberOfNodes(); ++n) {
    vtkMRMLReposeNode* node = loaded->GetNthNode(n);
    if (auto* seg = vtkMRMLReposeSegmentationNode::SafeDownCast(node)) {
      // The paths as OpenScene gives them to the panel, so building the rig reads nothing again.
      auto inFolder = [&](const std::string& name) {
        return name.empty() ? name : (dir / name).string();
      };
      seg->SetSourceStamp(vtkSlicerReposeLogicRead::FilesStamp(
          {inFolder(seg->GetLabelMapFileName()), inFolder(seg->GetBodyPartMapFileName()),
           inFolder(seg->GetImageFileName())}));
      std::vector<std::string> readNotes;
      seg->SetLabelMap(Conversion::ToImageData(
          vtkSlicerReposeLogicRead::ReadVolume(need(seg->GetLabelMapFileName(), seg), &readNotes)));
      seg->SetLabelMapReadNotes(readNotes);
      if (!seg->GetBodyPartMapFileName().empty()) {
        const std::string parts = (dir / seg->GetBodyPartMapFileName()).string();
        seg->SetBodyPartMap(Conversion::ToImageData(vtkSlicerReposeLogicRead::ReadVolume(parts)));
        // A scene the command line wrote names S where it is; its skeleton is beside it.
        if (seg->GetSkeletonJSON().empty())
          if (const std::string skeleton = repose::findSkeletonBeside(parts); !skeleton.empty())
            seg->SetSkeletonJSON(vtkSlicerReposeLogicRead::ReadText(skeleton));
      }
      if (!seg->GetImageFileName().empty())
        seg->SetImage(Conversion::ToImageData(
            vtkSlicerReposeLogicRead::ReadVolume((dir / seg->GetImageFileName()).string())));
    } else if (auto* cage = vtkMRMLReposeCageNode::SafeDownCast(node)) {
      cage->SetMesh(vtkSlicerReposeMeshConversion::ToPolyData(
          repose::readTriangleMesh(need(cage->GetFileName(), cage))));
    } else if (auto* tm = vtkMRMLReposeTransferMeshNode::SafeDownCast(node)) {
      const std::string meshFile = need(tm->GetFileName(), tm);
      tm->SetMesh(
          vtkSlicerReposeMeshConversion::ToUnstructuredGrid(repose::readTransferMesh(meshFile)));
      tm->SetCoordinatesFile(repose::greenCoordinatesFileFor(meshFile));
    } else if (auto* pose = vtkMRMLReposePoseNode::SafeDownCast(node)) {
      const std::string path = need(pose->GetFileName(), pose);
      pose->SetPose(std::make_shared<const repose::Pose>(repose::readPoseFile(path)));
    }
  }
  return {loaded, parameters};
}

}  // namespace vtkSlicerReposeSceneIO
