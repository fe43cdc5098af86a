// vtkSlicerReposeLogic, the pipeline half: segmentation and pose nodes from files, the rig (cage
// and transfer mesh) and posed volumes made by jobs on a worker thread, undoable pose edits, and
// scene folders. Node data is converted to Core types on the calling thread before a job starts
// and back when it is committed, so the worker never touches a VTK object the caller owns.
#include "vtkMRMLReposeCageNode.h"
#include "vtkMRMLReposeParametersNode.h"
#include "vtkMRMLReposePoseNode.h"
#include "vtkMRMLReposeScene.h"
#include "vtkMRMLReposeSegmentationNode.h"
#include "vtkMRMLReposeTransferMeshNode.h"
#include "vtkSlicerReposeJob.h"
#include "vtkSlicerReposeLogic.h"
#include "vtkSlicerReposeLogicGuarded.h"
#include "vtkSlicerReposeSceneIO.h"
#include "vtkSlicerReposeLogicRead.h"
#include "vtkSlicerReposeLogicInputs.h"
#include "vtkSlicerReposeMeshConversion.h"
#include "vtkSlicerReposeVolumeConversion.h"

#include <repose/io/MeshIO.h>
#include <repose/io/NrrdIO.h>
#include <repose/io/VolumeIO.h>
#include <repose/pose/PoseFrame.h>
#include <repose/pose/PoseJob.h>
#include <repose/pose/PoseReport.h>
#include <repose/pose/PoseRig.h>
#include <repose/pose/PoseRun.h>
#include <repose/raster/PocketFilling.h>
#include <repose/raster/Rasterizer.h>
#include <repose/rig/Rig.h>
#include <repose/schema/SceneSchema.h>
#include <repose/util/Error.h>

#include <nlohmann/json.hpp>
#include <vtkMatrix4x4.h>

#include <array>
#include <filesystem>
#include <fstream>
#include <iomanip>
#include <optional>
#include <sstream>

namespace fs = std::filesystem;
using Conversion = vtkSlicerReposeVolumeConversion;

namespace {

std::string stemOf(const std::string& path) {
  std::string name = fs::path(path).filename().string();
  for (const char* ext : {".nii.gz", ".seg.nrrd", ".pose.json", ".nii", ".nrrd", ".nhdr"})
    if (name.size() > std::strlen(ext) &&
        name.compare(name.size() - std::strlen(ext), std::strlen(ext), ext) == 0)
      return name.substr(0, name.size() - std::strlen(ext));
  return name;
}

}  // namespace

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

repose::LabelTable BodyPartLabels(vtkMRMLReposeSegmentationNode* seg) {
  if (seg->GetBodyPartMap()) return Conversion::GetLabelTable(seg->GetBodyPartMap());
  repose::LabelTable table;
  repose::Label body;
  body.value = 1;
  body.name = "body";
  table.set(body);
  return table;
}

}  // namespace vtkSlicerReposeLogicInputs

void vtkSlicerReposeLogic::SetScene(vtkMRMLReposeScene* scene) {
  if (!scene || scene == this->Scene) return;
  this->Scene = scene;
  this->History.Clear();
  this->Modified();
}
vtkMRMLReposeScene* vtkSlicerReposeLogic::GetScene() const {
  return this->Scene;
}

