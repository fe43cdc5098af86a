// Bones that a joint's turn drives into each other are parted along the distal bone.
//
// A pose turns a limb about the joint centre the rig fitted. On thick slices that centre is off
// by a few millimetres along the slices (a femoral condyle is one or two 8 mm slices deep), and a
// 90 degree turn about a centre off by e moves the distal bone by about 1.4 e: sitting drove each
// tibia 11 voxels into its femur on the ICRP adult male's grid, and the real adult female's 70
// (issue 64, item 4). Neither bone may lose voxels, and the joint's true centre is not in the
// data, so the distal group (with every group that follows it) is moved away from the joint
// along the distal bone's posed direction by the least amount, in 0.5 mm steps up to
// kMaxShiftMm, that leaves no rigid voxel of the distal part where the proximal part's rigid
// voxels are (PosedTally's count of a collision, on the posed lattice around the joint), or no
// more than the target allows; where no shift does, the group is left as posed. A
// joint whose bones meet in no more than the collision target allows (a voxel, or 0.1 % of the
// smaller bone end) is left as posed. Bones that meet away from a joint (a scapula turned into
// the ribs) are not parted here. Applied to every frame the rig solves (a pose
// file's, an edited one's and the live view's), so the view, the prediction and the export agree.
#pragma once

#include "repose/pose/Pose.h"
#include "repose/skeleton/Skeleton.h"
#include "repose/volume/Volume.h"

#include <Eigen/Geometry>

#include <array>
#include <cstdint>
#include <string>
#include <vector>

namespace repose {

class JointClearance {
 public:
  static constexpr double kMaxShiftMm = 8;
  static constexpr double kStepMm = 0.5;

  // What apply() did at one joint of one frame.
  struct Shift {
    std::string joint;
    int group = -1;  // the distal group moved (with its followers)
    Eigen::Vector3d shiftMm = Eigen::Vector3d::Zero();  // posed RAS mm
    std::int64_t voxelsBefore = 0, voxelsAfter = 0;     // distal rigid voxels on proximal ones
  };

  JointClearance() = default;  // nothing to part
  // Prepared once per rig: for each joint of the skeleton whose two parts two different groups
  // of `pose` carry (joints resolved, rhythms applied: the rig's pose), the rest positions of the
  // distal part's rigid voxels (labels in `rigidLabels`) within reach of the joint, and the
  // proximal part's rigid voxels there. `organs` (G) and `parts` (S) share one grid.
  JointClearance(const Pose& pose, const Skeleton& skeleton, const Volume& organs,
                 const Volume& parts, const std::vector<int>& rigidLabels);

  bool empty() const { return sites_.empty(); }
  // Moves, in `motions` (one per group of the pose, composed along `follows`: Pose::frames()),
  // each distal group and its followers off the joints whose bones the motions drive together;
  // returns what it moved.
  std::vector<Shift> apply(std::vector<Eigen::Isometry3d>& motions) const;

 private:
  struct Site {
    std::string name;
    int proximal = -1, distal = -1;  // groups
    Eigen::Vector3d centre = Eigen::Vector3d::Zero();
    double reachMm = 0;                      // the bones within this of the centre
    std::vector<std::int64_t> distalBone;    // rest voxel indices, sorted
    std::vector<std::int64_t> proximalBone;  // rest voxel indices, sorted
    Eigen::Vector3d distalCentroid = Eigen::Vector3d::Zero();  // rest RAS mm
    Eigen::AlignedBox3d distalBox, proximalBox;                // rest RAS mm
    std::vector<int> carried;  // the distal group and every group following it
  };
  std::int64_t overlap(const Site& site, const Eigen::Isometry3d& proximal,
                       const Eigen::Isometry3d& distal) const;

  std::vector<Site> sites_;
  VolumeGeometry grid_;
};

}  // namespace repose
