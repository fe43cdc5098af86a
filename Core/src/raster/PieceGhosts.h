// A whole piece's tissue that lies in soft tets, placed by the piece's own rigid motion.
//
// A bone is meshed as whole tets that move with its group (TransferMesh::rigid), and its rim
// takes the bone's voxels up to a voxel beyond them (Mesh_3's surface accuracy). Two kinds of soft
// tet still hold bone: the tets a joint demoted (demotePiecesAcrossJoints: where two bones share a
// mesh vertex, the smaller side's tets at it bend with the joint), and soft tets whose rest volume
// reaches into the bone by more than the rim covers. On thick slices those are a whole 5-8 mm
// layer at a bone's end: their bone bent with the joint (the radius lost 1 % beside a bent elbow,
// the pelvis 1 % beside a bent hip). A ghost is such a soft tet placed by a neighbouring piece
// tet's rigid map: scanned like a rim, it writes the voxels whose rest label is that body part's
// bone where the bone itself puts them.
//
// The soft tet may belong to another body part than the bone's. On thick slices Mesh_3 draws the
// parts' borders a slice or more off S's: on the ICRP adult male's grid half of the pelvis's
// voxels lie in the torso's tets. Those voxels had moved with the torso's soft tissue: sitting
// tilted the pelvis 25 degrees against it and 327 pelvis voxels landed off the pelvis (+1.27 %
// beyond its resampling floor). A ghost is therefore keyed by the piece and the body part S gives
// the piece's voxels, not by the soft tet's part.
//
// A piece tet can hold another part's bone too: on an 8 mm grid a scapula's tets lie on the ribs
// and take a slice of them. The piece tet does not copy that bone (it would move it with the
// shoulder girdle: the ribs +1.6 % under both arms raised); a ghost of it hosted by the bone's own
// part writes it where that part puts it (issue 64).
#pragma once

#include "TetScan.h"
#include "repose/mesh/TransferMesh.h"
#include "repose/volume/Volume.h"

#include <cstdint>
#include <vector>

namespace repose::raster {

struct PieceGhost {
  std::int32_t soft = -1;  // the soft tet whose rest volume holds the piece's tissue
  std::int32_t host = -1;  // a tet of that piece (same body part) whose map places it
};

// The soft tets whose rest volume holds a label of a piece (sampled at the centroid, half way to
// each vertex and at each face's centre drawn a quarter of the way in, on `pieceLabels`, the
// label map on the input's grid), and with `restParts` the piece tets whose rest volume holds a
// piece of another body part (sampled also on a lattice of about half a voxel), each with a tet
// of that piece in the body part `restParts`
// gives the sample (the soft tet's own part without it): within `rings` vertex-sharing steps
// through soft tets holding it, else any tet of that piece in that part (a piece moves whole:
// one rigid map), else, for a bone with no tet of its own there, the part's nearest piece tet
// (every piece of a body part moves with its group). `pieceOf[label]`: the piece id the label is
// meshed in (0: none). `restParts`, when given, is on `pieceLabels`' grid.
std::vector<PieceGhost> pieceGhosts(const TransferMesh& mesh, const Volume& pieceLabels,
                                    const std::vector<int>& pieceOf,
                                    const Volume* restParts = nullptr, int rings = 3);

// The ghosts as a mesh of their own: per ghost four vertices, its soft tet's rest positions
// (input IJK, from `in`) and their images under the host tet's map (output IJK). `tets` receives
// the ghost tets' vertex indices and must outlive the result.
ScanInput ghostScanInput(const ScanInput& in, const std::vector<PieceGhost>& ghosts,
                         Eigen::MatrixX4i& tets);

}  // namespace repose::raster
