// A body rigged for posing: cage and transfer mesh (built once, with the separations a pose
// needs), embedded, with a pose's handle groups resolved and their influence computed; then any
// frame of the pose is a few solves. What `repose pose`, the module's Logic and the Python
// bindings share.
#pragma once

#include "repose/cage/CageBuilder.h"
#include "repose/cage/CageLadder.h"
#include "repose/mesh/JointBend.h"
#include "repose/mesh/VolumeRestoration.h"
#include "repose/mesh/Refinement.h"
#include "repose/mesh/RigiditySolver.h"
#include "repose/pose/JointClearance.h"
#include "repose/pose/Pose.h"
#include "repose/pose/PoseRhythm.h"
#include "repose/util/Progress.h"
#include "repose/volume/TissueTable.h"
#include "repose/volume/Volume.h"

#include <map>
#include <memory>

namespace repose {

// A ball of finer tets around a joint a pose bends: the bend happens in the soft tissue there,
// and tets as large as the default (5% of the body's diagonal) cannot bulge as that tissue must
// to keep its volume.
struct JointRefinement {
  Eigen::Vector3d centre = Eigen::Vector3d::Zero();
  double radiusMm = 0;  // tets of sizeMm within this distance, growing to the default at twice it
  double sizeMm = 0;
};

struct RigSettings {
  int cageVertices = 300;
  double dilateMm = 10;
  double meshMm = 0;  // transfer-mesh tet size; 0: 5% of S's diagonal
  int threads = 0;
  // Labels of G that are rigid tissue (bones; TissueTable's rigid column). Meshed as pieces of
  // their own that a pose moves whole with their body part, so they stay rigid at the joints.
  std::vector<int> rigidLabels;
  // Labels of one bone (TissueTable's bone column: a humerus's cortex, spongiosa and marrow) ->
  // the id of the one piece they are meshed as: the bone's smallest label. A bone is one rigid
  // body however many labels segment it; meshed label by label, a one-voxel cortex on thick
  // slices (Mesh_3 follows borders to within the largest spacing) gets no tets of its own and
  // bends with the soft tissue at the joint. Labels not listed are pieces of their own.
  std::map<int, int> bonePieces;
  // Also mesh as whole pieces the labels of G that lie in one body part of S (organs: the
  // bladder beside the hip moves with the pelvis instead of bending with the thigh).
  bool wholeOrgans = true;
  // Finer tets around the joints the pose bends (PoseJob.h: jointRefinements).
  std::vector<JointRefinement> refineJoints;
};

// The sizing field of buildRigGeometry: the default size (meshMm, or 5% of S's diagonal), finer
// in the balls of settings.refineJoints. Uniform when there are none.
SizingField rigSizingField(const Volume& parts, const RigSettings& settings);

// The share of a label's voxels in one body part above which it is an organ of that part, and
// the share of them at most that may face another part (a label reaching a joint bends there).
constexpr double kWholeOrganShare = 0.99;
constexpr double kWholeOrganBorderShare = 0.002;

// The labels of G that buildRigGeometry meshes as whole pieces: settings.rigidLabels, and with
// settings.wholeOrgans every label with kWholeOrganShare of its voxels in one part of S and at
// most kWholeOrganBorderShare of them facing another part, and every soft label encased in the
// rigid labels' bone (labelsEncasedInBone: the spinal cord), in whichever parts it lies.
std::vector<int> labelsMovingWhole(const Volume& organs, const Volume& parts,
                                   const RigSettings& settings);

struct RigGeometry {
  TriangleMesh cage;
  TransferMesh mesh;
  // The Green coordinates saved with them (a scene's tm.green; CageDeformation); "" when none.
  // Used only if written for this very cage and mesh, else computed again.
  std::string coordinatesFile;
  // The cage's setting: asked, used (the ladder's first that passed its checks) and tried.
  CageChoice cageChoice;
};

// settings.bonePieces for a tissue table: each bone's rigid labels -> the bone's smallest label.
std::map<int, int> bonePiecesOf(const TissueTable& table);

// The map buildRigGeometry meshes the pieces from (TransferMeshOptions::rigidTissue): on S's grid,
// the piece of G's label (settings.bonePieces, else the label) where it is one of the
// labelsMovingWhole, else 0, with a seam of 0 where pieces
// of different body parts touch (a joint). An empty Volume when no label moves whole.
Volume wholePieceMap(const Volume& organs, const Volume& parts, const RigSettings& settings);

// Where pieces of two body parts share a vertex (a bone end meshed onto its neighbour across a
// joint, closer than the seam), the part with more piece volume around the vertex keeps it and
// the other parts' piece tets at it become soft tissue, so that pieces of different parts never
// share a vertex and each moves exactly with its group. A joint space thinner than a tet gets a
// free layer: a soft tet with all four vertices on two parts' pieces, or a soft vertex pressed
// between facing faces of two parts' pieces, makes one part's piece tets at those vertices soft.
// Idempotent: a second call returns 0. Returns how many tets went soft.
int demotePiecesAcrossJoints(TransferMesh& mesh);

// Cage and transfer mesh of S, separated where asked; with G (organs, on S's grid) the mesh has
// the labelsMovingWhole as pieces of their own. The cage is the first of the ladder from the
// settings' size that passes its checks (buildCageTrying). Progress: cage 0-0.5, mesh 0.5-1.
RigGeometry buildRigGeometry(const Volume& parts, const std::vector<LimbSeparation>& separations,
                             const RigSettings& settings, const ProgressFn& progress = {},
                             const Volume* organs = nullptr);

// The transfer mesh of buildRigGeometry (whole pieces, separations) refined for one posed cage
// by the motion-adaptive loop (seed §4.2, refineTransferMesh): smaller tets where the Green
// deformation distorts most, for `iterations` rounds of mesh, measure, shrink. `steps` (optional)
// receives the error of each round's mesh.
TransferMesh refineRigMesh(const Volume& parts, const TriangleMesh& cage,
                           const Eigen::MatrixX3d& posedCage,
                           const std::vector<LimbSeparation>& separations,
                           const RigSettings& settings, int iterations,
                           const ProgressFn& progress = {}, const Volume* organs = nullptr,
                           std::vector<RefinementStep>* steps = nullptr);

// A joint of the body's skeleton as the report names it: where the tets turned inside out are
// counted (PoseRig::invertedTetsByJoint).
struct JointSite {
  std::string name;
  Eigen::Vector3d centre = Eigen::Vector3d::Zero();
};

// Whether a frame computes every tet's linear map B_t (exports and reports need them; the live
// view shows positions only, and skipping them spares most of a frame's time at 200K tets).
enum class FrameMaps { With, Without };

class PoseRig {
 public:
  // Embeds the mesh in the cage and resolves the pose's groups (part names through partLabels).
  // jointRings: the widening of the joints (computeHandleInfluence); -1 takes the pose's own.
  // bends: the body's joints (Skeleton), where a turn about the joint bends the soft tissue
  // without overlap or loss of volume (JointBend.h) instead of blending the two motions.
  PoseRig(RigGeometry geometry, const Pose& pose, const LabelTable& partLabels, int threads = 0,
          int jointRings = -1, const std::vector<BendJoint>& bends = {});
  ~PoseRig();

