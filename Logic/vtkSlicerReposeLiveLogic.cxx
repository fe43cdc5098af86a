// vtkSlicerReposeLiveLogic: the Logic's side of a live session (Core's repose::LiveSession does
// the work): the nodes converted to Core on the calling thread before the session is prepared on
// the worker, the pose node observed, and the session's frame and slices converted to VTK.
#include "vtkSlicerReposeLiveLogic.h"

#include "vtkMRMLReposeCageNode.h"
#include "vtkMRMLReposePoseNode.h"
#include "vtkMRMLReposeSegmentationNode.h"
#include "vtkMRMLReposeTransferMeshNode.h"
#include "vtkSlicerReposeLogicContext.h"
#include "vtkSlicerReposeLogicInputs.h"
#include "vtkSlicerReposeMeshConversion.h"
#include "vtkSlicerReposeVolumeConversion.h"

#include <repose/pose/LivePredictionWorker.h>
#include <repose/pose/LiveSession.h>
#include <repose/pose/PoseJob.h>
#include <repose/util/Error.h>

#include <vtkCellArray.h>
#include <vtkCommand.h>
#include <vtkObjectFactory.h>
#include <vtkPoints.h>

using Conversion = vtkSlicerReposeVolumeConversion;
namespace Inputs = vtkSlicerReposeLogicInputs;

vtkStandardNewMacro(vtkSlicerReposeLiveLogic);

vtkSlicerReposeLiveLogic::vtkSlicerReposeLiveLogic()
    : Predictions(std::make_unique<repose::LivePredictionWorker>()) {}

vtkSlicerReposeLiveLogic::~vtkSlicerReposeLiveLogic() {
  this->ReleaseLivePose();
}

namespace {

// The outer faces of the rest mesh as triangles over the TM's vertices (posed by moving points).
vtkSmartPointer<vtkPolyData> bodySurface(const repose::TransferMesh& mesh,
                                         const std::vector<std::uint8_t>& outer) {
  static const int kFace[4][3] = {{1, 2, 3}, {0, 3, 2}, {0, 1, 3}, {0, 2, 1}};
  vtkNew<vtkCellArray> triangles;
  for (Eigen::Index t = 0; t < mesh.tets.rows(); ++t)
    for (int f = 0; f < 4; ++f)
      if (outer[std::size_t(t)] & (1u << f)) {
        const vtkIdType ids[3] = {mesh.tets(t, kFace[f][0]), mesh.tets(t, kFace[f][1]),
                                  mesh.tets(t, kFace[f][2])};
        triangles->InsertNextCell(3, ids);
      }
  auto poly = vtkSmartPointer<vtkPolyData>::New();
  vtkNew<vtkPoints> points;
  points->SetDataTypeToDouble();
  points->SetNumberOfPoints(mesh.vertices.rows());
  poly->SetPoints(points);
  poly->SetPolys(triangles);
  return poly;
}

void setPoints(vtkPolyData* poly, const Eigen::MatrixX3d& positions) {
  vtkPoints* points = poly->GetPoints();
  points->SetNumberOfPoints(positions.rows());
  for (Eigen::Index v = 0; v < positions.rows(); ++v)
    points->SetPoint(v, positions(v, 0), positions(v, 1), positions(v, 2));
  points->Modified();
  poly->Modified();
}

std::array<double, 3> array3(const Eigen::Vector3d& v) {
  return {v.x(), v.y(), v.z()};
}

}  // namespace

const std::string& vtkSlicerReposeLiveLogic::GetLastErrorMessage() const {
  return this->Context->LastErrorMessage;
}

