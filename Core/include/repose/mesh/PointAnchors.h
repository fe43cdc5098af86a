// Points carried by the transfer mesh's deformation: a point of the rest body (a joint's centre,
// a landmark) is anchored once to the rest tet that holds it, by barycentric coordinates, and
// then follows any posed frame at the cost of one weighted sum. Directions (a joint's axes)
// follow the anchor tet's deformation gradient. What the workbench uses to draw the skeleton's
// joints where the live frame puts them.
#pragma once

#include "repose/mesh/TransferMesh.h"

#include <Eigen/Core>

#include <vector>

namespace repose {

struct PointAnchor {
  int tet = -1;                                       // -1: the mesh has no tets
  Eigen::Vector4d weights = Eigen::Vector4d::Zero();  // barycentric in `tet`, summing to 1
  // The point is inside `tet` (all weights >= -1e-9). A point outside the mesh is anchored to the
  // tet it is least outside of (the largest smallest weight), with the weights extrapolated, so
  // an affine deformation still moves it exactly.
  bool inside = false;
};

// One anchor per row of `points` (RAS mm, rest). Cost: a pass over the tets per point, pruned by
// the tets' boxes for points inside the mesh.
std::vector<PointAnchor> anchorPoints(const TransferMesh& mesh, const Eigen::MatrixX3d& points);

// `point` anchored to tet `tet`, its weights extrapolated when it lies outside. An affine map
// carries extrapolated weights exactly, so a point fixed in a rigid piece (a joint's centre in
// its proximal bone) anchored to one of the piece's tets follows the piece's motion exactly.
// An anchor with no tet (-1) for a degenerate rest tet.
PointAnchor anchorPointInTet(const TransferMesh& mesh, const Eigen::Vector3d& point, int tet);

// Where the anchored points are in a frame (`deformed`: the posed TM vertices, one row per rest
// vertex). Anchors with no tet keep their rest position `rest` (same rows as the anchors).
Eigen::MatrixX3d movePoints(const TransferMesh& mesh, const Eigen::MatrixX3d& deformed,
                            const std::vector<PointAnchor>& anchors, const Eigen::MatrixX3d& rest);

// The deformation gradient of one tet (posed edges times the inverse of the rest edges): how a
// short direction at the anchor turns and stretches. Identity for a degenerate rest tet.
Eigen::Matrix3d tetDeformationGradient(const TransferMesh& mesh, const Eigen::MatrixX3d& deformed,
                                       int tet);

}  // namespace repose
