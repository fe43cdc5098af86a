// What the pose report counts in the posed maps, counted slab by slab so a frame too large for
// memory is reported as one that fits (issue 56): per label of the posed G its voxels, per pose
// group the bones' Dice counts against their analytically posed copy, and the enclosed
// background (holes), and where two groups' bones claim one voxel. The whole-grid report is the
// same tally over one slab.
#pragma once

#include "repose/mesh/RigidHandles.h"
#include "repose/raster/PieceOverlap.h"
#include "repose/volume/BackgroundTrace.h"
#include "repose/volume/Volume.h"

#include <cstdint>
#include <map>
#include <vector>

namespace repose {

// For one group: per label of G, the voxels inside the group's parts (S) of the posed maps, of
// the rest maps seen through the group's motion (nearest rest voxel at motion^-1 of each posed
// voxel centre: the analytically posed copy), of both, and of the rest maps themselves.
struct GroupDiceCounts {
  std::map<int, std::int64_t> posed, expected, both, rest;
};

class PosedTally {
 public:
  // `organs` and `parts`: G and S at rest (integer maps on one grid); `handles`: the frame's
  // groups with their motions (null: no Dice counts); `grid`: the posed maps' grid. The rest
  // maps and handles must outlive the tally.
  PosedTally(const Volume& organs, const Volume& parts, const std::vector<RigidHandle>* handles,
             const VolumeGeometry& grid, int threads = 0);

  // The rigid labels of G (bones, whole organs; TransferMesh::rigid and RigSettings::bonePieces),
  // before the first slice: then a posed voxel that the analytically posed copies of two groups'
  // rigid labels both claim is a collision between those pieces. Each group's copy is exact, so
  // it counts what the mesh's piece tets cannot see: a bone carried by another part's tets (the
  // rasterizer's ghosts) run into a bone of a neighbouring group, as a femur into a tibia when
  // a knee flexes about a pivot off the condyles.
  void countCollisions(const std::vector<int>& rigidLabels);

  // Slices [k0, k1) of layer 0 of the posed G and S (of the rest maps' scalar types), in order
  // from slice 0.
  void add(const void* posedOrgans, const void* posedParts, std::int64_t k0, std::int64_t k1);
  // Both posed maps whole.
  void addWhole(const Volume& posedOrgans, const Volume& posedParts);

  // After the last slice.
  const std::map<int, std::int64_t>& labelVoxels() const { return labels_; }  // non-zero labels
  const std::vector<GroupDiceCounts>& groups() const { return groups_; }      // one per handle
  // Per pair of pieces (label of G, body part of S at rest) of different groups, the posed voxels
  // both claim; pairs in increasing order. Empty unless countCollisions was called.
  std::vector<PieceOverlap> collisions() const;
  std::int64_t enclosedBackground() const { return holes_.enclosedVoxels(); }
  const VolumeGeometry& grid() const { return grid_; }
  bool complete() const { return next_ == grid_.dims[2]; }

 private:
  const Volume& organs_;
  const Volume& parts_;
  const std::vector<RigidHandle>* handles_;
  VolumeGeometry grid_;
  int threads_;
  std::int64_t next_ = 0;
  std::map<int, std::int64_t> labels_;
  std::vector<GroupDiceCounts> groups_;
  std::vector<int> rigid_;  // sorted
  std::map<std::pair<PieceId, PieceId>, std::int64_t> collisions_;
  BackgroundTrace holes_;
};

}  // namespace repose
