// vtkSlicerReposeLogic, the live half: a pose node prepared for interaction (its rig embedded and
// factorized once, on the worker), then each edit re-solved at preview precision on the calling
// thread, and the deformed labels rasterized on the slice planes the views show.
#include "vtkMRMLReposeCageNode.h"
#include "vtkMRMLReposePoseNode.h"
#include "vtkMRMLReposeScene.h"
#include "vtkMRMLReposeSegmentationNode.h"
#include "vtkMRMLReposeTransferMeshNode.h"
#include "vtkSlicerReposeJob.h"
#include "vtkSlicerReposeLogic.h"
#include "vtkSlicerReposeLogicGuarded.h"
#include "vtkSlicerReposeLogicInputs.h"
#include "vtkSlicerReposeMeshConversion.h"
#include "vtkSlicerReposeVolumeConversion.h"

#include <repose/mesh/PointAnchors.h>
#include <repose/mesh/VolumePrediction.h>
#include <repose/pose/PoseJob.h>
#include <repose/pose/PoseRig.h>
#include <repose/skeleton/Skeleton.h>
#include <repose/raster/Rasterizer.h>
#include <repose/util/Error.h>

#include <vtkCellArray.h>
#include <vtkCommand.h>
#include <vtkPoints.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <optional>

using Conversion = vtkSlicerReposeVolumeConversion;

struct vtkSlicerReposeLogic::LiveSession {
  vtkSmartPointer<vtkMRMLReposePoseNode> Pose;
  unsigned long PoseObserverTag = 0;
  std::shared_ptr<const repose::Volume> Labels;  // G
  // S (or G's body mask) for the outlines: converted from the segmentation node when first
  // asked for, so a live pose whose outlines are never shown holds no copy of it.
  std::shared_ptr<const repose::Volume> Parts;
  std::shared_ptr<const repose::Volume> Image;  // the segmentation's image, if any
  double ImageBackground = 0, ImageWindow = 0, ImageLevel = 0;
  std::shared_ptr<const repose::PoseRig> Rig;
  repose::LabelTable PartLabels;  // S's, for groups selecting parts
  std::vector<std::uint8_t> OuterFaces;
  Eigen::MatrixX3d Deformed;                 // the live frame's TM vertices
  std::vector<repose::RigidHandle> Handles;  // and its groups' motions
  Eigen::Vector3d Lo{0, 0, 0}, Hi{0, 0, 0};
  vtkSmartPointer<vtkPolyData> Cage, Body;
  double FrameMilliseconds = 0;
  std::optional<vtkSlicerReposeLogic::LivePrediction> Prediction;  // of Deformed, when asked
  // The skeleton's joints, anchored once in the rest mesh: their centres follow every frame.
  std::vector<repose::SkeletonJoint> Joints;
  Eigen::MatrixX3d JointCentres;  // rest, one row per joint
  std::vector<repose::PointAnchor> JointAnchors;
};

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

// The image's background (repose::imageBackground, as the export has it) and a grey window: CT's
// soft-tissue window when the values are Hounsfield units (air near -1000), else the 1st..99th
// percentile of a sample.
void imageWindow(const repose::Volume& image, double& background, double& window, double& level) {
  background = repose::imageBackground(image);
  std::vector<double> sample;
  const std::int64_t n = image.numVoxels();
  const std::int64_t stride = std::max<std::int64_t>(1, n / 200000);
  repose::dispatchScalar(image.scalarType(), [&](auto* tag) {
    using T = std::remove_pointer_t<decltype(tag)>;
    const T* v = image.data<T>();
    for (std::int64_t i = 0; i < n; i += stride) sample.push_back(double(v[i]));
  });
  if (sample.empty()) return;
  std::sort(sample.begin(), sample.end());
  const double lo = sample[sample.size() / 100], hi = sample[sample.size() * 99 / 100];
  if (background <= -900 && background >= -1100 && hi > 0) {
    window = 400;
    level = 40;
  } else {
    window = std::max(hi - lo, 1e-6);
    level = (hi + lo) / 2;
  }
}

