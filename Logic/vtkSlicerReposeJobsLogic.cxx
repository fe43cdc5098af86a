// vtkSlicerReposeJobsLogic: the rig from an organ map, the rig (cage and transfer mesh) of a pose,
// the export of a pose's frame and the mesh's refinement, as jobs on the one worker. Node data is
// converted to Core types on the calling thread before a job starts and back when it is
// committed, so the worker never touches a VTK object the caller owns.
#include "vtkSlicerReposeJobsLogic.h"

#include "vtkMRMLReposeCageNode.h"
#include "vtkMRMLReposeParametersNode.h"
#include "vtkMRMLReposePoseNode.h"
#include "vtkMRMLReposeScene.h"
#include "vtkMRMLReposeSegmentationNode.h"
#include "vtkMRMLReposeTransferMeshNode.h"
#include "vtkSlicerReposeLiveLogic.h"
#include "vtkSlicerReposeLogicContext.h"
#include "vtkSlicerReposeLogicInputs.h"
#include "vtkSlicerReposeLogicRead.h"
#include "vtkSlicerReposeMeshConversion.h"
#include "vtkSlicerReposeVolumeConversion.h"

#include <repose/pose/FramePreview.h>
#include <repose/pose/PoseFrame.h>
#include <repose/pose/PoseJob.h>
#include <repose/pose/PoseRig.h>
#include <repose/pose/PoseRun.h>
#include <repose/rig/Rig.h>
#include <repose/util/Error.h>
#include <repose/util/Memory.h>

#include <vtkObjectFactory.h>
#include <vtkUnstructuredGrid.h>

#include <algorithm>
#include <filesystem>
#include <iomanip>
#include <sstream>

namespace fs = std::filesystem;
using Conversion = vtkSlicerReposeVolumeConversion;
namespace Inputs = vtkSlicerReposeLogicInputs;

vtkStandardNewMacro(vtkSlicerReposeJobsLogic);

vtkSlicerReposeJobsLogic::vtkSlicerReposeJobsLogic() = default;
vtkSlicerReposeJobsLogic::~vtkSlicerReposeJobsLogic() = default;

const std::string& vtkSlicerReposeJobsLogic::GetLastErrorMessage() const {
  return this->Context->LastErrorMessage;
}