vtkMRMLReposeSegmentationNode* vtkSlicerReposeLogic::AddSegmentation(const std::string& labels,
                                                                     const std::string& parts,
                                                                     const std::string& image) {
  return this->Guarded<vtkMRMLReposeSegmentationNode*>(
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
                vtkSlicerReposeLogicRead::FilesStamp({labels, this->TissueTablePath})) {
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
          vtkSlicerReposeLogicRead::NameLabels(G, this->TissueTablePath, labels);
          labelMap = Conversion::ToImageData(G);
          for (int a = 0; a < 3; ++a) dims[std::size_t(a)] = int(G.dims()[std::size_t(a)]);
          ijkToRas = G.geometry().ijkToRas;
        }
        auto node = vtkSmartPointer<vtkMRMLReposeSegmentationNode>::New();
        node->SetName(stemOf(labels));
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
        this->Scene->AddNode(node);
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
  return this->Guarded<vtkMRMLReposePoseNode*>(nullptr, [&]() -> vtkMRMLReposePoseNode* {
    repose::Pose pose = repose::readPoseFile(path);
    // Named joints become numbers with the skeleton of the newest segmentation that has one;
    // without one they stay named until the rig is built for a segmentation (StartBuildRig).
    if (repose::poseNamesJoints(pose)) {
      const auto segs = this->Scene->GetNodesByClass("vtkMRMLReposeSegmentationNode");
      for (auto it = segs.rbegin(); it != segs.rend(); ++it)
        if (auto* seg = vtkMRMLReposeSegmentationNode::SafeDownCast(*it);
            seg && !seg->GetSkeletonJSON().empty()) {
          repose::resolvePoseJoints(
              pose, repose::parseSkeleton(seg->GetSkeletonJSON(), seg->GetName() + " skeleton"));
          break;
        }
    }
    return this->AddPoseNode(pose.name.empty() ? stemOf(path) : pose.name,
                             repose::poseToJson(pose));
  });
}

vtkMRMLReposePoseNode* vtkSlicerReposeLogic::AddPoseNode(const std::string& name,
                                                         const std::string& json) {
  auto node = vtkSmartPointer<vtkMRMLReposePoseNode>::New();
  node->SetName(name);
  node->SetPoseJSON(json);
  this->Scene->AddNode(node);
  return node;
}

bool vtkSlicerReposeLogic::StartBuildRig(vtkMRMLReposeSegmentationNode* seg,
                                         vtkMRMLReposePoseNode* poseNode) {
  return this->Guarded<bool>(false, [&]() -> bool {
    if (!seg || !seg->GetLabelMap() || !poseNode)
      throw repose::Error("building the rig needs a segmentation with a label map and a pose");
    if (this->Job->IsRunning()) throw repose::Error("another job is running");
    auto parts = std::make_shared<repose::Volume>(vtkSlicerReposeLogicInputs::PartsOf(seg));
    auto G = std::make_shared<repose::Volume>(Conversion::FromImageData(seg->GetLabelMap()));
    const repose::Pose named = repose::parsePose(poseNode->GetPoseJSON(), poseNode->GetName());
    if (repose::poseNamesJoints(named) && !vtkSlicerReposeLogicInputs::SkeletonOf(seg))
      throw repose::Error("pose " + poseNode->GetName() + " names joints, but segmentation " +
                          seg->GetName() + " has no skeleton (skeleton.json beside its S)");
    // The job decides what `repose pose` decides: joints, separations (the pose's and the
    // automatic ones), whole pieces, the joints' finer tets.
    const std::shared_ptr<const repose::PoseJob> job = this->PoseJobFor(seg, named, *G, *parts);
    // The user's pose (without the groups the girdles' and pelvis's rhythms add when the rig
    // solves: those follow the user's turns, they are not edited).
    const repose::Pose pose = job->userPose();
    if (repose::poseNamesJoints(named))
      poseNode->SetPoseJSON(repose::poseToJson(pose));  // the rig's pose, in numbers
    const repose::RigSettings settings = job->settings();
    vtkSmartPointer<vtkMRMLReposeSegmentationNode> segRef = seg;
    vtkSmartPointer<vtkMRMLReposePoseNode> poseRef = poseNode;
    // The job holds G and S: the worker keeps them alive while it builds.
    this->Job->Start(
        "rig", [=, G = G](const repose::ProgressFn& progress) -> vtkSlicerReposeJob::Commit {
          auto geometry = std::make_shared<repose::RigGeometry>(job->buildGeometry(progress));
          auto handles = std::make_shared<std::vector<repose::RigidHandle>>(
              repose::resolveHandles(pose, geometry->cage, geometry->mesh, parts->labels()));
          return [=] {
            auto cage = vtkSmartPointer<vtkMRMLReposeCageNode>::New();
            cage->SetName(segRef->GetName() + " cage");
            cage->SetMesh(vtkSlicerReposeMeshConversion::ToPolyData(geometry->cage));
            cage->SetTargetVertexCount(settings.cageVertices);
            cage->SetDilationMm(settings.dilateMm);
            std::vector<vtkMRMLReposeCageNode::HandleGroup> groups;
            for (std::size_t g = 0; g < handles->size(); ++g)
              groups.push_back({pose.groups[g].name, (*handles)[g].cageVertices});
            cage->SetHandleGroups(groups);
            cage->SetNodeReferenceID("segmentation", segRef->GetID());
            auto mesh = vtkSmartPointer<vtkMRMLReposeTransferMeshNode>::New();
            mesh->SetName(segRef->GetName() + " transfer mesh");
            mesh->SetMesh(vtkSlicerReposeMeshConversion::ToUnstructuredGrid(geometry->mesh));
            mesh->SetSizeMm(settings.meshMm);
            this->Scene->AddNode(cage);
            mesh->SetNodeReferenceID("segmentation", segRef->GetID());
            mesh->SetNodeReferenceID("cage", cage->GetID());
            this->Scene->AddNode(mesh);
            const int state = poseRef->StartModify();
            poseRef->SetNodeReferenceID("segmentation", segRef->GetID());
            poseRef->SetNodeReferenceID("cage", cage->GetID());
            poseRef->SetNodeReferenceID("transfer_mesh", mesh->GetID());
            poseRef->EndModify(state);
          };
        });
    return true;
  });
}

