// Pose files (`*.pose.json`, docs/POSES.md, docs/pose.schema.json): named handle groups of the
// cage, each selected by cage vertex indices, a region in RAS mm, body parts of S or "the rest",
// each with a rigid transform (rotation about an axis through a pivot, then a translation) or
// fixed; optional keyframes (a sequence of poses); optional limb separations the cage and the
// transfer mesh must make for the pose to be possible (a hand pressed to the hip).
#pragma once

#include "repose/cage/CageBuilder.h"
#include "repose/cage/TriangleMesh.h"
#include "repose/mesh/RigidHandles.h"
#include "repose/mesh/TransferMesh.h"
#include "repose/pose/Skeleton.h"
#include "repose/volume/LabelTable.h"

#include <Eigen/Geometry>
#include <array>
#include <optional>
#include <string>
#include <vector>

namespace repose {

struct PoseSelection {
  std::vector<int> cageVertices;       // by index
  std::optional<Region> region;        // cage vertices inside, in RAS mm
  std::vector<int> parts;              // body-part labels of S
  std::vector<std::string> partNames;  // body-part names of S's label table
  bool rest = false;                   // every cage vertex and part no other group selects
};

struct PoseTransform {
  Eigen::Vector3d axis = Eigen::Vector3d::UnitX();  // unit length
  double angleDeg = 0;
  Eigen::Vector3d pivot = Eigen::Vector3d::Zero();        // RAS mm
  Eigen::Vector3d translation = Eigen::Vector3d::Zero();  // mm, applied after the rotation
  // Named in the pose file instead of numbers: a joint of the body's skeleton ("elbow_left") and
  // one of its axes ("elbow_left.flexion"). resolvePoseJoints turns them into pivot and axis and
  // clears them; until then the transform has no motion (Pose::frames throws).
  std::string pivotJoint, axisName;
  bool namesJoints() const { return !pivotJoint.empty() || !axisName.empty(); }
  Eigen::Isometry3d isometry() const;
};

struct PoseGroup {
  std::string name;
  PoseSelection select;
  bool fixed = false;       // stays in place (its transform is the identity)
  PoseTransform transform;  // the pose's transform when there are no keyframes
};

struct PoseKeyframe {
  std::string name;
  std::vector<std::pair<std::string, PoseTransform>> transforms;  // group name -> transform
};

// Two body parts of S (labels, or names of S's label table) to separate inside a region.
struct PoseSeparation {
  std::array<int, 2> parts{0, 0};        // 0 where a name is given instead
  std::array<std::string, 2> partNames;  // empty where a label is given
  Region region;
};

struct Pose {
  std::string name, description;
  int jointRings = 0;  // widening of the joints' transitions (computeHandleInfluence), 0..8
  std::vector<PoseSeparation> separations;
  std::vector<PoseGroup> groups;
  std::vector<PoseKeyframe> keyframes;
  // One frame per keyframe (groups it does not name keep their base transform), or the base.
  // Throws repose::Error when a transform still names a joint (resolvePoseJoints first).
  std::vector<std::pair<std::string, std::vector<Eigen::Isometry3d>>> frames() const;
};

// Whether any group or keyframe names a joint of the skeleton (pivot or axis).
bool poseNamesJoints(const Pose& pose);
// Replaces every joint name by the skeleton's numbers (pivot: the joint's centre; axis: the
// joint's axis) and clears the names. Throws repose::Error naming the pose, the group and the
// joint or axis the skeleton lacks.
void resolvePoseJoints(Pose& pose, const Skeleton& skeleton);

// Posing by joint. The group that turns `joint` of the skeleton about its named axis: named
// "<joint>.<axis>" (e.g. "elbow_left.flexion"), selecting the body parts distal to the joint (its
// own distal part and those of every joint below it: the forearm and the hand for the elbow), its
// pivot and axis the joint's by name (resolvePoseJoints gives the numbers). Throws repose::Error
// naming the joint or axis the skeleton lacks, or a joint whose distal part is not known.
PoseGroup jointGroup(const Skeleton& skeleton, const std::string& joint, const std::string& axis,
                     double angleDeg);
// The body parts distal to a joint (names of S, proximal first); empty when not known.
std::vector<std::string> jointDistalParts(const Skeleton& skeleton, const std::string& joint);
// The anatomical range of motion of a joint about one of its axes, degrees (a healthy adult's,
// as clinical goniometry tables give them, rounded out), for the workbench's joint sliders:
// e.g. elbow flexion 0..150, shoulder abduction -30..180; -180..180 for an unknown pair.
std::pair<double, double> jointRangeDeg(const std::string& joint, const std::string& axis);
// The inverse of resolving for joint groups: every group named "<joint>.<axis>" of the skeleton
// gets its pivot and axis back as names (in its base transform and keyframes), so the pose file
// written poses any rigged body.
void nameJointGroups(Pose& pose, const Skeleton& skeleton);

// Whether two poses have the same handle groups (names, fixed, selections) in the same order:
// a rig prepared for one solves frames of the other.
bool sameHandleGroups(const Pose& a, const Pose& b);
// Throws repose::Error "<source>: <field>: <problem>" naming the offending field, e.g.
// "elbow.pose.json: groups[0].rotation.angle_deg: expected a number".
Pose parsePose(const std::string& jsonText, const std::string& source);
Pose readPoseFile(const std::string& path);
std::string poseToJson(const Pose& pose);
// A region as the pose file writes it ({"box": [...]}, {"sphere": [...]}, ...), JSON text.
std::string regionToJson(const Region& region);
void writePoseFile(const Pose& pose, const std::string& path);  // atomic

// The pose's groups as rigid handles of this cage and mesh, in group order, with the motions of
// one frame: selections resolved to cage vertices (a part selects the cage vertices whose nearest
// TM surface vertex lies in that part), part names through S's label table. Throws repose::Error
// for an unknown part name, a cage index out of range, a group that selects no cage vertex, or
// a cage vertex selected by two groups.
std::vector<RigidHandle> resolveHandles(const Pose& pose, const TriangleMesh& cage,
                                        const TransferMesh& mesh, const LabelTable& partLabels);
// The separations with part names resolved through S's label table.
std::vector<LimbSeparation> resolveSeparations(const Pose& pose, const LabelTable& partLabels);
void setMotions(std::vector<RigidHandle>& handles, const std::vector<Eigen::Isometry3d>& motions);

// The posed cage: handle vertices moved by their motions, the others (if any) by ARAP.
Eigen::MatrixX3d poseCage(const TriangleMesh& cage, const std::vector<RigidHandle>& handles);

}  // namespace repose
