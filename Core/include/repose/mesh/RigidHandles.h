// Tissue enclosed by a rigidly moved handle group moves with that group exactly.
//
// Green coordinates are not interior-local: a point of the forearm also "sees" the torso's cage
// faces a few centimetres away across the gap beside the hip, so when only the forearm's cage
// vertices turn about the elbow the forearm follows only part of the way, the wrist lags by
// 2–4 cm and the bones bend (bench/forearm_bench.cpp measures it). Handle groups of a pose are
// moved rigidly (pose files and the GUI's widgets give a rotation and a translation), so the
// motion intended for the tissue a group encloses is known.
//
// Which tissue that is is decided through the body, not through space. A group that names body
// parts (labels of S, which the TM's tets carry) owns exactly their tissue: a vertex's membership
// is the share of its surrounding tet volume in those parts, so the transition sits on the part
// boundary (the joint). A group of cage vertices only: each TM surface vertex takes the group
// membership of the nearest point of the rest cage (barycentric over that face's vertices), and
// the membership is extended harmonically into the TM (graph Laplacian over its edges), so the
// body's own connectivity keeps the forearm apart from the hip it nearly touches; the transition
// is then as wide as the cage faces that straddle the group's border. Where a group's membership is
// at least kFull the vertex takes the group's rigid motion; between kNone and kFull its Green
// position blends smoothly into the rigid one; below, Green coordinates alone. The seed's rigidity
// solver then runs on these targets unchanged.
#pragma once

#include "repose/cage/TriangleMesh.h"
#include "repose/mesh/TransferMesh.h"

#include <Eigen/Geometry>
#include <vector>

namespace repose {

struct RigidHandle {
  std::vector<int> cageVertices;  // indices into the cage; a vertex belongs to one group at most
  std::vector<int> parts;         // labels of S the group carries; empty: decided by the cage
  Eigen::Isometry3d motion = Eigen::Isometry3d::Identity();  // rest RAS mm -> posed RAS mm
  // Rings its transitions are widened by beyond everyone's (PoseGroup::widen): a girdle that
  // glides over the trunk spreads its turn over a band of tissue, not one ring of tets.
  int widen = 0;
};

// The group (index into `handles`) that carries body part `part` of S, -1 when none does.
int handleGroupOfPart(const std::vector<RigidHandle>& handles, int part);

// Per TM vertex, computed once per handle set: how much each group carries it, and how much the
// groups' motions (against its Green position) decide where it goes.
struct HandleInfluence {
  static constexpr double kNone = 0.35, kFull = 0.65;
  Eigen::MatrixXd membership;  // #V by #groups, each in [0, 1], each row summing to at most 1
  std::vector<double> weight;  // smoothstep of the row sum: 0 (Green) .. 1 (the groups' motion)
  int rigidVertices() const;   // vertices one group carries alone (membership 1)
  int dominantGroup(Eigen::Index vertex) const;  // the largest membership, -1 if none
};

// The motion of a vertex carried by several groups: the dual-quaternion blend of their motions
// with these weights (normalized). Between a fixed group and one turned about a joint it is the
// turn by the weighted share of the angle about the same joint, so a joint bends instead of
// shrinking as a blend of positions would.
Eigen::Isometry3d blendMotions(const Eigen::Ref<const Eigen::VectorXd>& weights,
                               const std::vector<RigidHandle>& handles);

// Throws repose::Error for a cage index out of range or a cage vertex in two groups.
// jointRings > 0 widens each transition by that many rings of TM vertices on both sides
// (memberships averaged with their edge neighbours): a gentler bend, less of the crease folding
// over itself (docs/QUALITY.md). Then, when the mesh has whole pieces (TransferMesh::rigid), each
// piece goes to the group carrying most of it, all its vertices with that group alone.
HandleInfluence computeHandleInfluence(const TransferMesh& mesh, const TriangleMesh& cage,
                                       const std::vector<RigidHandle>& handles, int threads = 0,
                                       int jointRings = 0);

// blendMotions for the rows of a HandleInfluence's membership, with the motion of each group
// taken alone computed once: most vertices belong to one group wholly, and their motion is then
// that group's blendMotions (the same value, bit for bit) without a blend per vertex.
class GroupMotions {
 public:
  explicit GroupMotions(const std::vector<RigidHandle>& handles);
  Eigen::Isometry3d of(const Eigen::Ref<const Eigen::RowVectorXd>& membership) const;

 private:
  const std::vector<RigidHandle>& handles_;
  std::vector<Eigen::Isometry3d> alone_;  // blendMotions of e_g
};

// Blend weight of a total membership: 0 below kNone, 1 above kFull, C1-smooth in between.
double handleBlendWeight(double membership);

// The rest cage with each group's vertices moved by its motion (the others stay): the cage a pose
// of rigid groups gives before any free vertex is solved for.
Eigen::MatrixX3d moveHandles(const Eigen::MatrixX3d& restCage,
                             const std::vector<RigidHandle>& handles);

}  // namespace repose