std::string vtkSlicerReposeLogic::PartsPath() const {
  return this->ParameterNode ? this->ParameterNode->GetBodyPartMapPath() : std::string();
}

std::shared_ptr<const repose::PoseJob> vtkSlicerReposeLogic::PoseJobFor(
    vtkMRMLReposeSegmentationNode* seg, const repose::Pose& pose, const repose::Volume& G,
    const repose::Volume& S) const {
  repose::PoseJobRequest request;
  request.organsName =
      seg->GetLabelMapFileName().empty() ? seg->GetName() : seg->GetLabelMapFileName();
  request.partsPath = this->PartsPath();
  request.tissuesPath = this->TissueTablePath;
  request.skeleton = vtkSlicerReposeLogicInputs::SkeletonOf(seg);
  // What G's reader decided (a DICOM SEG's grid...), kept in the export's report.json as the
  // command line keeps it: the segmentation's own, from the file it was read from.
  request.organsNotes = seg->GetLabelMapReadNotes();
  if (this->ParameterNode) {
    request.settings.cageVertices = this->ParameterNode->GetCageVertexCount();
    request.settings.dilateMm = this->ParameterNode->GetCageDilationMm();
    request.settings.meshMm = this->ParameterNode->GetTransferMeshSizeMm();
  }
  return std::make_shared<const repose::PoseJob>(pose, G, S, std::move(request));
}

std::string vtkSlicerReposeLogic::DefaultRigFolder(const std::string& labelsPath,
                                                   const std::string& outputFolder) {
  if (!outputFolder.empty()) return (fs::path(outputFolder) / "rig").string();
  if (labelsPath.empty()) return "";
  return (fs::path(labelsPath).parent_path() / (stemOf(labelsPath) + "_rig")).string();
}