void setPoints(vtkPolyData* poly, const Eigen::MatrixX3d& positions) {
  vtkPoints* points = poly->GetPoints();
  points->SetNumberOfPoints(positions.rows());
  for (Eigen::Index v = 0; v < positions.rows(); ++v)
    points->SetPoint(v, positions(v, 0), positions(v, 1), positions(v, 2));
  points->Modified();
  poly->Modified();
}

}  // namespace

bool vtkSlicerReposeLogic::StartLivePose(vtkMRMLReposePoseNode* poseNode) {
  return this->Guarded<bool>(false, [&]() -> bool {
    if (this->Job->IsRunning()) throw repose::Error("another job is running");
    const auto nodes = vtkSlicerReposeLogicInputs::Resolve(this->Scene, poseNode);
    // Converted here, on the caller's thread: the worker never touches the nodes.
    auto G = std::make_shared<const repose::Volume>(
        Conversion::FromImageData(nodes.Segmentation->GetLabelMap()));
    const repose::LabelTable partLabels =
        vtkSlicerReposeLogicInputs::BodyPartLabels(nodes.Segmentation);
    std::shared_ptr<const repose::Volume> image;
    if (nodes.Segmentation->GetImage())
      image = std::make_shared<const repose::Volume>(
          Conversion::FromImageData(nodes.Segmentation->GetImage()));
    repose::RigGeometry geometry{
        vtkSlicerReposeMeshConversion::FromPolyData(nodes.Cage->GetMesh()),
        vtkSlicerReposeMeshConversion::FromUnstructuredGrid(nodes.TransferMesh->GetMesh()),
        nodes.TransferMesh->GetCoordinatesFile()};
    const repose::Pose pose = repose::parsePose(poseNode->GetPoseJSON(), poseNode->GetName());
    // The joints bend live as they do in the export and in `repose pose` (Core's pose job).
    auto S = std::make_shared<const repose::Volume>(
        vtkSlicerReposeLogicInputs::PartsOf(nodes.Segmentation));
    const std::shared_ptr<const repose::PoseJob> job =
        this->PoseJobFor(nodes.Segmentation, pose, *G, *S);
    // A pose that turns about named joints (a scene `repose pose --scene` wrote, a pose file of
    // the suite) is written back in numbers, as the rig's build writes it: every frame of the
    // live session and every edit reads the node, and the joints' places are the skeleton's.
    if (repose::poseNamesJoints(pose)) poseNode->SetPoseJSON(repose::poseToJson(job->userPose()));
    const std::optional<repose::Skeleton> skeleton =
        vtkSlicerReposeLogicInputs::SkeletonOf(nodes.Segmentation);
    vtkSmartPointer<vtkMRMLReposePoseNode> poseRef = poseNode;
    this->Job->Start(
        "live pose",
        [=, S = S, geometry = std::move(geometry)](
            const repose::ProgressFn& progress) mutable -> vtkSlicerReposeJob::Commit {
          repose::reportProgress(progress, 0, "embedding");
          auto session = std::make_shared<LiveSession>();
          session->Labels = G;
          if (image) {
            session->Image = image;
            imageWindow(*image, session->ImageBackground, session->ImageWindow,
                        session->ImageLevel);
          }
          session->Rig = std::shared_ptr<const repose::PoseRig>(job->makeRig(std::move(geometry)));
          session->PartLabels = partLabels;
          session->OuterFaces = repose::outerFaces(session->Rig->mesh());
          session->Cage = vtkSlicerReposeMeshConversion::ToPolyData(session->Rig->cage());
          session->Body = bodySurface(session->Rig->mesh(), session->OuterFaces);
          if (skeleton) {
            session->Joints = skeleton->joints;
            session->JointCentres.resize(Eigen::Index(session->Joints.size()), 3);
            for (std::size_t j = 0; j < session->Joints.size(); ++j)
              session->JointCentres.row(Eigen::Index(j)) = session->Joints[j].centre.transpose();
            session->JointAnchors =
                repose::anchorPoints(session->Rig->mesh(), session->JointCentres);
          }
          repose::reportProgress(progress, 1, "embedding");
          return [this, session, poseRef] {
            this->StopLivePose();
            session->Pose = poseRef;
            this->Live = session;
            // Every change of the pose node (an edit, undo/redo, the keyframe) re-solves.
            session->PoseObserverTag = poseRef->AddObserver(
                vtkCommand::ModifiedEvent, this, &vtkSlicerReposeLogic::OnLivePoseModified);
            this->UpdateLiveFrame();
          };
        });
    return true;
  });
}