bool vtkSlicerReposeLiveLogic::StartLivePose(vtkMRMLReposePoseNode* poseNode) {
  vtkSlicerReposeLogicContext& context = *this->Context;
  return context.Guarded<bool>(false, [&]() -> bool {
    if (context.Job->IsRunning()) throw repose::Error("another job is running");
    const auto nodes = Inputs::Resolve(context.Scene, poseNode);
    // Converted here, on the caller's thread: the worker never touches the nodes.
    repose::LiveInputs inputs;
    inputs.labels = std::make_shared<const repose::Volume>(
        Conversion::FromImageData(nodes.Segmentation->GetLabelMap()));
    inputs.partLabels = Inputs::BodyPartLabels(nodes.Segmentation);
    if (nodes.Segmentation->GetImage())
      inputs.image = std::make_shared<const repose::Volume>(
          Conversion::FromImageData(nodes.Segmentation->GetImage()));
    inputs.skeleton = Inputs::SkeletonOf(nodes.Segmentation);
    repose::RigGeometry geometry{
        vtkSlicerReposeMeshConversion::FromPolyData(nodes.Cage->GetMesh()),
        vtkSlicerReposeMeshConversion::FromUnstructuredGrid(nodes.TransferMesh->GetMesh()),
        nodes.TransferMesh->GetCoordinatesFile(), Inputs::CageChoiceOf(nodes.Cage)};
    const repose::Pose& pose = Inputs::PoseOf(poseNode);
    // The joints bend live as they do in the export and in `repose pose` (Core's pose job).
    auto G = inputs.labels;
    auto S = std::make_shared<const repose::Volume>(Inputs::PartsOf(nodes.Segmentation));
    const std::shared_ptr<const repose::PoseJob> job =
        Inputs::PoseJobFor(context.ParameterNode, nodes.Segmentation, pose, *G, *S);
    // A pose that turns about named joints (a scene `repose pose --scene` wrote, a pose file of
    // the suite) is put back in numbers, as the rig's build puts it: every frame of the live
    // session and every edit reads the node, and the joints' places are the skeleton's.
    if (repose::poseNamesJoints(pose))
      poseNode->SetPose(std::make_shared<const repose::Pose>(job->userPose()));
    vtkSmartPointer<vtkMRMLReposePoseNode> poseRef = poseNode;
    context.Job->Start(
        "live pose",
        [=, S = S, geometry = std::move(geometry), inputs = std::move(inputs)](
            const repose::ProgressFn& progress) mutable -> vtkSlicerReposeJob::Commit {
          // The job reads G and S (held by G and S here) while it makes the rig.
          auto session = std::make_shared<repose::LiveSession>(*job, std::move(geometry),
                                                               std::move(inputs), progress);
          vtkSmartPointer<vtkPolyData> cage =
              vtkSlicerReposeMeshConversion::ToPolyData(session->rig().cage());
          vtkSmartPointer<vtkPolyData> body =
              bodySurface(session->rig().mesh(), session->outerFaces());
          return [this, session, poseRef, cage, body] {
            this->StopLivePose();
            this->Session = session;
            this->Pose = poseRef;
            this->Cage = cage;
            this->Body = body;
            // Every change of the pose node (an edit, undo/redo, the keyframe) re-solves.
            this->PoseObserverTag = poseRef->AddObserver(
                vtkCommand::ModifiedEvent, this, &vtkSlicerReposeLiveLogic::OnLivePoseModified);
            this->UpdateLiveFrame();
          };
        });
    return true;
  });
}

void vtkSlicerReposeLiveLogic::OnLivePoseModified() {
  if (!this->Session) return;
  // New or changed handle groups (a group made from a selection, or its undo) need the session
  // prepared again: a job, after which the frame is solved. Until then the last frame stays.
  const std::shared_ptr<const repose::Pose> pose = this->Pose->GetPose();
  if (pose && !this->Session->solves(*pose)) {
    if (!this->StartLivePose(this->Pose)) this->Modified();
    return;
  }
  this->SolveLiveFrame();
}

void vtkSlicerReposeLiveLogic::ReleaseLivePose() {
  if (this->Pose) this->Pose->RemoveObserver(this->PoseObserverTag);
  this->Pose = nullptr;
  this->Predictions->cancel();
  ++this->FrameSerial;
  this->Session.reset();
  this->Cage = this->Body = nullptr;
}

void vtkSlicerReposeLiveLogic::StopLivePose() {
  if (!this->Session) return;
  this->ReleaseLivePose();
  this->Modified();
}

vtkMRMLReposePoseNode* vtkSlicerReposeLiveLogic::GetLivePose() const {
  return this->Session ? this->Pose.GetPointer() : nullptr;
}

bool vtkSlicerReposeLiveLogic::UpdateLiveFrame() {
  if (!this->Session) return false;
  return this->SolveLiveFrame();
}