bool vtkSlicerReposeLogic::StartRigFromOrganMap(const std::string& labelsPath,
                                                const std::string& folder) {
  return this->Guarded<bool>(false, [&]() -> bool {
    if (this->Job->IsRunning()) throw repose::Error("another job is running");
    if (labelsPath.empty()) throw repose::Error("choose a segmentation first");
    if (folder.empty()) throw repose::Error("no folder given for the rig");
    auto G =
        std::make_shared<const repose::Volume>(vtkSlicerReposeLogicRead::ReadVolume(labelsPath));
    repose::requirePoseableLabels(*G, labelsPath);  // the rule of every front end
    const std::string imagePath = this->ParameterNode ? this->ParameterNode->GetImagePath() : "";
    std::shared_ptr<const repose::Volume> image;
    if (!imagePath.empty())
      image =
          std::make_shared<const repose::Volume>(vtkSlicerReposeLogicRead::ReadVolume(imagePath));
    vtkSmartPointer<vtkMRMLReposeParametersNode> parameters = this->ParameterNode;
    this->Job->Start(
        "rig from organ map",
        [=](const repose::ProgressFn& progress) -> vtkSlicerReposeJob::Commit {
          repose::RigOptions options;
          options.source = labelsPath;
          options.image = image.get();
          options.imageSource = imagePath;
          options.progress = progress;
          auto rig = std::make_shared<const repose::RigResult>(repose::rigBody(*G, options));
          repose::writeRigFolder(*rig, folder, labelsPath);
          return [=] {
            std::ostringstream summary;
            summary << rig->convention.name << " convention, " << rig->skeleton.joints.size()
                    << " joints";
            if (!rig->missing.empty())
              summary << ", " << rig->missing.size() << " not made (" << rig->missing.front()
                      << (rig->missing.size() > 1 ? ", ..." : "") << ")";
            if (!rig->warnings.empty())
              summary << "; " << rig->warnings.size()
                      << (rig->warnings.size() == 1 ? " warning" : " warnings") << " in rig.json";
            this->LastRigSummary = summary.str();
            this->TissueTablePath = folder + "/tissues.csv";
            if (parameters) parameters->SetBodyPartMapPath(folder + "/S.nii.gz");
          };
        });
    return true;
  });
}

bool vtkSlicerReposeLogic::StartRefineMesh(vtkMRMLReposePoseNode* poseNode, int iterations) {
  return this->Guarded<bool>(false, [&]() -> bool {
    if (this->Job->IsRunning()) throw repose::Error("another job is running");
    const auto nodes = vtkSlicerReposeLogicInputs::Resolve(this->Scene, poseNode);
    vtkPolyData* posed = this->GetLiveCage();
    if (poseNode != this->GetLivePose() || !posed)
      throw repose::Error("pose " + poseNode->GetName() +
                          " is not being posed live: the refinement adapts to its current frame");
    auto parts =
        std::make_shared<repose::Volume>(vtkSlicerReposeLogicInputs::PartsOf(nodes.Segmentation));
    auto G = std::make_shared<repose::Volume>(
        Conversion::FromImageData(nodes.Segmentation->GetLabelMap()));
    const repose::Pose pose = repose::parsePose(poseNode->GetPoseJSON(), poseNode->GetName());
    const std::shared_ptr<const repose::PoseJob> job =
        this->PoseJobFor(nodes.Segmentation, pose, *G, *parts);
    const std::vector<repose::LimbSeparation> separations = job->separations().all;
    const repose::RigSettings settings = job->settings();
    auto cage = std::make_shared<repose::TriangleMesh>(
        vtkSlicerReposeMeshConversion::FromPolyData(nodes.Cage->GetMesh()));
    Eigen::MatrixX3d posedCage(posed->GetNumberOfPoints(), 3);
    for (vtkIdType v = 0; v < posed->GetNumberOfPoints(); ++v) {
      double p[3];
      posed->GetPoint(v, p);
      posedCage.row(v) << p[0], p[1], p[2];
    }
    const int before = int(nodes.TransferMesh->GetMesh()->GetNumberOfPoints());
    vtkSmartPointer<vtkMRMLReposePoseNode> poseRef = poseNode;
    vtkSmartPointer<vtkMRMLReposeTransferMeshNode> oldMesh = nodes.TransferMesh;
    this->Job->Start("refine",
                     [=](const repose::ProgressFn& progress) -> vtkSlicerReposeJob::Commit {
                       auto steps = std::make_shared<std::vector<repose::RefinementStep>>();
                       auto mesh = std::make_shared<repose::TransferMesh>(
                           repose::refineRigMesh(*parts, *cage, posedCage, separations, settings,
                                                 iterations, progress, G.get(), steps.get()));
                       return [=] {
                         auto node = vtkSmartPointer<vtkMRMLReposeTransferMeshNode>::New();
                         node->SetName(oldMesh->GetName() + " refined for " + poseRef->GetName());
                         node->SetMesh(vtkSlicerReposeMeshConversion::ToUnstructuredGrid(*mesh));
                         node->SetSizeMm(settings.meshMm);
                         for (const auto& [role, id] : oldMesh->GetNodeReferences())
                           node->SetNodeReferenceID(role, id);
                         this->Scene->AddNode(node);
                         poseRef->SetNodeReferenceID("transfer_mesh", node->GetID());
                         std::ostringstream summary;
                         summary << "refined in " << steps->size() << " rounds: " << before
                                 << " -> " << mesh->vertices.rows() << " vertices";
                         if (!steps->empty())
                           summary << ", maximum error " << std::setprecision(3)
                                   << steps->front().maxError << " -> " << steps->back().maxError;
                         this->LastRefinementSummary = summary.str();
                         this->RefinementVertices.clear();
                         this->RefinementErrors.clear();
                         for (const repose::RefinementStep& step : *steps) {
                           this->RefinementVertices.push_back(step.vertices);
                           this->RefinementErrors.push_back(step.maxError);
                         }
                       };
                     });
    return true;
  });
}

