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
#include "repose/skeleton/Skeleton.h"
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

// A further turn of a transform about the same pivot (PoseTransform::then).
struct PoseTurn {
  Eigen::Vector3d axis = Eigen::Vector3d::UnitX();  // unit length
  double angleDeg = 0;
  std::string axisName;  // a joint's axis by name ("shoulder_left.abduction") until resolved
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
  // More turns about the same pivot ("then" in the pose file), each applied after the one before
  // it, about its axis as given (the rest body's axes, not turned by the earlier turns): a joint
  // moved about several of its axes at once, flexion then abduction then rotation.
  std::vector<PoseTurn> then;
  bool namesJoints() const;
  Eigen::Isometry3d isometry() const;
};

struct PoseGroup {
  std::string name;
  PoseSelection select;
  bool fixed = false;       // stays in place (its transform is the identity)
  PoseTransform transform;  // the pose's transform when there are no keyframes
  // The group this one is carried by, "" for none: its motion is this group's own transform
  // followed by that group's motion (a chain of joints: the forearm turns at the elbow and goes
  // where the shoulder takes the upper arm). No cycles; a fixed group follows nothing.
  std::string follows;
  // Rings its transitions are widened by beyond the pose's joint_rings (not in pose files: the
  // rhythms' groups, whose parts meet the trunk all around, set it).
  int widen = 0;
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
  // The rhythms a body follows when the skeleton has their joints (pose/PoseRhythm.h): the
  // shoulder girdle turning with an arm raised beyond 90 degrees, the pelvis tilting back with a
  // hip flexed beyond 60. A pose file's "rhythms" switches either off.
  bool scapulohumeralRhythm = true, lumbopelvicRhythm = true;
  std::vector<PoseSeparation> separations;
  std::vector<PoseGroup> groups;
  std::vector<PoseKeyframe> keyframes;
  // One frame per keyframe (groups it does not name keep their base transform), or the base;
  // each group's motion composed along its chain of `follows`. Throws repose::Error when a
  // transform still names a joint (resolvePoseJoints first), or for a group that follows an
  // unknown group or itself round a cycle.
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
// The inverse of resolving for joint groups: every group named "<joint>.<axis>" or "<joint>" of
// the skeleton gets its pivot back as the joint's name and each turn's axis as the name of the
// joint's axis it equals (in its base transform and keyframes), so the pose file written poses
// any rigged body.
void nameJointGroups(Pose& pose, const Skeleton& skeleton);

// Posing a limb by its joints, several at once. Adds (or keeps) the group named `joint` that
// turns the joint about every axis of the skeleton's joint (a turn per axis in jointTurnAxes'
// order, "then" after the first; angles 0 for a new group) and fits it into the chain of joint
// groups already in the pose:
// - it selects the joint's distal parts (jointDistalParts) except those of joint groups below
//   it, which then follow it;
// - a joint group above it gives up those parts, and the new group follows it;
// - any other group selecting one of those parts (by name or, through `partLabels`, by label)
//   gives way, with its keyframe entries; a fixed "rest" group keeps the rest of the body.
// Joint groups are those named after a joint of the skeleton ("elbow_left") or one of its axes
// ("elbow_left.flexion", the single-axis form). Returns the group's name. Throws repose::Error
// as jointGroup does.
std::string setJointGroup(Pose& pose, const Skeleton& skeleton, const std::string& joint,
                          const LabelTable& partLabels);
// The order a joint group's turns take (setJointGroup), whatever order skeleton.json lists the
// axes in: the limb's own rotation first, then abduction (the neck's lateral bend), then flexion,
// each about its axis at rest. Composed so, the motion is the joint coordinate system's of
// Grood & Suntay and the ISB: flexion about the proximal segment's axis, abduction about the
// floating axis, rotation about the distal segment's own axis.
std::vector<std::string> jointTurnAxes(const SkeletonJoint& joint);
// The joint a group of the pose turns (by its name, either form), "" when it is no joint group.
std::string jointOfGroup(const Skeleton& skeleton, const std::string& group);

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
