// A joint bent as soft tissue bends: without overlap, without losing volume.
//
// The rigid handle groups meet at a joint, where their motions are blended vertex by vertex
// (RigidHandles.h). A blend of two rigid motions cannot both keep volume and avoid overlap: at a
// 90-degree elbow the inner side either shrinks (blended tets) or folds over itself (the two
// sides' rigid images overlap by about a quarter of a Steinmetz solid of the limb's radius), and
// a thin vessel crossing the crease loses several percent of its volume.
//
// Where the relative motion of the two parts is a turn by theta about an axis a through the joint
// centre c (every pose of the standard suite; pose files turn groups about their joints), the
// tissue near the joint takes an analytic bend instead. In cylindrical coordinates about the axis
// line (rho, phi, z), phi measured from the distal segment's direction: phi' = phi + theta s(phi)
// with s = 1 along the distal part, 0 along the proximal, a smooth ramp across the joint plane
// wide enough that phi' stays monotonic (no overlap), and rho' = rho / sqrt(dphi'/dphi) so that
// areas in each plane, and so volumes, are kept: the inner side of the bend bulges out and the
// outer side thins, as flesh does. The proximal part's motion is applied on top.
#pragma once

#include "repose/mesh/RigidHandles.h"
#include "repose/mesh/TransferMesh.h"

#include <Eigen/Core>

#include <string>
#include <vector>

namespace repose {

struct BendJoint {
  std::string name;
  Eigen::Vector3d centre = Eigen::Vector3d::Zero();
  Eigen::Vector3d distal = Eigen::Vector3d::UnitZ();  // the distal segment's direction at rest
  int proximalPart = 0, distalPart = 0;               // labels of S (the TM's tet labels)
  // More parts on the proximal side, bent with it where the same group carries them (the torso
  // beside a shoulder whose girdle is a part of its own: the armpit).
  std::vector<int> proximalAlso;
  double radiusMm = 0;  // where the two parts meet across the joint (Skeleton's radius_mm)
  // How far from the centre the bend reaches (beyond, each part follows its group's motion), in
  // radii, on the proximal and the distal side; in between it follows the share of the turn, so
  // the two sides agree at the joint plane. The pose job's joints (PoseJob.cpp, bendJoints): a
  // limb's joint (elbow, wrist, knee, ankle) 2 radii each side; a root joint (shoulder, hip)
  // 1.5 on the limb's side and only near the joint on the trunk's, so the chest wall and the
  // pelvis stay put.
  double proximalReach = 1.5, distalReach = 1.5;
};

struct JointBendReport {
  int joints = 0;    // joints bent in this frame
  int vertices = 0;  // vertices placed by a bend
};

class JointBends {
 public:
  JointBends() = default;
  // Finds, per joint, the groups carrying its two parts and the soft-tissue vertices of those
  // parts within its reach of its centre (never a whole piece's).
  JointBends(const TransferMesh& mesh, const std::vector<RigidHandle>& handles,
             const std::vector<BendJoint>& joints);
  bool empty() const { return joints_.empty(); }

  // Moves the joints' vertices of `deformed` (the frame solved with blended motions) to their
  // bend, for each joint whose relative motion is a turn about an axis through its centre (a
  // screw with neither slide nor offset beyond 2% of its radius); other joints keep the blend.
  JointBendReport apply(const TransferMesh& mesh, const std::vector<RigidHandle>& frame,
                        Eigen::MatrixX3d& deformed) const;
  // The vertices `apply` bends in this frame (of the joints that turn), marked 1 among
  // `vertexCount`.
  std::vector<char> zone(const std::vector<RigidHandle>& frame, Eigen::Index vertexCount) const;
  // The tets whose centre lies within the reach of a joint that turns in this frame, whatever
  // their vertices (the soft tissue between two bone ends, every vertex on a bone, among them).
  std::vector<char> reachTets(const TransferMesh& mesh,
                              const std::vector<RigidHandle>& frame) const;

 private:
  struct Joint {
    BendJoint joint;
    int proximalGroup = -1, distalGroup = -1;
    std::vector<int> vertices;
  };
  // Whether the joint turns about its centre in this frame (what apply bends), and the turn.
  bool turns(const Joint& j, const std::vector<RigidHandle>& frame) const;
  std::vector<Joint> joints_;
};

// The bend of one rest point, relative to the proximal part (apply the proximal group's motion
// after): the turn `angle` (radians) about `axis` through `centre`, shared by angle from
// `distal`. Public for tests.
// `share` (optional) receives the point's share of the turn, s(phi).
Eigen::Vector3d bendPoint(const Eigen::Vector3d& p, const Eigen::Vector3d& centre,
                          const Eigen::Vector3d& axis, const Eigen::Vector3d& distal, double angle,
                          double* share = nullptr);

}  // namespace repose
