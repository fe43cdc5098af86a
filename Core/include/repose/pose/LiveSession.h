// A live session: one body's rig prepared once for interaction, then one frame per change of the
// pose (warm-started from the last, at preview precision) and the slices a workbench's views ask
// for, in one call. What the workbench's Logic drives while a user drags the cage; a script
// drives it the same way (Python's repose.LiveSession, docs/PYTHON.md). It holds parsed poses only:
// an edit hands it a Pose, never text.
//
// Preparing (the constructor: Green coordinates, the factorizations, the joints' anchors) is the
// long step, for a worker thread. setPose and the queries are for one thread at a time.
#pragma once

#include "repose/mesh/PointAnchors.h"
#include "repose/pose/Pose.h"
#include "repose/pose/PoseJob.h"
#include "repose/pose/PoseRig.h"
#include "repose/raster/Rasterizer.h"
#include "repose/skeleton/Skeleton.h"
#include "repose/util/Progress.h"
#include "repose/volume/Volume.h"

#include <Eigen/Core>

#include <atomic>
#include <cstdint>
#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <vector>

namespace repose {

// What a session poses and shows, besides the job's rig.
struct LiveInputs {
  std::shared_ptr<const Volume> labels;  // G, at rest (required)
  std::shared_ptr<const Volume> image;   // the body's image (CT, MR), if any
  LabelTable partLabels;                 // S's, for groups selecting parts and part names
  std::optional<Skeleton> skeleton;      // the joints drawn where the frame puts them
};

// What the live frame predicts of the export's volumes: the frame restored as the export
// restores it (PoseRig::restoreFrameVolumes), then predictVolumeChange over every tet.
struct LivePrediction {
  double bodyChangePercent = 0;
  std::string worstPart, draggedBy;  // names of S ("" when nothing changes)
  double worstPartChangePercent = 0;
  bool met = true;     // body within kBodyTargetPercent, each part within kLabelTargetPercent
  std::string missed;  // one line, "" when met
};

struct LiveJoint {
  std::string name;
  Eigen::Vector3d centre;                                     // RAS mm, posed
  std::vector<std::pair<std::string, Eigen::Vector3d>> axes;  // unit, posed
};

class LiveSession {
 public:
  // The rig of `geometry` for the job's user pose (the joints bent as the export bends them).
  // The job is only read here. Throws repose::Error as PoseJob::makeRig does.
  LiveSession(const PoseJob& job, RigGeometry geometry, LiveInputs inputs,
              const ProgressFn& progress = {});
  ~LiveSession();
  LiveSession(const LiveSession&) = delete;
  LiveSession& operator=(const LiveSession&) = delete;

  // Whether this session solves frames of `pose`: the same handle groups as the pose it was
  // prepared for (else a new session must be prepared, e.g. after a group was added).
  bool solves(const Pose& pose) const;
  // The frame of keyframe `frame` of `pose` (clamped to its keyframes), warm-started from the
  // last. Throws repose::Error for a pose this session does not solve; the last frame stays.
  void setPose(const Pose& pose, std::size_t frame);
  bool hasFrame() const { return deformed_.rows() > 0; }
  double frameMilliseconds() const { return frameMs_; }

  const PoseRig& rig() const { return *rig_; }
  const Eigen::MatrixX3d& deformed() const { return deformed_; }  // the frame's TM vertices
  const Eigen::MatrixX3d& posedCage() const { return posedCage_; }
  // Per tet, its faces on the body's surface (outerFaces): what a view draws of the body.
  const std::vector<std::uint8_t>& outerFaces() const { return outerFaces_; }
  // The rest and posed body together (RAS mm), where the views place their slices.
  const Eigen::Vector3d& lo() const { return lo_; }
  const Eigen::Vector3d& hi() const { return hi_; }
  Eigen::Vector3d restCentre() const;

  // Slices of the frame. Layer: G's labels; S's (or whatever map setParts gave); the image.
  enum class Layer { Labels, Parts, Image };
  struct SliceRequest {
    Layer layer = Layer::Labels;
    SliceOrientation orientation = SliceOrientation::Axial;
    double positionMm = 0;
    int pixels = 256;  // across the box's larger in-plane side; the other side as the box needs
  };
  struct Slice {
    std::optional<Volume> voxels;  // none without a frame, or for a layer the session lacks
    double milliseconds = 0;
  };
  // Every slice the views show, in one call, each equal to that plane of the exported map.
  std::vector<Slice> slices(const std::vector<SliceRequest>& requests) const;
  // The map the Parts layer shows (S, or G's body mask): given when first needed, so a session
  // whose outlines are never shown holds no copy of it.
  void setParts(std::shared_ptr<const Volume> parts) { parts_ = std::move(parts); }
  bool hasParts() const { return parts_ != nullptr; }
  const Volume& labels() const { return *inputs_.labels; }
  const Volume* image() const { return inputs_.image.get(); }
  // A grey window for the image: CT's soft-tissue window (W 400, L 40) for Hounsfield units,
  // else the 1st..99th percentile of a sample of its voxels. Background: imageBackground.
  struct ImageWindow {
    double window = 0, level = 0;
  };
  std::optional<ImageWindow> imageWindow() const;

  // Computed once per frame, when asked (the restoration and a pass over every tet).
  const LivePrediction& prediction() const;
  // The same prediction as a job for another thread, so a workbench's event loop never waits on
  // it (a few hundred milliseconds on a whole body): it holds a copy of the frame at hand and a
  // share of the rig, so the session may solve further frames, or be dropped, while it runs.
  // Setting `cancel` stops it at its next round (a new drag made it stale): it then returns
  // nothing.
  using PredictionJob = std::function<std::optional<LivePrediction>(const std::atomic<bool>*)>;
  PredictionJob predictionJob() const;
  // The skeleton's joints where the frame puts them: centres anchored once in the rest mesh,
  // axes turned by the deformation gradient of the tissue there. Empty without a skeleton.
  std::vector<LiveJoint> joints() const;
  // The cage vertices group `group` of the prepared pose moves (empty for an unknown one), and
  // those a group selecting body part `label` of S would move (empty for a part too small).
  std::vector<int> groupVertices(const std::string& group) const;
  std::vector<int> cageVerticesOfPart(int label) const;
  const LabelTable& partLabels() const { return inputs_.partLabels; }
  std::string partName(int value) const;  // S's name, else the number
  // G's label at rest at a RAS point (the nearest voxel); -1 outside its grid.
  int restLabelAt(const Eigen::Vector3d& ras) const;

 private:
  void anchorJointsInProximalBones(const std::vector<SkeletonJoint>& joints);

  LiveInputs inputs_;
  std::shared_ptr<const Volume> parts_;
  std::shared_ptr<const PoseRig> rig_;  // shared with prediction jobs still running
  std::vector<std::uint8_t> outerFaces_;
  Eigen::MatrixX3d deformed_, posedCage_;
  std::vector<RigidHandle> handles_;  // the frame's groups with their motions
  Eigen::Vector3d lo_ = Eigen::Vector3d::Zero(), hi_ = Eigen::Vector3d::Zero();
  double frameMs_ = 0;
  double imageBackground_ = 0;
  std::optional<ImageWindow> window_;
  Eigen::MatrixX3d jointCentres_;  // rest, one row per joint
  std::vector<PointAnchor> jointAnchors_;
  mutable std::optional<LivePrediction> prediction_;
};

}  // namespace repose
