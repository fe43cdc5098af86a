// Soft labels encased in bone: the spinal cord in its canal (and any soft label that, like it,
// lies inside a ring of bone). Such a label must move with the bone around it. Left to the soft
// tissue's deformation, it is dragged off its canal wherever the tissue beside the bone is pulled
// (both arms raised 180 degrees pull the neck's tissue with the shoulder girdles): the fixed
// vertebrae then cut it and it spills out through the canal's gaps (on 4.8 mm slices the cord
// +4.8 %, issue 64). It spans the trunk, the head and the pelvis, so the whole-organ rule (one
// body part) never takes it.
#pragma once

#include "repose/volume/Volume.h"

#include <cstdint>
#include <vector>

namespace repose {

struct EncasedTissueOptions {
  // How far a ray may go through soft tissue to meet the bone around it (a canal's radius and the
  // bone's gaps: an adult's spinal canal is 15-25 mm across, its laminae a few mm apart).
  double reachMm = 20;
  // Of the four horizontal directions (the two voxel axes most across the body's long axis, S,
  // both ways), how many must meet bone within the reach for a voxel to be encased.
  int sides = 3;
  // The share of a label's voxels that must be encased for the label to be.
  double share = 0.6;
};

// The soft labels of `organs` (non-zero, not in `rigidLabels`) encased in bone, sorted. The grid
// axis nearest RAS S is the long axis (a body acquired standing or lying has its head-foot axis
// along S); each slice across it is scanned along its two axes both ways, so the work is four
// passes over the voxels and the memory one slice. On the generated phantom (4.8 mm slices), the
// ICRP-labelled one (8 mm slices) and TotalSegmentator's example segmentation (3 mm) the spinal
// cord is encased in at least 70 % of its voxels and every other soft label in under 5 %
// (EncasedTissueTest).
std::vector<int> labelsEncasedInBone(const Volume& organs, const std::vector<int>& rigidLabels,
                                     const EncasedTissueOptions& options = {});

// How far from another body part an encased label stays soft tissue: about a vertebra's height
// (a lumbar vertebra is 25-30 mm high, its disc 10 mm), so the bend at the joint its bone is
// parted at has soft tissue to bend over on each side.
constexpr double kEncasedJointBandMm = 10;

// Makes soft (0 in `piece`, the piece map on the grid of `parts`) every voxel of an `encased`
// label of `organs` with a voxel of another body part of `parts` within `bandMm` along one of
// the six voxel axes.
void softenEncasedNearOtherParts(const Volume& organs, const Volume& parts,
                                 const std::vector<int>& encased, double bandMm,
                                 std::uint16_t* piece);

}  // namespace repose
