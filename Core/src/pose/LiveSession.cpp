#include "repose/pose/LiveSession.h"

#include "repose/mesh/VolumePrediction.h"
#include "repose/pose/PoseFrame.h"
#include "repose/util/Error.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <limits>

namespace repose {

namespace {

using Clock = std::chrono::steady_clock;

double msSince(Clock::time_point start) {
  return std::chrono::duration<double, std::milli>(Clock::now() - start).count();
}

// A label's name in `table`, else its number.
std::string nameIn(const LabelTable& table, int value) {
  if (const Label* l = table.find(value); l && !l->name.empty()) return l->name;
  return std::to_string(value);
}

// CT's soft-tissue window when the values are Hounsfield units (air near -1000), else the
// 1st..99th percentile of a sample of at most about 200,000 voxels.
std::optional<LiveSession::ImageWindow> windowOf(const Volume& image, double background) {
  std::vector<double> sample;
  const std::int64_t n = image.numVoxels();
  const std::int64_t stride = std::max<std::int64_t>(1, n / 200000);
  dispatchScalar(image.scalarType(), [&](auto* tag) {
    using T = std::remove_pointer_t<decltype(tag)>;
    const T* v = image.data<T>();
    for (std::int64_t i = 0; i < n; i += stride) sample.push_back(double(v[i]));
  });
  if (sample.empty()) return std::nullopt;
  std::sort(sample.begin(), sample.end());
  const double lo = sample[sample.size() / 100], hi = sample[sample.size() * 99 / 100];
  if (background <= -900 && background >= -1100 && hi > 0) return LiveSession::ImageWindow{400, 40};
  return LiveSession::ImageWindow{std::max(hi - lo, 1e-6), (hi + lo) / 2};
}

// The plane through the live box: square pixels, `pixels` across the box's larger in-plane side
// and only as many as the box needs across the other.
VolumeGeometry liveSliceGrid(const Eigen::Vector3d& lo, const Eigen::Vector3d& hi,
                             SliceOrientation orientation, double positionMm, int pixels) {
  VolumeGeometry grid = slicePlaneGrid(orientation, positionMm, lo, hi, pixels);
  const int u = orientation == SliceOrientation::Sagittal ? 1 : 0;
  const int v = orientation == SliceOrientation::Axial ? 1 : 2;
  const double pixel = grid.ijkToRas.block<3, 1>(0, 0).norm();
  grid.dims[0] =
      std::clamp<std::int64_t>(std::int64_t(std::ceil((hi[u] - lo[u]) / pixel)), 1, pixels);
  grid.dims[1] =
      std::clamp<std::int64_t>(std::int64_t(std::ceil((hi[v] - lo[v]) / pixel)), 1, pixels);
  return grid;
}

}  // namespace

LiveSession::LiveSession(const PoseJob& job, RigGeometry geometry, LiveInputs inputs,
                         const ProgressFn& progress)
    : inputs_(std::move(inputs)) {
  if (!inputs_.labels) throw Error("a live session needs the label map it poses");
  reportProgress(progress, 0, "embedding");
  rig_ = job.makeRig(std::move(geometry));
  outerFaces_ = repose::outerFaces(rig_->mesh());
  if (inputs_.image) {
    imageBackground_ = imageBackground(*inputs_.image);
    window_ = windowOf(*inputs_.image, imageBackground_);
  }
  if (inputs_.skeleton) {
    const std::vector<SkeletonJoint>& joints = inputs_.skeleton->joints;
    jointCentres_.resize(Eigen::Index(joints.size()), 3);
    for (std::size_t j = 0; j < joints.size(); ++j)
      jointCentres_.row(Eigen::Index(j)) = joints[j].centre.transpose();
    jointAnchors_ = anchorPoints(rig_->mesh(), jointCentres_);
    anchorJointsInProximalBones(joints);
  }
  reportProgress(progress, 1, "embedding");
}

void LiveSession::anchorJointsInProximalBones(const std::vector<SkeletonJoint>& joints) {
  // A joint's centre is a point of its proximal bone: anchored to the nearest piece tet of its
  // proximal part, it moves with that bone exactly. The tet that holds it is a soft tet of the
  // joint space, which bends with the joint (since joint spaces get free layers, the elbow's
  // sphere drifted 4 mm off the unmoved humerus at a 90 degree bend). A part with no piece keeps
  // the holding tet.
  const TransferMesh& mesh = rig_->mesh();
  if (mesh.rigid.empty()) return;
  for (std::size_t j = 0; j < joints.size(); ++j) {
    int part = 0;
    for (const Label& l : inputs_.partLabels.labels())
      if (!joints[j].parts[0].empty() && l.name == joints[j].parts[0]) part = l.value;
    if (part == 0) continue;
    int nearest = -1;
    double best = std::numeric_limits<double>::infinity();
    for (Eigen::Index t = 0; t < mesh.tets.rows(); ++t) {
      if (!mesh.rigid[std::size_t(t)] || mesh.labels[t] != part) continue;
      Eigen::Vector3d c = Eigen::Vector3d::Zero();
      for (int k = 0; k < 4; ++k) c += mesh.vertices.row(mesh.tets(t, k)).transpose() / 4;
      const double d = (c - joints[j].centre).squaredNorm();
      if (d < best) best = d, nearest = int(t);
    }
    const PointAnchor anchor = anchorPointInTet(mesh, joints[j].centre, nearest);
    if (anchor.tet >= 0) jointAnchors_[j] = anchor;
  }
}

LiveSession::~LiveSession() = default;

bool LiveSession::solves(const Pose& pose) const {
  return sameHandleGroups(pose, rig_->userPose());
}

void LiveSession::setPose(const Pose& pose, std::size_t frame) {
  const auto start = Clock::now();
  const std::size_t frames = pose.frames().size();
  // Warm-started from the last live frame: a drag's free cage vertices converge in a few ARAP
  // iterations per edit (the export solves its frame from rest).
  PoseRig::Frame solved = rig_->liveFrame(pose, std::min(frame, frames - 1));
  // Copied into the buffers the last frame used (the same size every frame), not moved: the
  // slices then read memory that stays mapped, and the solver's buffers go back to the heap.
  deformed_ = solved.deformed;
  posedCage_ = solved.cage;
  handles_ = std::move(solved.handles);
  prediction_.reset();
  const TransferMesh& mesh = rig_->mesh();
  lo_ = mesh.vertices.colwise().minCoeff().transpose().cwiseMin(
      deformed_.colwise().minCoeff().transpose());
  hi_ = mesh.vertices.colwise().maxCoeff().transpose().cwiseMax(
      deformed_.colwise().maxCoeff().transpose());
  frameMs_ = msSince(start);
}

Eigen::Vector3d LiveSession::restCentre() const {
  const Eigen::MatrixX3d& v = rig_->mesh().vertices;
  return (v.colwise().minCoeff() + v.colwise().maxCoeff()).transpose() / 2;
}

std::vector<LiveSession::Slice> LiveSession::slices(
    const std::vector<SliceRequest>& requests) const {
  std::vector<Slice> out(requests.size());
  if (!hasFrame()) return out;
  RasterOptions options;
  options.outerFaces = &outerFaces_;
  for (std::size_t r = 0; r < requests.size(); ++r) {
    const SliceRequest& q = requests[r];
    const Volume* source = q.layer == Layer::Labels  ? inputs_.labels.get()
                           : q.layer == Layer::Parts ? parts_.get()
                                                     : inputs_.image.get();
    if (!source || q.pixels < 2) continue;
    const auto start = Clock::now();
    const VolumeGeometry grid = liveSliceGrid(lo_, hi_, q.orientation, q.positionMm, q.pixels);
    out[r].voxels =
        q.layer == Layer::Image
            ? rasterizeImage(*source, rig_->mesh(), deformed_, grid, imageBackground_, options)
            : rasterizeLabels(*source, rig_->mesh(), deformed_, grid, options);
    out[r].milliseconds = msSince(start);
  }
  return out;
}

std::optional<LiveSession::ImageWindow> LiveSession::imageWindow() const {
  return window_;
}

std::string LiveSession::partName(int value) const {
  return nameIn(inputs_.partLabels, value);
}

const LivePrediction& LiveSession::prediction() const {
  if (prediction_) return *prediction_;
  prediction_ = predictionJob()(nullptr);
  return *prediction_;
}

LiveSession::PredictionJob LiveSession::predictionJob() const {
  if (!hasFrame()) throw Error("no live frame to predict from");
  // By value: the frame, the handles, the part names; the rig by a share of it.
  return [rig = rig_, restored = deformed_, handles = handles_, names = inputs_.partLabels](
             const std::atomic<bool>* cancel) mutable -> std::optional<LivePrediction> {
    const VolumeRestorationReport r = rig->restoreFrameVolumes(restored, handles, cancel);
    if (r.cancelled || (cancel && cancel->load())) return std::nullopt;
    const VolumePrediction p = predictVolumeChange(rig->mesh(), restored);
    LivePrediction out;
    out.bodyChangePercent = p.changePercent();
    auto name = [&](int part) { return part == 0 ? std::string() : nameIn(names, part); };
    out.worstPart = name(p.worstPart);
    out.draggedBy = name(p.draggedBy);
    for (const PartVolumeChange& c : p.parts)
      if (c.part == p.worstPart) out.worstPartChangePercent = c.changePercent();
    // The part furthest from its volume in percent, against the per-part target.
    const PartVolumeChange* furthest = nullptr;
    for (const PartVolumeChange& c : p.parts)
      if (c.restMm3 > 0 &&
          (!furthest || std::fabs(c.changePercent()) > std::fabs(furthest->changePercent())))
        furthest = &c;
    char text[160];
    if (std::fabs(out.bodyChangePercent) > kBodyTargetPercent) {
      std::snprintf(text, sizeof text, "body %+.2f %% (target within 0.5 %%)",
                    out.bodyChangePercent);
      out.missed = text;
    }
    if (furthest && std::fabs(furthest->changePercent()) > kLabelTargetPercent) {
      std::snprintf(text, sizeof text, "%s %+.2f %% (target within 1 %%)",
                    name(furthest->part).c_str(), furthest->changePercent());
      out.missed += (out.missed.empty() ? "" : "; ") + std::string(text);
      out.worstPart = name(furthest->part);
      out.worstPartChangePercent = furthest->changePercent();
    }
    out.met = out.missed.empty();
    return out;
  };
}

std::vector<LiveJoint> LiveSession::joints() const {
  std::vector<LiveJoint> out;
  if (!inputs_.skeleton || !hasFrame()) return out;
  const TransferMesh& mesh = rig_->mesh();
  const Eigen::MatrixX3d centres = movePoints(mesh, deformed_, jointAnchors_, jointCentres_);
  const std::vector<SkeletonJoint>& joints = inputs_.skeleton->joints;
  for (std::size_t j = 0; j < joints.size(); ++j) {
    LiveJoint joint;
    joint.name = joints[j].name;
    joint.centre = centres.row(Eigen::Index(j)).transpose();
    // An axis turns with the tissue around the joint's centre (its tet's gradient).
    const int tet = jointAnchors_[j].tet;
    const Eigen::Matrix3d F =
        tet >= 0 ? tetDeformationGradient(mesh, deformed_, tet) : Eigen::Matrix3d::Identity();
    for (const auto& [axisName, axis] : joints[j].axes) {
      const Eigen::Vector3d a = F * axis;
      joint.axes.emplace_back(axisName, a.norm() > 1e-12 ? Eigen::Vector3d(a.normalized()) : axis);
    }
    out.push_back(std::move(joint));
  }
  return out;
}

std::vector<int> LiveSession::groupVertices(const std::string& group) const {
  const Pose& pose = rig_->pose();
  for (std::size_t g = 0; g < pose.groups.size(); ++g)
    if (pose.groups[g].name == group) return rig_->handles().at(g).cageVertices;
  return {};
}

std::vector<int> LiveSession::cageVerticesOfPart(int label) const {
  if (label <= 0) return {};
  // As a group selecting the part would: resolved by the same function as a pose file's.
  Pose probe;
  PoseGroup group;
  group.name = "part";
  group.select.parts = {label};
  probe.groups.push_back(group);
  try {
    return resolveHandles(probe, rig_->cage(), rig_->mesh(), inputs_.partLabels)
        .front()
        .cageVertices;
  } catch (const Error&) {
    return {};  // a part too small to reach the cage
  }
}

int LiveSession::restLabelAt(const Eigen::Vector3d& ras) const {
  const Volume& G = *inputs_.labels;
  const Eigen::Vector3d ijk = G.geometry().rasToVoxel(ras);
  std::int64_t at[3];
  for (int k = 0; k < 3; ++k) {
    if (!std::isfinite(ijk[k])) return -1;
    at[k] = std::llround(ijk[k]);
    if (at[k] < 0 || at[k] >= G.dims()[std::size_t(k)]) return -1;
  }
  return int(G.valueAsDouble(G.index(at[0], at[1], at[2])));
}

}  // namespace repose
