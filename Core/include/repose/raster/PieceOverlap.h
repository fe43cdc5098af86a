// Where the whole pieces of a deformed transfer mesh (bones and organs that move rigidly:
// TransferMesh::rigid) run into each other. Two rigid pieces cannot share space; where a pose
// puts them into each other (a forearm turned about a pivot off the elbow's axis pushes the ulna
// into the humerus), the rasterizer gives the shared voxels to one of them and the other loses
// them. This finds those voxels on the output grid, so a pose can report and warn before anyone
// trusts the posed bones.
#pragma once

#include "repose/mesh/TransferMesh.h"
#include "repose/volume/VolumeGeometry.h"

#include <Eigen/Core>

#include <cstdint>
#include <vector>

namespace repose {

// A piece: its label of G (TransferMesh::rigid) in one body part of S (TransferMesh::labels), so
// the left and the right humerus of a map that labels both alike are two pieces.
struct PieceId {
  int label = 0;
  int part = 0;
  bool operator<(const PieceId& o) const {
    return label != o.label ? label < o.label : part < o.part;
  }
  bool operator==(const PieceId& o) const { return label == o.label && part == o.part; }
};

struct PieceOverlap {
  PieceId a, b;             // a < b
  std::int64_t voxels = 0;  // output voxel centres inside both
};

// Every pair of distinct pieces whose deformed tets both contain some voxel centres of `grid`,
// with how many; pairs in increasing order of (a, b). Empty when the mesh has no pieces. A piece
// folded onto itself is not counted (it cannot be: pieces move rigidly).
std::vector<PieceOverlap> pieceOverlaps(const TransferMesh& mesh, const Eigen::MatrixX3d& deformed,
                                        const VolumeGeometry& grid);

}  // namespace repose
