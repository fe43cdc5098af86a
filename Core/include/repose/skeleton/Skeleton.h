// The body's skeleton: named joints in RAS mm with their anatomical axes, as `repose phantom` and
// `repose rig` write it (skeleton.json beside S, docs/FORMATS.md). Pose files name its joints
// ("pivot": "elbow_left", "axis": "elbow_left.flexion"), so one pose file poses any rigged body;
// automatic contact separation reads which two body parts each joint connects and how far from
// its centre they meet.
#pragma once

#include <Eigen/Core>

#include <array>
#include <string>
#include <utility>
#include <vector>

namespace repose {

struct SkeletonJoint {
  std::string name;                                  // e.g. "elbow_left"
  std::string parent;                                // "" for the root
  Eigen::Vector3d centre = Eigen::Vector3d::Zero();  // RAS mm
  // Unit vectors in RAS, right-handed: a positive angle about "flexion" flexes the joint (the
  // elbow bends the forearm forward, the knee the shank backward, the hip the thigh forward);
  // "abduction" (shoulder, hip) moves the limb away from the midline; "rotation" turns the distal
  // part about its own long axis; the neck also has "lateral" (the head to the body's left).
  std::vector<std::pair<std::string, Eigen::Vector3d>> axes;
  // The body parts of S it connects, proximal then distal ("" when not known).
  std::array<std::string, 2> parts;
  // Within this distance of the centre the two parts meet across the joint itself; beyond it a
  // contact between them is a contact (an arm resting on the trunk), which automatic separation
  // cuts. 0 when not known.
  double radiusMm = 0;
  std::string method;    // how the centre was found ("phantom", "sphere fit: humeral head", ...)
  double fitRmsMm = -1;  // residual of the fit, -1 when none

  const Eigen::Vector3d* axis(const std::string& axisName) const;
};

struct Skeleton {
  std::vector<SkeletonJoint> joints;
  std::string source;  // the file it was read from, for messages

  const SkeletonJoint* find(const std::string& name) const;
  // "elbow_left" -> its centre. Throws repose::Error naming `where` and listing the joints.
  Eigen::Vector3d centre(const std::string& joint, const std::string& where) const;
  // "elbow_left.flexion" -> the unit axis. Throws repose::Error naming `where`.
  Eigen::Vector3d axis(const std::string& jointDotAxis, const std::string& where) const;
};

// skeleton.json: {"units": "mm", "space": "RAS", "joints": [{"name", "parent", "ras": [x,y,z],
// "axes": {"flexion": [x,y,z], ...}, "parts": [proximal, distal], "radius_mm", "method",
// "fit_rms_mm"}, ...], ...}; only name and ras are required. Throws repose::Error
// "<source>: <field>: <problem>".
Skeleton parseSkeleton(const std::string& jsonText, const std::string& source);
Skeleton readSkeleton(const std::string& path);
// `extra` (a JSON object's text, or "") adds top-level fields (what made the skeleton).
std::string skeletonToJson(const Skeleton& skeleton, const std::string& extra = "");
void writeSkeleton(const Skeleton& skeleton, const std::string& path,
                   const std::string& extra = "");

// The skeleton that belongs to a body-part map: "skeleton.json" in S's folder, or
// "<prefix>skeleton.json" for S named "<prefix>S.<ext>" (as `repose phantom --prefix` writes).
// "" when there is none.
std::string findSkeletonBeside(const std::string& partsPath);
// Likewise the tissue table `repose rig` writes beside S ("tissues.csv" / "<prefix>tissues.csv").
std::string findTissuesBeside(const std::string& partsPath);

// The anatomical axes of a joint, unit vectors in RAS, from the direction of its distal segment
// (away from the joint: the forearm for the elbow, the foot for the ankle, the head for the neck)
// and the body's frame; `side` is +1 for the body's right, -1 for its left, 0 on the midline;
// `palmar` (wrist only) is where the palm faces. What the phantom's and the rig's skeletons both
// use, so a pose file means the same motion on either.
// Sternoclavicular: the shoulder girdle on the trunk (distal: along the clavicle, outwards; its
// axes "elevation", "protraction" and "rotation"); Lumbosacral: the pelvis under the lumbar spine
// (distal: downwards; "flexion" tilts the pelvis back, the same turn as the hips' flexion,
// "lateral", "rotation").
enum class JointKind {
  Shoulder,
  Elbow,
  Wrist,
  Hip,
  Knee,
  Ankle,
  Neck,
  Sternoclavicular,
  Lumbosacral
};
std::vector<std::pair<std::string, Eigen::Vector3d>> jointAxes(
    JointKind kind, const Eigen::Vector3d& distal, const Eigen::Vector3d& anterior,
    const Eigen::Vector3d& superior, int side,
    const Eigen::Vector3d& palmar = Eigen::Vector3d::Zero());

}  // namespace repose
