// Neighbourhoods of a tetrahedral mesh the solvers and the error metric share: face-adjacent
// tets T1(t), edges with their tets T1(e), and tets around each vertex T1(v).
#pragma once

#include "repose/mesh/TransferMesh.h"

#include <array>
#include <vector>

namespace repose {

struct TetAdjacency {
  std::vector<std::vector<int>> faceNeighbours;  // T1(t)
  std::vector<std::array<int, 2>> edges;         // (i, j), i < j
  std::vector<std::vector<int>> edgeTets;        // T1(e), parallel to edges
  std::vector<std::vector<int>> vertexTets;      // T1(v)
  static TetAdjacency build(const TransferMesh& mesh);
};

// Per vertex: 1 on the mesh's surface (a face that belongs to one tet only), else 0.
std::vector<char> surfaceVertices(const TransferMesh& mesh);

}  // namespace repose
