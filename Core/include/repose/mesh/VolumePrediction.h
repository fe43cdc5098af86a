// The body's volume change a posed transfer mesh predicts, before a voxel is written: each tet's
// deformed volume against its rest volume, summed per body part (signed, so a tet turned inside
// out subtracts what it covers twice). A pose that drags a sheet of one part's tissue along with
// another (an arm raised off the trunk it is tied to along their contact) stretches the dragged
// part's tets; the part whose volume changes most and the neighbouring part that shares the most
// of that change through common vertices say what went wrong, and where.
#pragma once

#include "repose/mesh/TransferMesh.h"

#include <Eigen/Core>

#include <vector>

namespace repose {

struct PartVolumeChange {
  int part = 0;  // label of S
  double restMm3 = 0, posedMm3 = 0;
  double changePercent() const { return restMm3 > 0 ? 100 * (posedMm3 / restMm3 - 1) : 0; }
};

struct VolumePrediction {
  double restMm3 = 0, posedMm3 = 0;     // the whole mesh
  std::vector<PartVolumeChange> parts;  // in increasing part label
  // The part whose volume changes most in mm^3 (0 when nothing changes), and the neighbouring
  // part most tied to that change: the one whose tets share the most vertices of the worst part's
  // changed tets, weighted by their change (0 when the worst part touches no other part).
  int worstPart = 0;
  int draggedBy = 0;
  double changePercent() const { return restMm3 > 0 ? 100 * (posedMm3 / restMm3 - 1) : 0; }
};

// `deformed` holds the mesh's posed vertices (RAS mm). Throws repose::Error on a size mismatch.
VolumePrediction predictVolumeChange(const TransferMesh& mesh, const Eigen::MatrixX3d& deformed);

}  // namespace repose