  struct Frame {
    std::string name;
    std::vector<RigidHandle> handles;      // with this frame's motions
    Eigen::MatrixX3d cage;                 // posed cage vertices
    Eigen::MatrixX3d deformed;             // posed TM vertices
    std::vector<Eigen::Matrix3d> tetMaps;  // B_t of every tet (empty with FrameMaps::Without)
    // What the volume restoration did (nothing in a live frame, or when it is off).
    VolumeRestorationReport restoration;
    // Groups moved off joints whose bones the turn drove together (JointClearance.h).
    std::vector<JointClearance::Shift> clearances;
  };
  std::size_t frameCount() const { return frames_.size(); }
  const std::string& frameName(std::size_t index) const { return frames_.at(index).first; }
  Frame frame(std::size_t index, GreenPrecision precision = GreenPrecision::Exact,
              FrameMaps tetMaps = FrameMaps::With) const;
  // A frame of an edited copy of the pose (the same groups, other transforms or keyframes): what
  // an interactive edit re-solves. Throws repose::Error when the groups differ or the index is out
  // of range.
  Frame frame(const Pose& edited, std::size_t index,
              GreenPrecision precision = GreenPrecision::Exact,
              FrameMaps tetMaps = FrameMaps::With) const;

  // The frame the live view shows after each edit of a drag: preview Green coordinates, no tet
  // maps, and the cage's free vertices (those no group holds) moved by at most
  // kLiveCageIterations ARAP local/global iterations started from the previous live frame's
  // cage, instead of a solve to convergence from rest (the first live frame solves from rest).
  // Consecutive edits differ little, so the cage converges over the events of a drag and stays
  // within a small fraction of a millimetre of the converged one (PoseRigTest). frame() never
  // depends on what was solved before it; liveFrame() continues from the last liveFrame()
  // (thread-safe).
  Frame liveFrame(const Pose& edited, std::size_t index) const;
  static constexpr int kLiveCageIterations = 3;
  // A live edit that moves a group's cage vertex further than this fraction of the cage's
  // diagonal (100 mm on a 2 m body) is a jump, not a step of a drag: its cage is solved from rest.
  static constexpr double kLiveCageStep = 0.05;
  // ARAP iterations the last cage solve took (0 when every cage vertex is in a group).
  int lastCageIterations() const;

