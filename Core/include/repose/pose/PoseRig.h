// A body rigged for posing: cage and transfer mesh (built once, with the separations a pose
// needs), embedded, with a pose's handle groups resolved and their influence computed; then any
// frame of the pose is a few solves. What `repose pose`, the module's Logic and the Python
// bindings share.
#pragma once

#include "repose/cage/CageBuilder.h"
#include "repose/mesh/RigiditySolver.h"
#include "repose/pose/Pose.h"
#include "repose/util/Progress.h"
#include "repose/volume/Volume.h"

#include <memory>

namespace repose {

struct RigSettings {
  int cageVertices = 300;
  double dilateMm = 10;
  double meshMm = 0;  // transfer-mesh tet size; 0: 5% of S's diagonal
  int threads = 0;
};

struct RigGeometry {
  TriangleMesh cage;
  TransferMesh mesh;
};

// Cage and transfer mesh of S, separated where asked. Progress: cage 0-0.5, mesh 0.5-1.
RigGeometry buildRigGeometry(const Volume& parts, const std::vector<LimbSeparation>& separations,
                             const RigSettings& settings, const ProgressFn& progress = {});

class PoseRig {
 public:
  // Embeds the mesh in the cage and resolves the pose's groups (part names through partLabels).
  // jointRings: the widening of the joints (computeHandleInfluence); -1 takes the pose's own.
  PoseRig(RigGeometry geometry, const Pose& pose, const LabelTable& partLabels, int threads = 0,
          int jointRings = -1);
  ~PoseRig();

  struct Frame {
    std::string name;
    std::vector<RigidHandle> handles;      // with this frame's motions
    Eigen::MatrixX3d cage;                 // posed cage vertices
    Eigen::MatrixX3d deformed;             // posed TM vertices
    std::vector<Eigen::Matrix3d> tetMaps;  // B_t of every tet
  };
  std::size_t frameCount() const { return frames_.size(); }
  const std::string& frameName(std::size_t index) const { return frames_.at(index).first; }
  Frame frame(std::size_t index, GreenPrecision precision = GreenPrecision::Exact) const;

  const TriangleMesh& cage() const { return geometry_.cage; }
  const TransferMesh& mesh() const { return geometry_.mesh; }
  const CageDeformation& deformation() const { return *deformation_; }
  const std::vector<RigidHandle>& handles() const { return handles_; }
  const HandleInfluence& influence() const { return influence_; }
  const Pose& pose() const { return pose_; }

 private:
  RigGeometry geometry_;
  Pose pose_;
  std::unique_ptr<CageDeformation> deformation_;
  std::vector<RigidHandle> handles_;
  HandleInfluence influence_;
  std::vector<std::pair<std::string, std::vector<Eigen::Isometry3d>>> frames_;
};

}  // namespace repose