void vtkSlicerReposeLogic::OnLivePoseModified() {
  if (!this->Live) return;
  // New or changed handle groups (a group made from a selection, or its undo) need the rig
  // prepared again: a job, after which the frame is solved. Until then the last frame stays.
  std::optional<repose::Pose> pose;
  if (!this->Guarded<bool>(false, [&] {
        pose = repose::parsePose(this->Live->Pose->GetPoseJSON(), this->Live->Pose->GetName());
        return true;
      })) {
    this->Modified();
    return;
  }
  if (!repose::sameHandleGroups(*pose, this->Live->Rig->userPose())) {
    if (!this->StartLivePose(this->Live->Pose)) this->Modified();
    return;
  }
  this->SolveLiveFrame(*pose);  // the pose parsed once per change
}

void vtkSlicerReposeLogic::ReleaseLivePose() {
  if (this->Live && this->Live->Pose) this->Live->Pose->RemoveObserver(this->Live->PoseObserverTag);
  this->Live.reset();
}

void vtkSlicerReposeLogic::StopLivePose() {
  if (!this->Live) return;
  this->ReleaseLivePose();
  this->Modified();
}

vtkMRMLReposePoseNode* vtkSlicerReposeLogic::GetLivePose() const {
  return this->Live ? this->Live->Pose.GetPointer() : nullptr;
}

bool vtkSlicerReposeLogic::UpdateLiveFrame() {
  if (!this->Live) return false;
  std::optional<repose::Pose> pose;
  if (!this->Guarded<bool>(false, [&] {
        pose = repose::parsePose(this->Live->Pose->GetPoseJSON(), this->Live->Pose->GetName());
        return true;
      })) {
    this->Modified();
    return false;
  }
  return this->SolveLiveFrame(*pose);
}

bool vtkSlicerReposeLogic::SolveLiveFrame(const repose::Pose& pose) {
  LiveSession& live = *this->Live;
  const bool solved = this->Guarded<bool>(false, [&] {
    const auto start = std::chrono::steady_clock::now();
    const std::size_t frames = pose.frames().size();
    const std::size_t index =
        std::min<std::size_t>(std::size_t(live.Pose->GetCurrentFrame()), frames - 1);
    // Warm-started from the last live frame: a drag's free cage vertices converge in a few ARAP
    // iterations per edit (the export solves its frame from rest).
    const repose::PoseRig::Frame frame = live.Rig->liveFrame(pose, index);
    live.Deformed = frame.deformed;
    live.Handles = frame.handles;
    live.Prediction.reset();
    setPoints(live.Cage, frame.cage);
    setPoints(live.Body, frame.deformed);
    const repose::TransferMesh& mesh = live.Rig->mesh();
    live.Lo = mesh.vertices.colwise().minCoeff().transpose().cwiseMin(
        frame.deformed.colwise().minCoeff().transpose());
    live.Hi = mesh.vertices.colwise().maxCoeff().transpose().cwiseMax(
        frame.deformed.colwise().maxCoeff().transpose());
    live.FrameMilliseconds =
        std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
    return true;
  });
  this->Modified();  // the views follow a new frame, or show the message
  return solved;
}

double vtkSlicerReposeLogic::GetLiveFrameMilliseconds() const {
  return this->Live ? this->Live->FrameMilliseconds : 0;
}