  const TriangleMesh& cage() const { return geometry_.cage; }
  const TransferMesh& mesh() const { return geometry_.mesh; }
  // The cage's setting, asked and used (CageLadder.h).
  const CageChoice& cageChoice() const { return geometry_.cageChoice; }
  const CageDeformation& deformation() const { return *deformation_; }
  const std::vector<RigidHandle>& handles() const { return handles_; }
  const HandleInfluence& influence() const { return influence_; }
  // The pose the rig solves: with the rhythms' groups, when the rig was given rhythms.
  const Pose& pose() const { return pose_; }
  // The pose as its user wrote it (without the rhythms' groups): edits of it are what
  // frame(edited) and liveFrame take, and what a scene folder keeps.
  const Pose& userPose() const { return userPose_; }
  // The rhythms `pose` was given (PoseJob::makeRig): edits of the user's pose get them too.
  void setRhythms(const Pose& userPose, PoseRhythms rhythms) {
    userPose_ = userPose;
    rhythms_ = std::move(rhythms);
  }
  // Whether frame() restores the soft tissue's volumes after the solve and the bends
  // (VolumeRestoration.h; on by default). Live frames never do: they are previews.
  void setVolumeRestoration(bool on) { restoreVolumes_ = on; }
  // Parts the bones each frame drives together at a joint (JointClearance.h), in every frame
  // solved from now on: made by PoseJob from G and S at rest.
  void setJointClearance(JointClearance clearance) { clearance_ = std::move(clearance); }
  const JointClearance& jointClearance() const { return clearance_; }
  // The tissues of G each soft tet holds at rest (restTetTissues): with them the restoration holds
  // each tissue's volume at the joints as well as each body part's. Without, parts only.
  void setTetTissues(TetTissues tissues) { tissues_ = std::move(tissues); }
  // The pairs of body parts (labels of S) a joint of the skeleton connects: where two groups
  // carrying such a pair blend their motions (the girdle on the trunk, the pelvis under it), the
  // restoration relaxes the transition as it does a bend. Elsewhere a blend is a tether.
  void setJointedParts(std::vector<std::pair<int, int>> pairs) { jointedParts_ = std::move(pairs); }
  bool volumeRestoration() const { return restoreVolumes_; }
  // The skeleton's joints (PoseJob::makeRig): invertedTetsByJoint names them.
  void setJointSites(std::vector<JointSite> sites) { jointSites_ = std::move(sites); }
  // The tets turned inside out at `deformed` (posed volume <= 0), each counted at the joint
  // nearest its rest centroid: (joint, tets) for the joints with any, in the skeleton's order;
  // ("", tets) when the rig has no joints.
  std::vector<std::pair<std::string, int>> invertedTetsByJoint(
      const Eigen::MatrixX3d& deformed) const;
  // The restoration frame() applies, on posed vertices of this rig's mesh solved elsewhere (a
  // live frame, to predict what its export will measure) with the frame's handles (their
  // motions say which joints bend). It acts in the joints' bends only, the soft tissue the bends
  // place and one ring of tets around them: tissue dragged along elsewhere (two parts tied along
  // a contact no cut freed) keeps the volume change that says so. Nothing when it is off.
  // `cancel`: VolumeRestorationOptions::cancel.
  VolumeRestorationReport restoreFrameVolumes(Eigen::MatrixX3d& deformed,
                                              const std::vector<RigidHandle>& handles,
                                              const std::atomic<bool>* cancel = nullptr) const;

 private:
  enum class CageStart { Rest, LastLiveFrame };
  Frame solveFrame(const std::string& name, const std::vector<Eigen::Isometry3d>& motions,
                   GreenPrecision precision, FrameMaps tetMaps,
                   CageStart start = CageStart::Rest) const;
  Frame solveEdited(const Pose& edited, std::size_t index, GreenPrecision precision,
                    FrameMaps tetMaps, CageStart start) const;
  Eigen::MatrixX3d posedCage(const std::vector<RigidHandle>& handles, CageStart start) const;
  // The ARAP of the free cage vertices, factorized once for the groups' vertices (null when the
  // groups hold every cage vertex), and the live frames' last cage.
  struct CageArap;
  std::unique_ptr<CageArap> arap_;
  RigGeometry geometry_;
  Pose pose_, userPose_;
  PoseRhythms rhythms_;
  std::unique_ptr<CageDeformation> deformation_;
  std::vector<RigidHandle> handles_;
  HandleInfluence influence_;
  JointBends bends_;
  JointClearance clearance_;
  std::vector<char> movable_;  // per TM vertex: not a whole piece's
  // The transfer mesh's surface, for the restoration's folds (SelfContact.h).
  std::unique_ptr<SelfContactFinder> contacts_;
  bool restoreVolumes_ = true;
  TetTissues tissues_;
  std::vector<std::pair<int, int>> jointedParts_;
  std::vector<JointSite> jointSites_;
  std::vector<std::pair<std::string, std::vector<Eigen::Isometry3d>>> frames_;
};

}  // namespace repose