bool vtkSlicerReposeLiveLogic::SolveLiveFrame() {
  // A prediction of the last frame is stale now: stopped, so it leaves the cores to the drag.
  this->Predictions->cancel();
  ++this->FrameSerial;
  const bool solved = this->Context->Guarded<bool>(false, [&] {
    // The node's pose, as the last edit left it: parsed when it was read, never here.
    this->Session->setPose(Inputs::PoseOf(this->Pose),
                           std::size_t(std::max(0, this->Pose->GetCurrentFrame())));
    setPoints(this->Cage, this->Session->posedCage());
    setPoints(this->Body, this->Session->deformed());
    return true;
  });
  this->Modified();  // the views follow a new frame, or show the message
  return solved;
}

double vtkSlicerReposeLiveLogic::GetLiveFrameMilliseconds() const {
  return this->Session ? this->Session->frameMilliseconds() : 0;
}

std::array<double, 6> vtkSlicerReposeLiveLogic::GetLiveBounds() const {
  if (!this->Session) return {0, 0, 0, 0, 0, 0};
  const Eigen::Vector3d &lo = this->Session->lo(), &hi = this->Session->hi();
  return {lo.x(), hi.x(), lo.y(), hi.y(), lo.z(), hi.z()};
}

std::array<double, 3> vtkSlicerReposeLiveLogic::GetLiveRestCenter() const {
  return this->Session ? array3(this->Session->restCentre()) : std::array<double, 3>{0, 0, 0};
}

std::vector<std::array<double, 3>> vtkSlicerReposeLiveLogic::GetLiveRestCage() const {
  std::vector<std::array<double, 3>> out;
  if (!this->Session) return out;
  const Eigen::MatrixX3d& v = this->Session->rig().cage().vertices;
  out.reserve(std::size_t(v.rows()));
  for (Eigen::Index i = 0; i < v.rows(); ++i) out.push_back({v(i, 0), v(i, 1), v(i, 2)});
  return out;
}

std::vector<int> vtkSlicerReposeLiveLogic::GetLiveGroupVertices(const std::string& group) const {
  return this->Session ? this->Session->groupVertices(group) : std::vector<int>();
}

std::vector<int> vtkSlicerReposeLiveLogic::GetLiveCageVerticesOfPart(int label) const {
  return this->Session ? this->Session->cageVerticesOfPart(label) : std::vector<int>();
}

std::vector<std::pair<int, std::string>> vtkSlicerReposeLiveLogic::GetLiveBodyParts() const {
  std::vector<std::pair<int, std::string>> parts;
  if (!this->Session) return parts;
  for (const repose::Label& l : this->Session->partLabels().labels())
    if (l.value > 0) parts.emplace_back(l.value, l.name);
  return parts;
}

namespace {

vtkSlicerReposeLiveLogic::LivePrediction toLogic(const repose::LivePrediction& p) {
  vtkSlicerReposeLiveLogic::LivePrediction out;
  out.valid = true;
  out.bodyChangePercent = p.bodyChangePercent;
  out.worstPart = p.worstPart;
  out.draggedBy = p.draggedBy;
  out.worstPartChangePercent = p.worstPartChangePercent;
  out.met = p.met;
  out.missed = p.missed;
  return out;
}

}  // namespace

vtkSlicerReposeLiveLogic::LivePrediction vtkSlicerReposeLiveLogic::GetLivePrediction() {
  if (!this->Session || !this->Session->hasFrame()) return {};
  // The worker's, if it predicts this frame; else computed here.
  if (this->Predictions->state(this->FrameSerial) != repose::LivePredictionWorker::State::None)
    if (const auto p = this->Predictions->wait(this->FrameSerial)) return toLogic(*p);
  return toLogic(this->Session->prediction());
}

void vtkSlicerReposeLiveLogic::RequestLivePrediction() {
  if (!this->Session || !this->Session->hasFrame()) return;
  // The panel asks on every update: the job (a copy of the frame) is made once per frame.
  if (this->Predictions->state(this->FrameSerial) != repose::LivePredictionWorker::State::None)
    return;
  this->Predictions->start(this->FrameSerial, this->Session->predictionJob());
}

vtkSlicerReposeLiveLogic::LivePrediction vtkSlicerReposeLiveLogic::PeekLivePrediction() {
  if (const auto p = this->Predictions->ready(this->FrameSerial)) return toLogic(*p);
  LivePrediction out;
  out.pending =
      this->Predictions->state(this->FrameSerial) == repose::LivePredictionWorker::State::Running;
  return out;
}

