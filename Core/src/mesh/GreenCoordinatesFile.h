// The Green coordinates of a transfer mesh in its cage, kept on disk between runs
// (docs/FORMATS.md, "Green-coordinate files"). Computing them is most of a deformation's time
// with a saved rig; reading them back is a copy. A file is used only for the mesh and cage it was
// written for (a 64-bit key over both) and only when whole (sizes and CRC-32s); anything else is
// reported as a reason and the coordinates are computed again.
#pragma once

#include "CompactGreenMatrix.h"

#include "repose/cage/TriangleMesh.h"
#include "repose/mesh/TransferMesh.h"

#include <Eigen/Core>
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

namespace repose {

struct SavedGreenCoordinates {
  std::vector<int> cageVertices;   // V_c, increasing (those the coordinates reproduce)
  int unreproduced = 0;            // vertices inside the cage left out of V_c
  Eigen::MatrixX3d restPositions;  // the exact Green image of the rest cage, rows follow V_c
  CompactGreenMatrix coefficients;
};

// FNV-1a over the format version, the mesh's vertices and tets and the cage's vertices and faces.
std::uint64_t greenCoordinatesKey(const TransferMesh& mesh, const TriangleMesh& cage);

// Written atomically (a temporary beside it, renamed); throws repose::Error naming the file.
void writeGreenCoordinatesFile(const std::string& path, std::uint64_t key,
                               Eigen::Index meshVertices, const std::vector<int>& cageVertices,
                               int unreproduced, const Eigen::MatrixX3d& restPositions,
                               const CompactGreenMatrix& coefficients, int threads);

// The saved coordinates when `path` holds them for this key, mesh size and cage; else nullopt and
// *why says which (no such file, another mesh or cage, another format, damaged or cut short).
std::optional<SavedGreenCoordinates> readGreenCoordinatesFile(const std::string& path,
                                                              std::uint64_t key,
                                                              Eigen::Index meshVertices,
                                                              const TriangleMesh& cage, int threads,
                                                              std::string* why);

}  // namespace repose