bool vtkSlicerReposeLogic::StartApplyPose(vtkMRMLReposePoseNode* poseNode,
                                          const std::string& outputFolder) {
  return this->Guarded<bool>(false, [&]() -> bool {
    if (this->Job->IsRunning()) throw repose::Error("another job is running");
    const auto nodes = vtkSlicerReposeLogicInputs::Resolve(this->Scene, poseNode);
    auto* seg = nodes.Segmentation;
    auto* cageNode = nodes.Cage;
    auto* meshNode = nodes.TransferMesh;
    if (!outputFolder.empty() && !fs::is_directory(fs::absolute(outputFolder).parent_path()))
      throw repose::Error(outputFolder + ": its parent folder does not exist");
    auto G = std::make_shared<repose::Volume>(Conversion::FromImageData(seg->GetLabelMap()));
    auto S = std::make_shared<repose::Volume>(vtkSlicerReposeLogicInputs::PartsOf(seg));
    std::shared_ptr<repose::Volume> I;
    if (seg->GetImage())
      I = std::make_shared<repose::Volume>(Conversion::FromImageData(seg->GetImage()));
    repose::RigGeometry geometry{
        vtkSlicerReposeMeshConversion::FromPolyData(cageNode->GetMesh()),
        vtkSlicerReposeMeshConversion::FromUnstructuredGrid(meshNode->GetMesh()),
        meshNode->GetCoordinatesFile()};
    const repose::Pose pose = repose::parsePose(poseNode->GetPoseJSON(), poseNode->GetName());
    const std::size_t frame = std::size_t(poseNode->GetCurrentFrame());
    // Tissues, skeleton and the joints' bends as `repose pose` has them.
    const std::shared_ptr<const repose::PoseJob> job = this->PoseJobFor(seg, pose, *G, *S);
    // Memory: the posed G, S and image and the displacement field beside what the workbench
    // holds, by the rule `repose pose` has (repose::checkFrameMemory): first on the input's grid
    // (here), then on the frame's (on the worker, before any voxel is written). 0 MiB: half the
    // physical memory, as --memory's default.
    const double budget =
        1048576.0 * (this->ParameterNode ? this->ParameterNode->GetOutputMemoryBudgetMB() : 0);
    const char* budgetHint = "Output > Memory budget; out of core: `repose warp`";
    repose::checkFrameMemory(G->geometry(), repose::posedBytesPerVoxel(*G, *S, I.get()), budget,
                             "the posed volumes", budgetHint);
    vtkSmartPointer<vtkMRMLReposeSegmentationNode> segRef = seg;
    vtkSmartPointer<vtkMRMLReposePoseNode> poseRef = poseNode;
    this->Job->Start(
        "pose",
        [=, geometry = std::move(geometry)](
            const repose::ProgressFn& progress) mutable -> vtkSlicerReposeJob::Commit {
          repose::reportProgress(progress, 0, "embedding");
          const std::unique_ptr<repose::PoseRig> rig = job->makeRig(std::move(geometry));
          // The frame as `repose pose` runs it (one implementation: repose::runPoseFrame).
          repose::FrameRun run;
          run.image = I.get();  // where no tissue is: Core's rule (imageBackground)
          run.memoryBudget = budget;
          run.budgetHint = budgetHint;
          run.sceneReused = true;  // the scene's nodes' rig
          run.progress = [&](double x, const std::string& stage) {
            return progress(0.1 + 0.8 * x, stage);
          };
          // Written here, on the worker: past the rasterization nothing can cancel the job, and
          // the files are atomic, so a cancelled export still leaves the folder as it was.
          // Locked like `repose pose --out`: a run of it writing there refuses, and so does this.
          run.folder = outputFolder;
          run.write.lockFolder = true;
          auto f = std::make_shared<repose::PosedFrame>(
              repose::runPoseFrame(*job, *rig, std::min(frame, rig->frameCount() - 1), *G, *S, run)
                  .frame);
          repose::reportProgress(progress, 1, "posed");
          return [=] {
            auto node = vtkSmartPointer<vtkMRMLReposeSegmentationNode>::New();
            node->SetName(segRef->GetName() + " " + f->name);
            node->SetLabelMap(Conversion::ToImageData(f->organs));
            node->SetBodyPartMap(Conversion::ToImageData(f->parts));
            if (f->image) node->SetImage(Conversion::ToImageData(*f->image));
            node->SetNodeReferenceID("source", segRef->GetID());
            node->SetNodeReferenceID("pose", poseRef->GetID());
            this->Scene->AddNode(node);
            this->LastPosedSegmentation = node;
            this->LastPoseReport = f->reportJson;
            this->LastPoseWarnings = job->warnings();
          };
        });
    return true;
  });
}