vtkPolyData* vtkSlicerReposeLogic::GetLiveCage() const {
  return this->Live ? this->Live->Cage.GetPointer() : nullptr;
}

vtkPolyData* vtkSlicerReposeLogic::GetLiveBodySurface() const {
  return this->Live ? this->Live->Body.GetPointer() : nullptr;
}

std::vector<std::array<double, 3>> vtkSlicerReposeLogic::GetLiveRestCage() const {
  std::vector<std::array<double, 3>> out;
  if (!this->Live) return out;
  const Eigen::MatrixX3d& v = this->Live->Rig->cage().vertices;
  out.reserve(std::size_t(v.rows()));
  for (Eigen::Index i = 0; i < v.rows(); ++i) out.push_back({v(i, 0), v(i, 1), v(i, 2)});
  return out;
}

std::vector<int> vtkSlicerReposeLogic::GetLiveGroupVertices(const std::string& group) const {
  if (!this->Live) return {};
  const repose::Pose& pose = this->Live->Rig->pose();
  for (std::size_t g = 0; g < pose.groups.size(); ++g)
    if (pose.groups[g].name == group) return this->Live->Rig->handles().at(g).cageVertices;
  return {};
}

std::vector<int> vtkSlicerReposeLogic::GetLiveCageVerticesOfPart(int label) const {
  if (!this->Live || label <= 0) return {};
  // As a group selecting the part would: resolved by the same Core function as a pose file's.
  repose::Pose probe;
  repose::PoseGroup group;
  group.name = "part";
  group.select.parts = {label};
  probe.groups.push_back(group);
  try {
    return repose::resolveHandles(probe, this->Live->Rig->cage(), this->Live->Rig->mesh(),
                                  this->Live->PartLabels)
        .front()
        .cageVertices;
  } catch (const repose::Error&) {
    return {};  // a part too small to reach the cage
  }
}

std::vector<std::pair<int, std::string>> vtkSlicerReposeLogic::GetLiveBodyParts() const {
  std::vector<std::pair<int, std::string>> parts;
  if (!this->Live) return parts;
  for (const repose::Label& l : this->Live->PartLabels.labels())
    if (l.value > 0) parts.emplace_back(l.value, l.name);
  return parts;
}

std::array<double, 3> vtkSlicerReposeLogic::GetLiveRestCenter() const {
  if (!this->Live) return {0, 0, 0};
  const repose::TransferMesh& mesh = this->Live->Rig->mesh();
  const Eigen::Vector3d c =
      (mesh.vertices.colwise().minCoeff() + mesh.vertices.colwise().maxCoeff()).transpose() / 2;
  return {c.x(), c.y(), c.z()};
}

vtkSlicerReposeLogic::LivePrediction vtkSlicerReposeLogic::GetLivePrediction() {
  if (!this->Live || this->Live->Deformed.rows() == 0) return {};
  LiveSession& live = *this->Live;
  if (!live.Prediction) {
    Eigen::MatrixX3d restored = live.Deformed;
    live.Rig->restoreFrameVolumes(restored, live.Handles);
    const repose::VolumePrediction p = repose::predictVolumeChange(live.Rig->mesh(), restored);
    LivePrediction out;
    out.valid = true;
    out.bodyChangePercent = p.changePercent();
    auto name = [&](int part) -> std::string {
      if (part == 0) return "";
      const repose::Label* l = live.PartLabels.find(part);
      return l && !l->name.empty() ? l->name : std::to_string(part);
    };
    out.worstPart = name(p.worstPart);
    out.draggedBy = name(p.draggedBy);
    for (const repose::PartVolumeChange& c : p.parts)
      if (c.part == p.worstPart) out.worstPartChangePercent = c.changePercent();
    // The part furthest from its volume in percent, against the per-part target.
    const repose::PartVolumeChange* furthest = nullptr;
    for (const repose::PartVolumeChange& c : p.parts)
      if (c.restMm3 > 0 &&
          (!furthest || std::fabs(c.changePercent()) > std::fabs(furthest->changePercent())))
        furthest = &c;
    char text[160];
    if (std::fabs(out.bodyChangePercent) > repose::kBodyTargetPercent) {
      std::snprintf(text, sizeof text, "body %+.2f %% (target within 0.5 %%)",
                    out.bodyChangePercent);
      out.missed = text;
    }
    if (furthest && std::fabs(furthest->changePercent()) > repose::kLabelTargetPercent) {
      std::snprintf(text, sizeof text, "%s %+.2f %% (target within 1 %%)",
                    name(furthest->part).c_str(), furthest->changePercent());
      out.missed += (out.missed.empty() ? "" : "; ") + std::string(text);
      out.worstPart = name(furthest->part);
      out.worstPartChangePercent = furthest->changePercent();
    }
    out.met = out.missed.empty();
    live.Prediction = out;
  }
  return *live.Prediction;
}

