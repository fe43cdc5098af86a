// Adjacency by sorting (face key, tet) and (edge key, tet) pairs: O(T log T), no hash maps.
#include "repose/mesh/TetAdjacency.h"

#include <algorithm>
#include <array>
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

std::vector<char> surfaceVertices(const TransferMesh& mesh) {
  // Sorted face keys: a key that appears once is on the surface.
  std::vector<std::array<int, 3>> faces;
  faces.reserve(4 * static_cast<std::size_t>(mesh.tets.rows()));
  static constexpr int kFace[4][3] = {{1, 2, 3}, {0, 2, 3}, {0, 1, 3}, {0, 1, 2}};
  for (Eigen::Index t = 0; t < mesh.tets.rows(); ++t)
    for (const auto& f : kFace) {
      std::array<int, 3> key{mesh.tets(t, f[0]), mesh.tets(t, f[1]), mesh.tets(t, f[2])};
      std::sort(key.begin(), key.end());
      faces.push_back(key);
    }
  std::sort(faces.begin(), faces.end());
  std::vector<char> surface(static_cast<std::size_t>(mesh.vertices.rows()), 0);
  for (std::size_t i = 0; i < faces.size();) {
    std::size_t j = i + 1;
    while (j < faces.size() && faces[j] == faces[i]) ++j;
    if (j - i == 1)
      for (const int v : faces[i]) surface[v] = 1;
    i = j;
  }
  return surface;
}

}  // namespace repose
