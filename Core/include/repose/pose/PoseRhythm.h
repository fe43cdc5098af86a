// The rhythms a body follows beyond what one joint does: the scapulohumeral rhythm (an arm raised
// beyond 90 degrees turns the shoulder girdle with it) and the lumbopelvic rhythm (a hip flexed
// beyond 60 degrees tilts the pelvis back). Where the skeleton has the girdle's and the pelvis's
// joints (`repose rig` makes them from the clavicles and the pelvis: sternoclavicular_left/right,
// lumbosacral), a pose that raises an arm or flexes a hip gets a group for the girdle or the
// pelvis, turned by its share of the motion about its own joint, and the limb's group follows it
// with the rest of the turn about the limb's joint: the limb ends where the pose puts it, its
// joint riding on the girdle or the pelvis (docs/POSES.md, "Rhythms").
#pragma once

#include "repose/pose/Pose.h"
#include "repose/skeleton/Skeleton.h"
#include "repose/volume/LabelTable.h"

#include <string>
#include <vector>

namespace repose {

// The girdle's share of an arm's elevation (the angle between the upper arm's rest and posed
// directions), degrees: none up to 90, then one degree for every two at the glenohumeral joint,
// the 2:1 ratio Inman, Saunders and Abbott (1944) measured (30 degrees of the girdle at 180).
double girdleTurnDeg(double elevationDeg);
// The pelvis's backward tilt for a hip flexed by `flexionDeg` (the thigh against the trunk),
// degrees: none up to 60, then five degrees of every six, up to 30: sitting from standing (a
// thigh-trunk flexion of about 80-90 degrees) tilts the pelvis back about 20-25 degrees while the
// hip itself flexes about 60-65 (Lazennec et al. 2011, Endo et al. 2012).
double pelvisTiltDeg(double flexionDeg);

class PoseRhythms {
 public:
  PoseRhythms() = default;  // a body without the girdle's or the pelvis's joints: no rhythm
  // The joints the rhythms turn about, from the skeleton; S's labels name the parts.
  PoseRhythms(const Skeleton& skeleton, const LabelTable& partLabels);
  bool empty() const { return girdles_.empty() && !pelvis_.present; }

  // The pose (joints resolved to numbers) with the rhythms' groups after its own: for each side
  // whose upper arm a group turns about the shoulder, a group for the girdle; for the hips, one
  // for the pelvis. Each such limb group then follows the new group, its own turn less the new
  // group's, about its joint carried with the girdle or the pelvis. A group that selects the
  // torso also selects the girdles and the pelvis no other group takes (they are the trunk's).
  // In every frame (the base and each keyframe) the turn follows the rhythm, 0 where the limb
  // stays within it, so the groups are the same in every frame and for every edit of the
  // pose. Nothing changes where the pose switches the rhythm off, already selects the girdle or
  // the pelvis, or turns no limb about its joint. `notes` (optional) gets a line per group made.
  Pose apply(const Pose& pose, std::vector<std::string>* notes = nullptr) const;

 private:
  struct Girdle {
    std::string side, girdlePart, armPart, joint;  // names of S's parts, the shoulder's name
    Eigen::Vector3d sc = Eigen::Vector3d::Zero(), shoulder = Eigen::Vector3d::Zero();
    Eigen::Vector3d distal = Eigen::Vector3d::UnitZ();  // the upper arm's rest direction
  };
  struct Pelvis {
    bool present = false;
    std::string part;
    Eigen::Vector3d centre = Eigen::Vector3d::Zero(), axis = Eigen::Vector3d::UnitX();
    struct Hip {
      std::string joint, thighPart;
      Eigen::Vector3d centre = Eigen::Vector3d::Zero(), distal = -Eigen::Vector3d::UnitZ();
      Eigen::Vector3d flexion = Eigen::Vector3d::UnitX();
    };
    std::vector<Hip> hips;
  };
  std::vector<Girdle> girdles_;
  Pelvis pelvis_;
  LabelTable partLabels_;
};

// Warnings, one line each, for every turn of a pose about a named joint axis beyond that joint's
// published range of motion (jointRangeDeg: clinical goniometry), in the base and each keyframe.
// The pose must still name its joints (before resolvePoseJoints).
std::vector<std::string> jointRangeWarnings(const Pose& pose);

}  // namespace repose