bool vtkSlicerReposeLogic::IsJobRunning() const {
  return this->Job->IsRunning();
}
double vtkSlicerReposeLogic::GetJobProgress() const {
  return this->Job->GetProgress();
}
std::string vtkSlicerReposeLogic::GetJobStage() const {
  return this->Job->GetStage();
}
void vtkSlicerReposeLogic::CancelJob() {
  this->Job->Cancel();
}

namespace {
int toStatus(vtkSlicerReposeJob::Status s) {
  switch (s) {
    case vtkSlicerReposeJob::Running:
      return vtkSlicerReposeLogic::JobRunning;
    case vtkSlicerReposeJob::Succeeded:
      return vtkSlicerReposeLogic::JobSucceeded;
    case vtkSlicerReposeJob::Cancelled:
      return vtkSlicerReposeLogic::JobCancelled;
    case vtkSlicerReposeJob::Failed:
      return vtkSlicerReposeLogic::JobFailed;
    default:
      return vtkSlicerReposeLogic::JobIdle;
  }
}
}  // namespace

int vtkSlicerReposeLogic::WaitForJob() {
  const int status = toStatus(this->Job->Wait());
  if (status == JobFailed) this->LastErrorMessage = this->Job->GetLastError();
  if (status == JobSucceeded) this->Modified();
  return status;
}

int vtkSlicerReposeLogic::PollJob() {
  const int status = toStatus(this->Job->Poll());
  if (status == JobFailed) this->LastErrorMessage = this->Job->GetLastError();
  if (status == JobSucceeded) this->Modified();
  return status;
}

void vtkSlicerReposeLogic::SetTissueTablePath(const std::string& path) {
  this->TissueTablePath = path;
}

vtkMRMLReposeSegmentationNode* vtkSlicerReposeLogic::GetLastPosedSegmentation() const {
  return this->LastPosedSegmentation;
}

bool vtkSlicerReposeLogic::SaveScene(const std::string& folder) {
  return this->Guarded<bool>(false, [&] {
    vtkSlicerReposeSceneIO::Save(this->Scene, folder);
    return true;
  });
}

bool vtkSlicerReposeLogic::LoadScene(const std::string& folder) {
  return this->Guarded<bool>(false, [&] {
    const vtkSmartPointer<vtkMRMLReposeScene> loaded = vtkSlicerReposeSceneIO::Load(folder);
    this->Scene->Clear();
    for (int n = 0; n < loaded->GetNumberOfNodes(); ++n)
      this->Scene->AddNode(loaded->GetNthNode(n));
    this->History.Clear();
    this->LastPosedSegmentation = nullptr;
    this->Modified();
    return true;
  });
}

