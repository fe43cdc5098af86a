// The transfer mesh inside the cage: V_c (TM vertices inside it), T_c (tets with all four
// vertices in V_c) and the Green coordinates of V_c, computed once per TM and cage.
#pragma once

#include "repose/cage/GreenCoordinates.h"
#include "repose/mesh/TransferMesh.h"

#include <vector>

namespace repose {

struct Embedding {
  std::vector<int> cageVertices;  // V_c: indices of TM vertices inside the cage, increasing
  std::vector<int> cageTets;      // T_c: indices of tets whose 4 vertices are in V_c
  std::vector<char> inside;       // per TM vertex: 1 if in V_c
  GreenCoordinates coordinates;   // rows follow cageVertices
  int outliers() const { return static_cast<int>(inside.size() - cageVertices.size()); }
};

// Inside means generalized winding number >= 0.5. Throws repose::Error when no TM vertex is
// inside the cage (nothing would move). Without coordinates, `coordinates` stays empty (a caller
// computing them in blocks to bound memory).
Embedding embedInCage(const TransferMesh& mesh, const TriangleMesh& cage, int threads = 0,
                      bool withCoordinates = true);

}  // namespace repose