int vtkSlicerReposeLogic::GetLiveRestLabelAt(double r, double a, double s) const {
  if (!this->Live || !this->Live->Labels) return -1;
  const repose::Volume& G = *this->Live->Labels;
  const Eigen::Vector3d ijk = G.geometry().rasToVoxel(Eigen::Vector3d(r, a, s));
  std::int64_t at[3];
  for (int k = 0; k < 3; ++k) {
    at[k] = std::llround(ijk[k]);
    if (!std::isfinite(ijk[k]) || at[k] < 0 || at[k] >= G.dims()[std::size_t(k)]) return -1;
  }
  return int(G.valueAsDouble(G.index(at[0], at[1], at[2])));
}

std::string vtkSlicerReposeLogic::GetLivePartName(int value) const {
  if (this->Live)
    if (const repose::Label* l = this->Live->PartLabels.find(value); l && !l->name.empty())
      return l->name;
  return std::to_string(value);
}

std::vector<vtkSlicerReposeLogic::LiveJoint> vtkSlicerReposeLogic::GetLiveJoints() const {
  std::vector<LiveJoint> out;
  if (!this->Live || this->Live->Joints.empty() || this->Live->Deformed.rows() == 0) return out;
  const LiveSession& live = *this->Live;
  const repose::TransferMesh& mesh = live.Rig->mesh();
  const Eigen::MatrixX3d centres =
      repose::movePoints(mesh, live.Deformed, live.JointAnchors, live.JointCentres);
  for (std::size_t j = 0; j < live.Joints.size(); ++j) {
    LiveJoint joint;
    joint.name = live.Joints[j].name;
    const Eigen::Index row = Eigen::Index(j);
    joint.centre = {centres(row, 0), centres(row, 1), centres(row, 2)};
    // An axis turns with the tissue around the joint's centre (its tet's gradient).
    const int tet = live.JointAnchors[j].tet;
    const Eigen::Matrix3d F = tet >= 0 ? repose::tetDeformationGradient(mesh, live.Deformed, tet)
                                       : Eigen::Matrix3d::Identity();
    for (const auto& [axisName, axis] : live.Joints[j].axes) {
      Eigen::Vector3d a = F * axis;
      a = a.norm() > 1e-12 ? a.normalized() : axis;
      joint.axes.push_back({axisName, {a.x(), a.y(), a.z()}});
    }
    out.push_back(std::move(joint));
  }
  return out;
}

std::string vtkSlicerReposeLogic::GetLiveLabelName(int value) const {
  if (this->Live && this->Live->Labels)
    if (const repose::Label* l = this->Live->Labels->labels().find(value); l && !l->name.empty())
      return l->name;
  return std::to_string(value);
}

std::array<double, 6> vtkSlicerReposeLogic::GetLiveBounds() const {
  if (!this->Live) return {0, 0, 0, 0, 0, 0};
  const LiveSession& l = *this->Live;
  return {l.Lo.x(), l.Hi.x(), l.Lo.y(), l.Hi.y(), l.Lo.z(), l.Hi.z()};
}