bool vtkSlicerReposeJobsLogic::StartBuildRig(vtkMRMLReposeSegmentationNode* seg,
                                             vtkMRMLReposePoseNode* poseNode) {
  return this->Context->Guarded<bool>(false, [&]() -> bool {
    if (!seg || !seg->GetLabelMap() || !poseNode)
      throw repose::Error("building the rig needs a segmentation with a label map and a pose");
    if (this->Context->Job->IsRunning()) throw repose::Error("another job is running");
    auto parts = std::make_shared<repose::Volume>(Inputs::PartsOf(seg));
    auto G = std::make_shared<repose::Volume>(Conversion::FromImageData(seg->GetLabelMap()));
    const repose::Pose& named = Inputs::PoseOf(poseNode);
    if (repose::poseNamesJoints(named) && !Inputs::SkeletonOf(seg))
      throw repose::Error("pose " + poseNode->GetName() + " names joints, but segmentation " +
                          seg->GetName() + " has no skeleton (skeleton.json beside its S)");
    // The job decides what `repose pose` decides: joints, separations (the pose's and the
    // automatic ones), whole pieces, the joints' finer tets.
    const std::shared_ptr<const repose::PoseJob> job =
        Inputs::PoseJobFor(this->Context->ParameterNode, seg, named, *G, *parts);
    // The user's pose (without the groups the girdles' and pelvis's rhythms add when the rig
    // solves: those follow the user's turns, they are not edited).
    const repose::Pose pose = job->userPose();
    if (repose::poseNamesJoints(named))
      poseNode->SetPose(std::make_shared<const repose::Pose>(pose));  // the rig's, in numbers
    const repose::RigSettings settings = job->settings();
    vtkSmartPointer<vtkMRMLReposeSegmentationNode> segRef = seg;
    vtkSmartPointer<vtkMRMLReposePoseNode> poseRef = poseNode;
    // The job holds G and S: the worker keeps them alive while it builds.
    this->Context->Job->Start(
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
            cage->SetCageChoice(geometry->cageChoice.json());
            std::vector<vtkMRMLReposeCageNode::HandleGroup> groups;
            for (std::size_t g = 0; g < handles->size(); ++g)
              groups.push_back({pose.groups[g].name, (*handles)[g].cageVertices});
            cage->SetHandleGroups(groups);
            cage->SetNodeReferenceID("segmentation", segRef->GetID());
            auto mesh = vtkSmartPointer<vtkMRMLReposeTransferMeshNode>::New();
            mesh->SetName(segRef->GetName() + " transfer mesh");
            mesh->SetMesh(vtkSlicerReposeMeshConversion::ToUnstructuredGrid(geometry->mesh));
            mesh->SetSizeMm(settings.meshMm);
            this->Context->Scene->AddNode(cage);
            mesh->SetNodeReferenceID("segmentation", segRef->GetID());
            mesh->SetNodeReferenceID("cage", cage->GetID());
            this->Context->Scene->AddNode(mesh);
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

std::string vtkSlicerReposeJobsLogic::DefaultRigFolder(const std::string& labelsPath,
                                                       const std::string& outputFolder) {
  if (!outputFolder.empty()) return (fs::path(outputFolder) / "rig").string();
  if (labelsPath.empty()) return "";
  return (fs::path(labelsPath).parent_path() /
          (vtkSlicerReposeLogicRead::FileStem(labelsPath) + "_rig"))
      .string();
}

bool vtkSlicerReposeJobsLogic::StartRigFromOrganMap(const std::string& labelsPath,
                                                    const std::string& folder) {
  return this->Context->Guarded<bool>(false, [&]() -> bool {
    if (this->Context->Job->IsRunning()) throw repose::Error("another job is running");
    if (labelsPath.empty()) throw repose::Error("choose a segmentation first");
    if (folder.empty()) throw repose::Error("no folder given for the rig");
    auto G =
        std::make_shared<const repose::Volume>(vtkSlicerReposeLogicRead::ReadVolume(labelsPath));
    repose::requirePoseableLabels(*G, labelsPath);  // the rule of every front end
    const std::string imagePath =
        this->Context->ParameterNode ? this->Context->ParameterNode->GetImagePath() : "";
    std::shared_ptr<const repose::Volume> image;
    if (!imagePath.empty())
      image =
          std::make_shared<const repose::Volume>(vtkSlicerReposeLogicRead::ReadVolume(imagePath));
    vtkSmartPointer<vtkMRMLReposeParametersNode> parameters = this->Context->ParameterNode;
    this->Context->Job->Start(
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
            if (!parameters) return;
            const int state = parameters->StartModify();
            parameters->SetRigSummary(summary.str());
            parameters->SetTissueTablePath(folder + "/tissues.csv");
            parameters->SetBodyPartMapPath(folder + "/S.nii.gz");
            parameters->EndModify(state);
          };
        });
    return true;
  });
}

bool vtkSlicerReposeJobsLogic::StartRefineMesh(vtkMRMLReposePoseNode* poseNode, int iterations) {
  return this->Context->Guarded<bool>(false, [&]() -> bool {
    if (this->Context->Job->IsRunning()) throw repose::Error("another job is running");
    const auto nodes = Inputs::Resolve(this->Context->Scene, poseNode);
    vtkPolyData* posed = this->Context->Live->GetLiveCage();
    if (poseNode != this->Context->Live->GetLivePose() || !posed)
      throw repose::Error("pose " + poseNode->GetName() +
                          " is not being posed live: the refinement adapts to its current frame");
    auto parts = std::make_shared<repose::Volume>(Inputs::PartsOf(nodes.Segmentation));
    auto G = std::make_shared<repose::Volume>(
        Conversion::FromImageData(nodes.Segmentation->GetLabelMap()));
    const repose::Pose& pose = Inputs::PoseOf(poseNode);
    const std::shared_ptr<const repose::PoseJob> job =
        Inputs::PoseJobFor(this->Context->ParameterNode, nodes.Segmentation, pose, *G, *parts);
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
    this->Context->Job->Start(
        "refine", [=](const repose::ProgressFn& progress) -> vtkSlicerReposeJob::Commit {
          auto steps = std::make_shared<std::vector<repose::RefinementStep>>();
          auto mesh = std::make_shared<repose::TransferMesh>(
              repose::refineRigMesh(*parts, *cage, posedCage, separations, settings, iterations,
                                    progress, G.get(), steps.get()));
          return [=] {
            auto node = vtkSmartPointer<vtkMRMLReposeTransferMeshNode>::New();
            node->SetName(oldMesh->GetName() + " refined for " + poseRef->GetName());
            node->SetMesh(vtkSlicerReposeMeshConversion::ToUnstructuredGrid(*mesh));
            node->SetSizeMm(settings.meshMm);
            for (const auto& [role, id] : oldMesh->GetNodeReferences())
              node->SetNodeReferenceID(role, id);
            this->Context->Scene->AddNode(node);
            poseRef->SetNodeReferenceID("transfer_mesh", node->GetID());
            vtkMRMLReposeTransferMeshNode::Refinement record;
            record.fromVertices = before;
            for (const repose::RefinementStep& step : *steps) {
              record.vertices.push_back(step.vertices);
              record.maxErrors.push_back(step.maxError);
            }
            node->SetRefinement(record);
          };
        });
    return true;
  });
}

bool vtkSlicerReposeJobsLogic::StartApplyPose(vtkMRMLReposePoseNode* poseNode,
                                              const std::string& outputFolder) {
  return this->Context->Guarded<bool>(false, [&]() -> bool {
    if (this->Context->Job->IsRunning()) throw repose::Error("another job is running");
    const auto nodes = Inputs::Resolve(this->Context->Scene, poseNode);
    auto* seg = nodes.Segmentation;
    auto* cageNode = nodes.Cage;
    auto* meshNode = nodes.TransferMesh;
    if (!outputFolder.empty() && !fs::is_directory(fs::absolute(outputFolder).parent_path()))
      throw repose::Error(outputFolder + ": its parent folder does not exist");
    auto G = std::make_shared<repose::Volume>(Conversion::FromImageData(seg->GetLabelMap()));
    auto S = std::make_shared<repose::Volume>(Inputs::PartsOf(seg));
    std::shared_ptr<repose::Volume> I;
    if (seg->GetImage())
      I = std::make_shared<repose::Volume>(Conversion::FromImageData(seg->GetImage()));
    repose::RigGeometry geometry{
        vtkSlicerReposeMeshConversion::FromPolyData(cageNode->GetMesh()),
        vtkSlicerReposeMeshConversion::FromUnstructuredGrid(meshNode->GetMesh()),
        meshNode->GetCoordinatesFile(), Inputs::CageChoiceOf(cageNode)};
    const repose::Pose& pose = Inputs::PoseOf(poseNode);
    const std::size_t frame = std::size_t(poseNode->GetCurrentFrame());
    // Tissues, skeleton and the joints' bends as `repose pose` has them.
    const std::shared_ptr<const repose::PoseJob> job =
        Inputs::PoseJobFor(this->Context->ParameterNode, seg, pose, *G, *S);
    // Memory: the posed G, S and image and the displacement field beside what the workbench
    // holds, by the rule `repose pose` has (repose::checkFrameMemory): first on the input's grid
    // (here), then on the frame's (on the worker, before any voxel is written). 0 MiB: half the
    // physical memory, as --memory's default.
    const double budget = 1048576.0 * (this->Context->ParameterNode
                                           ? this->Context->ParameterNode->GetOutputMemoryBudgetMB()
                                           : 0);
    // With an output folder a frame beyond the budget is made slab by slab there, as `repose
    // pose` makes it (the same files); the new node then holds a preview read back from them.
    const bool outOfCore = !outputFolder.empty();
    const char* budgetHint =
        "Output > Memory budget, or an output folder: a frame beyond the budget is made slab by "
        "slab there";
    if (!outOfCore)
      repose::checkFrameMemory(G->geometry(), repose::posedBytesPerVoxel(*G, *S, I.get()), budget,
                               "the posed volumes", budgetHint);
    vtkSmartPointer<vtkMRMLReposeSegmentationNode> segRef = seg;
    vtkSmartPointer<vtkMRMLReposePoseNode> poseRef = poseNode;
    this->Context->Job->Start(
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
          run.outOfCore = outOfCore;
          repose::FrameOutcome outcome =
              repose::runPoseFrame(*job, *rig, std::min(frame, rig->frameCount() - 1), *G, *S, run);
          auto f = std::make_shared<repose::PosedFrame>(std::move(outcome.frame));
          std::vector<std::string> warnings = job->warnings();
          std::string name = segRef->GetName() + " " + f->name;
          if (outcome.streamed) {
            // Its maps are the folder's files: the node gets G and S read back as a preview
            // within what the budget leaves, 8 MiB to 512 MiB (the heap the frame used may not
            // be back with the system, and a preview needs no more); no image.
            const double previewBytes =
                std::clamp(repose::memoryLeftWithin(budget), 8.0 * 1048576, 512.0 * 1048576);
            const repose::FramePreview preview = repose::previewStreamedFrame(
                outputFolder, previewBytes,
                [&](double x, const std::string&) { return progress(0.9 + 0.1 * x, "preview"); });
            f->organs = preview.organs;
            f->parts = preview.parts;
            f->image.reset();
            const std::string ratio = "1:" + std::to_string(preview.factor);
            name += " (preview " + ratio + ")";
            warnings.push_back(
                "made slab by slab (beyond Output > Memory budget): the full-"
                "resolution frame is in " +
                outputFolder + "; this node holds a " + ratio + " preview of G and S");
          }
          repose::reportProgress(progress, 1, "posed");
          return [=] {
            auto node = vtkSmartPointer<vtkMRMLReposeSegmentationNode>::New();
            node->SetName(name);
            node->SetLabelMap(Conversion::ToImageData(f->organs));
            node->SetBodyPartMap(Conversion::ToImageData(f->parts));
            if (f->image) node->SetImage(Conversion::ToImageData(*f->image));
            node->SetNodeReferenceID("source", segRef->GetID());
            node->SetNodeReferenceID("pose", poseRef->GetID());
            node->SetPoseReportJSON(f->reportJson);
            node->SetPoseWarnings(warnings);
            this->Context->Scene->AddNode(node);
            if (this->Context->ParameterNode)
              this->Context->ParameterNode->SetOutputSegmentationNodeID(node->GetID());
          };
        });
    return true;
  });
}

bool vtkSlicerReposeJobsLogic::IsJobRunning() const {
  return this->Context->Job->IsRunning();
}
double vtkSlicerReposeJobsLogic::GetJobProgress() const {
  return this->Context->Job->GetProgress();
}
std::string vtkSlicerReposeJobsLogic::GetJobStage() const {
  return this->Context->Job->GetStage();
}
void vtkSlicerReposeJobsLogic::CancelJob() {
  this->Context->Job->Cancel();
}

namespace {
int toStatus(vtkSlicerReposeJob::Status s) {
  switch (s) {
    case vtkSlicerReposeJob::Running:
      return vtkSlicerReposeJobsLogic::JobRunning;
    case vtkSlicerReposeJob::Succeeded:
      return vtkSlicerReposeJobsLogic::JobSucceeded;
    case vtkSlicerReposeJob::Cancelled:
      return vtkSlicerReposeJobsLogic::JobCancelled;
    case vtkSlicerReposeJob::Failed:
      return vtkSlicerReposeJobsLogic::JobFailed;
    default:
      return vtkSlicerReposeJobsLogic::JobIdle;
  }
}
}  // namespace

int vtkSlicerReposeJobsLogic::WaitForJob() {
  const int status = toStatus(this->Context->Job->Wait());
  if (status == JobFailed) this->Context->LastErrorMessage = this->Context->Job->GetLastError();
  if (status == JobSucceeded) this->Modified();
  return status;
}

int vtkSlicerReposeJobsLogic::PollJob() {
  const int status = toStatus(this->Context->Job->Poll());
  if (status == JobFailed) this->Context->LastErrorMessage = this->Context->Job->GetLastError();
  if (status == JobSucceeded) this->Modified();
  return status;
}

std::string vtkSlicerReposeJobsLogic::GetLastRigSummary() const {
  return this->Context->ParameterNode ? this->Context->ParameterNode->GetRigSummary() : "";
}

vtkMRMLReposeSegmentationNode* vtkSlicerReposeJobsLogic::GetLastPosedSegmentation() const {
  if (!this->Context->ParameterNode) return nullptr;
  return vtkMRMLReposeSegmentationNode::SafeDownCast(this->Context->Scene->GetNodeByID(
      this->Context->ParameterNode->GetOutputSegmentationNodeID()));
}

std::vector<std::string> vtkSlicerReposeJobsLogic::GetLastPoseWarnings() const {
  const vtkMRMLReposeSegmentationNode* posed = this->GetLastPosedSegmentation();
  return posed ? posed->GetPoseWarnings() : std::vector<std::string>();
}

vtkMRMLReposeTransferMeshNode* vtkSlicerReposeJobsLogic::LastRefinedMesh() const {
  const auto meshes = this->Context->Scene->GetNodesByClass("vtkMRMLReposeTransferMeshNode");
  for (auto it = meshes.rbegin(); it != meshes.rend(); ++it)
    if (auto* mesh = vtkMRMLReposeTransferMeshNode::SafeDownCast(*it);
        mesh && !mesh->GetRefinement().vertices.empty())
      return mesh;
  return nullptr;
}

std::string vtkSlicerReposeJobsLogic::GetLastRefinementSummary() const {
  const vtkMRMLReposeTransferMeshNode* mesh = this->LastRefinedMesh();
  if (!mesh) return "";
  const vtkMRMLReposeTransferMeshNode::Refinement& r = mesh->GetRefinement();
  std::ostringstream summary;
  summary << "refined in " << r.vertices.size() << " rounds: " << r.fromVertices << " -> "
          << (mesh->GetMesh() ? mesh->GetMesh()->GetNumberOfPoints() : vtkIdType(0)) << " vertices";
  if (!r.maxErrors.empty())
    summary << ", maximum error " << std::setprecision(3) << r.maxErrors.front() << " -> "
            << r.maxErrors.back();
  return summary.str();
}

std::vector<int> vtkSlicerReposeJobsLogic::GetLastRefinementVertices() const {
  const vtkMRMLReposeTransferMeshNode* mesh = this->LastRefinedMesh();
  return mesh ? mesh->GetRefinement().vertices : std::vector<int>();
}

std::vector<double> vtkSlicerReposeJobsLogic::GetLastRefinementMaxErrors() const {
  const vtkMRMLReposeTransferMeshNode* mesh = this->LastRefinedMesh();
  return mesh ? mesh->GetRefinement().maxErrors : std::vector<double>();
}