int vtkSlicerReposeLiveLogic::GetLiveRestLabelAt(double r, double a, double s) const {
  return this->Session ? this->Session->restLabelAt(Eigen::Vector3d(r, a, s)) : -1;
}

std::string vtkSlicerReposeLiveLogic::GetLiveLabelName(int value) const {
  if (this->Session)
    if (const repose::Label* l = this->Session->labels().labels().find(value);
        l && !l->name.empty())
      return l->name;
  return std::to_string(value);
}

std::string vtkSlicerReposeLiveLogic::GetLivePartName(int value) const {
  return this->Session ? this->Session->partName(value) : std::to_string(value);
}

std::vector<vtkSlicerReposeLiveLogic::LiveJoint> vtkSlicerReposeLiveLogic::GetLiveJoints() const {
  std::vector<LiveJoint> out;
  if (!this->Session) return out;
  for (const repose::LiveJoint& j : this->Session->joints()) {
    LiveJoint joint;
    joint.name = j.name;
    joint.centre = array3(j.centre);
    for (const auto& [name, axis] : j.axes) joint.axes.emplace_back(name, array3(axis));
    out.push_back(std::move(joint));
  }
  return out;
}

vtkSmartPointer<vtkImageData> vtkSlicerReposeLiveLogic::ComputeLiveSlice(int orientation,
                                                                         double positionMm,
                                                                         int pixels) {
  if (!this->Session || orientation < 0 || orientation > 2) return nullptr;
  const std::vector<repose::LiveSession::Slice> slices = this->Session->slices(
      {{repose::LiveSession::Layer::Labels, static_cast<repose::SliceOrientation>(orientation),
        positionMm, pixels}});
  if (!slices[0].voxels) return nullptr;
  this->SliceMilliseconds = slices[0].milliseconds;
  return Conversion::ToImageData(*slices[0].voxels);
}

vtkSlicerReposeLiveLogic::LiveSlices vtkSlicerReposeLiveLogic::ComputeLiveSlices(
    const std::array<double, 3>& positionsMm, int pixels, bool parts) {
  LiveSlices out;
  if (!this->Session || !this->Session->hasFrame()) return out;
  repose::LiveSession& session = *this->Session;
  // S (or G's body mask) for the outlines, converted from the segmentation node when first asked
  // for: a live pose whose outlines are never shown holds no copy of it.
  if (parts && !session.hasParts() && !this->Context->Guarded<bool>(false, [&] {
        session.setParts(std::make_shared<const repose::Volume>(
            Inputs::PartsOf(Inputs::Resolve(this->Context->Scene, this->Pose).Segmentation)));
        return true;
      }))
    parts = false;
  using Layer = repose::LiveSession::Layer;
  std::vector<repose::LiveSession::SliceRequest> requests;
  for (int o = 0; o < 3; ++o) {
    const auto orientation = static_cast<repose::SliceOrientation>(o);
    requests.push_back({Layer::Labels, orientation, positionsMm[std::size_t(o)], pixels});
    if (session.image())
      requests.push_back({Layer::Image, orientation, positionsMm[std::size_t(o)], pixels});
    if (parts) requests.push_back({Layer::Parts, orientation, positionsMm[std::size_t(o)], pixels});
  }
  const std::vector<repose::LiveSession::Slice> slices = session.slices(requests);
  for (std::size_t r = 0; r < requests.size(); ++r) {
    if (!slices[r].voxels) continue;
    const std::size_t o = std::size_t(requests[r].orientation);
    vtkSmartPointer<vtkImageData> image = Conversion::ToImageData(*slices[r].voxels);
    switch (requests[r].layer) {
      case Layer::Labels:
        out.labels[o] = image;
        out.labelMilliseconds[o] = slices[r].milliseconds;
        this->SliceMilliseconds = slices[r].milliseconds;
        break;
      case Layer::Image:
        out.images[o] = image;
        break;
      case Layer::Parts:
        out.parts[o] = image;
        break;
    }
  }
  return out;
}

std::optional<vtkSlicerReposeLiveLogic::ImageWindow> vtkSlicerReposeLiveLogic::GetLiveImageWindow()
    const {
  if (!this->Session) return std::nullopt;
  const auto window = this->Session->imageWindow();
  if (!window) return std::nullopt;
  return ImageWindow{window->window, window->level};
}
