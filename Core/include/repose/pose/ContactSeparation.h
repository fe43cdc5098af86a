// Automatic contact separation. Body parts that a pose moves with different handle groups are cut
// free wherever they touch in S (an arm resting on the trunk, a hand on a thigh, two thighs),
// except across the joint that connects them: a cage inset between them and a split of the
// transfer mesh along their interface (the seed's limb separation, with the region found rather
// than drawn). Without it, the mesh ties the two sides together along the contact, and moving one
// drags a sheet of the other's tissue with it.
#pragma once

#include "repose/cage/CageBuilder.h"
#include "repose/pose/Pose.h"
#include "repose/pose/Skeleton.h"
#include "repose/volume/Volume.h"

#include <array>
#include <string>
#include <vector>

namespace repose {

struct ContactSeparation {
  LimbSeparation separation;  // the two labels of S and where to cut
  std::array<std::string, 2> names;
  std::string joint;  // the joint the two parts meet across, which is not cut ("" when none)
  // Voxels of either part with a face on the other, inside the region; their centroid and box.
  std::int64_t contactVoxels = 0;
  Eigen::Vector3d centroid = Eigen::Vector3d::Zero();
  Eigen::Vector3d lo = Eigen::Vector3d::Zero(), hi = Eigen::Vector3d::Zero();
};

struct ContactSeparations {
  std::vector<ContactSeparation> made;
  // Touching pairs left joined, one line each saying why (a joint the skeleton lacks).
  std::vector<std::string> skipped;
  std::vector<LimbSeparation> separations() const;
  std::string json() const;  // report.json's "automatic_separations"
};

// Which handle group carries each body part (label of S -> group index), as resolveHandles
// decides it: the parts a group names, and for the "rest" group every other part present when
// all other groups name parts. Parts of groups decided by cage vertices are left out.
std::vector<std::pair<int, int>> groupOfParts(const Pose& pose, const Volume& parts);

// The separations a pose needs on S. A pair that touches across its own joint is cut only
// outside the joint's sphere (the skeleton's centre and radius_mm). A pair of standard part
// names that a standard joint connects (torso and upper_arm_left at the shoulder, ...) is left
// joined, and said so, when the skeleton lacks that joint. Groups that never move relative to
// each other (all fixed) are not separated.
ContactSeparations findContactSeparations(const Volume& parts, const Pose& pose,
                                          const Skeleton* skeleton);

}  // namespace repose