bool vtkSlicerReposeLogic::OpenScene(const std::string& folder) {
  if (!this->LoadScene(folder)) return false;
  if (!this->ParameterNode) return true;
  const auto segs = this->Scene->GetNodesByClass("vtkMRMLReposeSegmentationNode");
  const auto poses = this->Scene->GetNodesByClass("vtkMRMLReposePoseNode");
  auto* seg = segs.empty() ? nullptr : vtkMRMLReposeSegmentationNode::SafeDownCast(segs.front());
  auto* pose = poses.empty() ? nullptr : vtkMRMLReposePoseNode::SafeDownCast(poses.front());
  // The nodes name their files relative to the folder (or absolute, as the command line writes).
  auto inFolder = [&](const std::string& name) {
    return name.empty() || fs::path(name).is_absolute() ? name : (fs::path(folder) / name).string();
  };
  vtkMRMLReposeParametersNode* p = this->ParameterNode;
  const int state = p->StartModify();
  if (seg) {
    p->SetInputSegmentationNodeID(seg->GetID());
    p->SetBodyPartMapPath(inFolder(seg->GetBodyPartMapFileName()));
    p->SetImagePath(inFolder(seg->GetImageFileName()));
  }
  if (pose) {
    p->SetActivePoseNodeID(pose->GetID());
    p->SetPosePath(inFolder(pose->GetFileName()));
    const PoseSummary summary = this->GetPoseSummary(pose);
    if (!summary.movableGroups.empty()) p->SetActiveGroup(summary.movableGroups.front());
    if (auto* cage = vtkMRMLReposeCageNode::SafeDownCast(
            this->Scene->GetReferencedNode(pose, repose::scene_schema::kCageRole))) {
      p->SetCageVertexCount(cage->GetTargetVertexCount());
      p->SetCageDilationMm(cage->GetDilationMm());
    }
    if (auto* mesh = vtkMRMLReposeTransferMeshNode::SafeDownCast(
            this->Scene->GetReferencedNode(pose, repose::scene_schema::kTransferMeshRole)))
      p->SetTransferMeshSizeMm(mesh->GetSizeMm());
  }
  p->EndModify(state);
  // The input box shows G: the voxels and label table the node read, not the file again.
  if (seg && !this->ShowVolume(inFolder(seg->GetLabelMapFileName()), seg->GetLabelMap()))
    return false;
  if (seg) this->VolumeReadNotes = seg->GetLabelMapReadNotes();  // the box says them as a read does
  // A rigged pose goes live (a job: PollJob/WaitForJob commits it).
  if (pose && this->Scene->GetReferencedNode(pose, repose::scene_schema::kTransferMeshRole) &&
      !this->StartLivePose(pose))
    return false;
  this->Modified();
  return true;
}

vtkSlicerReposeLogic::PoseSummary vtkSlicerReposeLogic::GetPoseSummary(
    vtkMRMLReposePoseNode* pose) const {
  if (!pose) return {};
  if (pose == this->SummarizedPose && pose->GetMTime() == this->SummarizedTime)
    return this->Summary;
  PoseSummary s;
  try {
    const repose::Pose p = repose::parsePose(pose->GetPoseJSON(), pose->GetName());
    for (const repose::PoseGroup& g : p.groups)
      if (!g.fixed) s.movableGroups.push_back(g.name);
    s.keyframes = int(p.keyframes.size());
    for (const repose::PoseSeparation& sep : p.separations) {
      auto part = [&](int k) {
        return sep.partNames[std::size_t(k)].empty() ? std::to_string(sep.parts[std::size_t(k)])
                                                     : sep.partNames[std::size_t(k)];
      };
      s.separations.push_back(part(0) + " | " + part(1));
    }
    s.valid = true;
  } catch (const std::exception& e) {
    s.error = e.what();
  }
  this->SummarizedPose = pose;
  this->SummarizedTime = pose->GetMTime();
  this->Summary = s;
  return s;
}
