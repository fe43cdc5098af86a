// Adjacency by sorting (face key, tet) and (edge key, tet) pairs: O(T log T), no hash maps.
#include "TetAdjacency.h"

#include <algorithm>
#include <tuple>

namespace repose {

TetAdjacency TetAdjacency::build(const TransferMesh& mesh) {
  const int nt = static_cast<int>(mesh.tets.rows());
  TetAdjacency a;
  a.faceNeighbours.assign(nt, {});
  a.vertexTets.assign(static_cast<std::size_t>(mesh.vertices.rows()), {});
  std::vector<std::tuple<int, int, int, int>> faces;  // sorted vertex triple, tet
  std::vector<std::tuple<int, int, int>> edges;       // sorted vertex pair, tet
  faces.reserve(4 * static_cast<std::size_t>(nt));
  edges.reserve(6 * static_cast<std::size_t>(nt));
  for (int t = 0; t < nt; ++t) {
    std::array<int, 4> v{mesh.tets(t, 0), mesh.tets(t, 1), mesh.tets(t, 2), mesh.tets(t, 3)};
    for (int c = 0; c < 4; ++c) a.vertexTets[v[c]].push_back(t);
    std::sort(v.begin(), v.end());
    faces.emplace_back(v[1], v[2], v[3], t);
    faces.emplace_back(v[0], v[2], v[3], t);
    faces.emplace_back(v[0], v[1], v[3], t);
    faces.emplace_back(v[0], v[1], v[2], t);
    for (int i = 0; i < 4; ++i)
      for (int j = i + 1; j < 4; ++j) edges.emplace_back(v[i], v[j], t);
  }
  std::sort(faces.begin(), faces.end());
  for (std::size_t f = 0; f + 1 < faces.size(); ++f) {
    const auto& [a0, a1, a2, ta] = faces[f];
    const auto& [b0, b1, b2, tb] = faces[f + 1];
    if (a0 == b0 && a1 == b1 && a2 == b2) {
      a.faceNeighbours[ta].push_back(tb);
      a.faceNeighbours[tb].push_back(ta);
    }
  }
  std::sort(edges.begin(), edges.end());
  for (std::size_t e = 0; e < edges.size(); ++e) {
    const auto& [i, j, t] = edges[e];
    if (e == 0 || std::get<0>(edges[e - 1]) != i || std::get<1>(edges[e - 1]) != j) {
      a.edges.push_back({i, j});
      a.edgeTets.emplace_back();
    }
    a.edgeTets.back().push_back(t);
  }
  return a;
}

}  // namespace repose