namespace {
// The plane through the live box: square pixels, `pixels` across the box's larger in-plane side
// and only as many as the box needs across the other.
repose::VolumeGeometry liveSliceGrid(const Eigen::Vector3d& lo, const Eigen::Vector3d& hi,
                                     int orientation, double positionMm, int pixels) {
  repose::VolumeGeometry grid = repose::slicePlaneGrid(
      static_cast<repose::SliceOrientation>(orientation), positionMm, lo, hi, pixels);
  const int u = orientation == 2 ? 1 : 0, v = orientation == 0 ? 1 : 2;
  const double pixel = grid.ijkToRas.block<3, 1>(0, 0).norm();
  grid.dims[0] =
      std::clamp<std::int64_t>(std::int64_t(std::ceil((hi[u] - lo[u]) / pixel)), 1, pixels);
  grid.dims[1] =
      std::clamp<std::int64_t>(std::int64_t(std::ceil((hi[v] - lo[v]) / pixel)), 1, pixels);
  return grid;
}
}  // namespace

vtkSmartPointer<vtkImageData> vtkSlicerReposeLogic::ComputeLiveSlice(int orientation,
                                                                     double positionMm,
                                                                     int pixels) {
  if (!this->Live || this->Live->Deformed.rows() == 0 || orientation < 0 || orientation > 2 ||
      pixels < 2)
    return nullptr;
  const LiveSession& live = *this->Live;
  const auto start = std::chrono::steady_clock::now();
  const repose::VolumeGeometry grid =
      liveSliceGrid(live.Lo, live.Hi, orientation, positionMm, pixels);
  repose::RasterOptions options;
  options.outerFaces = &live.OuterFaces;
  const repose::Volume slice =
      repose::rasterizeLabels(*live.Labels, live.Rig->mesh(), live.Deformed, grid, options);
  this->LiveSliceMilliseconds =
      std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
  return Conversion::ToImageData(slice);
}

vtkSmartPointer<vtkImageData> vtkSlicerReposeLogic::ComputeLivePartsSlice(int orientation,
                                                                          double positionMm,
                                                                          int pixels) {
  if (!this->Live || this->Live->Deformed.rows() == 0 || orientation < 0 || orientation > 2 ||
      pixels < 2)
    return nullptr;
  LiveSession& live = *this->Live;
  if (!live.Parts && !this->Guarded<bool>(false, [&] {
        live.Parts = std::make_shared<const repose::Volume>(vtkSlicerReposeLogicInputs::PartsOf(
            vtkSlicerReposeLogicInputs::Resolve(this->Scene, live.Pose).Segmentation));
        return true;
      }))
    return nullptr;
  repose::RasterOptions options;
  options.outerFaces = &live.OuterFaces;
  return Conversion::ToImageData(repose::rasterizeLabels(
      *live.Parts, live.Rig->mesh(), live.Deformed,
      liveSliceGrid(live.Lo, live.Hi, orientation, positionMm, pixels), options));
}

vtkSmartPointer<vtkImageData> vtkSlicerReposeLogic::ComputeLiveImageSlice(int orientation,
                                                                          double positionMm,
                                                                          int pixels) {
  if (!this->Live || !this->Live->Image || this->Live->Deformed.rows() == 0 || orientation < 0 ||
      orientation > 2 || pixels < 2)
    return nullptr;
  const LiveSession& live = *this->Live;
  repose::RasterOptions options;
  options.outerFaces = &live.OuterFaces;
  return Conversion::ToImageData(
      repose::rasterizeImage(*live.Image, live.Rig->mesh(), live.Deformed,
                             liveSliceGrid(live.Lo, live.Hi, orientation, positionMm, pixels),
                             live.ImageBackground, options));
}

std::optional<vtkSlicerReposeLogic::ImageWindow> vtkSlicerReposeLogic::GetLiveImageWindow() const {
  if (!this->Live || !this->Live->Image) return std::nullopt;
  return ImageWindow{this->Live->ImageWindow, this->Live->ImageLevel};
}
