// Automatic contact separation. Body parts that a pose moves with different handle groups are cut
// free wherever they touch in S (an arm resting on the trunk, a hand on a thigh, two thighs),
// except across the joint that connects them: a cage inset between them and a split of the
// transfer mesh along their interface (the seed's limb separation, with the region found rather
// than drawn). Without it, the mesh ties the two sides together along the contact, and moving one
// drags a sheet of the other's tissue with it.
#pragma once

#include "repose/cage/CageBuilder.h"
#include "repose/pose/Pose.h"
#include "repose/skeleton/Skeleton.h"
#include "repose/volume/Volume.h"

#include <array>
#include <string>
#include <vector>

namespace repose {

struct ContactSeparation {
  LimbSeparation separation;  // the two labels of S and where to cut
  std::array<std::string, 2> names;
  std::string joint;  // the joint the two parts meet across, which is not cut ("" when none)
  // Voxels of either part whose centre lies within the reach of a voxel centre of the other part
  // (ContactOptions::reachMm; with no reach, those with a face on the other part), inside the
  // region; their centroid and box.
  std::int64_t contactVoxels = 0;
  // Of those, the voxels with a face on the other part (0: the parts only come near).
  std::int64_t touchingVoxels = 0;
  // The air between the two parts at their closest, inside the region: the distance between
  // the nearest two voxels' boxes (0 when they touch; a gap of two voxels of air along x is
  // 2 * spacing x).
  double gapMm = 0;
  Eigen::Vector3d centroid = Eigen::Vector3d::Zero();
  Eigen::Vector3d lo = Eigen::Vector3d::Zero(), hi = Eigen::Vector3d::Zero();
};

struct ContactSeparations {
  std::vector<ContactSeparation> made;
  // Touching pairs left joined, one line each saying why (a joint the skeleton lacks).
  std::vector<std::string> skipped;
  double reachMm = 0;  // the reach the near contacts were found with
  std::vector<LimbSeparation> separations() const;
  std::string json() const;  // report.json's "automatic_separations"
};

// Which handle group carries each body part (label of S -> group index), as resolveHandles
// decides it: the parts a group names, and for the "rest" group every other part present when
// all other groups name parts. Parts of groups decided by cage vertices are left out.
std::vector<std::pair<int, int>> groupOfParts(const Pose& pose, const Volume& parts);

struct ContactOptions {
  // Parts closer than this (between voxel centres, mm) are cut too, not only touching ones: a
  // hand a few millimetres off the hip is tied to it by any cage or transfer-mesh element wider
  // than the gap. 0: only parts that touch (share a voxel face).
  double reachMm = 0;
  int threads = 0;
};

// The reach at which the cage ties two parts together: closer than twice the cage's dilation
// plus its working voxel, their dilated surfaces merge and the cage cannot pass between them
// (cage/CageBuilder.h). The transfer mesh is made finer along each cut (nearContactRefinements),
// so it cannot span a gap the cage no longer spans.
double contactReachMm(const CageOptions& cage, const Volume& parts);

// The separations a pose needs on S: parts carried by different groups that touch or come
// within options.reachMm of each other. A pair that meets across its own joint is cut only
// outside the joint's sphere (the skeleton's centre and radius_mm). A pair of standard part
// names that a standard joint connects (torso and upper_arm_left at the shoulder, ...) is left
// joined, and said so, when the skeleton lacks that joint. Groups that never move relative to
// each other (all fixed) are not separated.
ContactSeparations findContactSeparations(const Volume& parts, const Pose& pose,
                                          const Skeleton* skeleton,
                                          const ContactOptions& options = {});

}  // namespace repose
