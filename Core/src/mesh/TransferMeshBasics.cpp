// Small pieces of the transfer mesh: tet volume, the sizing field, and label separation.
#include "repose/mesh/TransferMesh.h"

#include "repose/util/Error.h"

#include <Eigen/LU>
#include <algorithm>
#include <array>
#include <cmath>
#include <map>
#include <set>
#include <vector>

namespace repose {

double tetVolume(const Eigen::MatrixX3d& vertices, const Eigen::RowVector4i& tet) {
  Eigen::Matrix3d E;
  for (int c = 0; c < 3; ++c)
    E.col(c) = (vertices.row(tet[c + 1]) - vertices.row(tet[0])).transpose();
  return E.determinant() / 6;
}

SizingField SizingField::uniform(const VolumeGeometry& grid, double sizeMm) {
  if (!(sizeMm > 0) || !std::isfinite(sizeMm))
    throw Error("tet size must be a positive number of mm");
  SizingField f;
  f.grid = grid;
  f.sizeMm.assign(static_cast<std::size_t>(grid.numVoxels()), static_cast<float>(sizeMm));
  return f;
}

double SizingField::at(const Eigen::Vector3d& ras) const {
  const Eigen::Vector3d x = grid.rasToVoxel(ras);
  std::int64_t i0[3];
  double f[3];
  for (int c = 0; c < 3; ++c) {
    const double clamped = std::clamp(x[c], 0.0, double(grid.dims[c] - 1));
    i0[c] = std::min<std::int64_t>(static_cast<std::int64_t>(clamped),
                                   std::max<std::int64_t>(0, grid.dims[c] - 2));
    f[c] = grid.dims[c] > 1 ? clamped - i0[c] : 0;
  }
  auto v = [&](int di, int dj, int dk) {
    const std::int64_t i = std::min(i0[0] + di, grid.dims[0] - 1),
                       j = std::min(i0[1] + dj, grid.dims[1] - 1),
                       k = std::min(i0[2] + dk, grid.dims[2] - 1);
    return double(sizeMm[static_cast<std::size_t>(i + grid.dims[0] * (j + grid.dims[1] * k))]);
  };
  const double c00 = v(0, 0, 0) * (1 - f[0]) + v(1, 0, 0) * f[0],
               c10 = v(0, 1, 0) * (1 - f[0]) + v(1, 1, 0) * f[0];
  const double c01 = v(0, 0, 1) * (1 - f[0]) + v(1, 0, 1) * f[0],
               c11 = v(0, 1, 1) * (1 - f[0]) + v(1, 1, 1) * f[0];
  return (c00 * (1 - f[1]) + c10 * f[1]) * (1 - f[2]) + (c01 * (1 - f[1]) + c11 * f[1]) * f[2];
}

void cleanTransferMesh(TransferMesh& mesh, double frameSign, TransferMeshReport& r) {
  const Eigen::Index nt = mesh.tets.rows();
  double meanVolume = 0;
  for (Eigen::Index t = 0; t < nt; ++t)
    meanVolume += std::fabs(tetVolume(mesh.vertices, mesh.tets.row(t)));
  meanVolume /= std::max<double>(1, static_cast<double>(nt));
  r.degenerateTets = r.invertedTets = 0;
  std::vector<char> used(static_cast<std::size_t>(mesh.vertices.rows()), 0);
  Eigen::Index kept = 0;
  for (Eigen::Index t = 0; t < nt; ++t) {
    Eigen::RowVector4i tet = mesh.tets.row(t);
    const double vol = tetVolume(mesh.vertices, tet);
    if (!(std::fabs(vol) >= 1e-9 * meanVolume) || meanVolume == 0) {  // also catches NaN
      ++r.degenerateTets;
      continue;
    }
    if (frameSign * vol < 0) ++r.invertedTets;
    if (vol < 0) std::swap(tet[2], tet[3]);
    for (int c = 0; c < 4; ++c) used[tet[c]] = 1;
    mesh.tets.row(kept) = tet;
    if (!mesh.rigid.empty()) mesh.rigid[kept] = mesh.rigid[t];
    mesh.labels[kept++] = mesh.labels[t];
  }
  mesh.tets.conservativeResize(kept, 4);
  mesh.labels.conservativeResize(kept);
  if (!mesh.rigid.empty()) mesh.rigid.resize(static_cast<std::size_t>(kept));
  // Renumber the vertices that are still used, keeping their order.
  std::vector<int> newIndex(used.size(), -1);
  int nv = 0;
  for (std::size_t v = 0; v < used.size(); ++v)
    if (used[v])
      mesh.vertices.row(nv) = mesh.vertices.row(static_cast<Eigen::Index>(v)), newIndex[v] = nv++;
  mesh.vertices.conservativeResize(nv, 3);
  for (Eigen::Index t = 0; t < kept; ++t)
    for (int c = 0; c < 4; ++c) mesh.tets(t, c) = newIndex[mesh.tets(t, c)];
  std::map<int, int> perLabel;
  for (Eigen::Index t = 0; t < kept; ++t) ++perLabel[mesh.labels[t]];
  r.vertices = nv;
  r.tets = static_cast<int>(kept);
  r.tetsPerLabel.assign(perLabel.begin(), perLabel.end());
}

int separateLabels(TransferMesh& mesh, int labelA, int labelB, const Region& region) {
  bool hasA = false, hasB = false;
  for (Eigen::Index t = 0; t < mesh.labels.size(); ++t)
    hasA |= mesh.labels[t] == labelA, hasB |= mesh.labels[t] == labelB;
  if (!hasA || !hasB)
    throw Error("separation: label " + std::to_string(!hasA ? labelA : labelB) +
                " has no tetrahedron in the mesh");
  // The seed duplicates the vertices of faces shared by an a-tet and a b-tet. Tets that touch
  // only along an edge or at a vertex would still tie the parts together, so every vertex inside
  // the region used by both an a-tet and a b-tet is split (a superset of the face rule).
  std::vector<char> usedByA(static_cast<std::size_t>(mesh.vertices.rows()), 0), usedByB(usedByA);
  for (Eigen::Index t = 0; t < mesh.tets.rows(); ++t)
    for (int c = 0; c < 4; ++c) {
      if (mesh.labels[t] == labelA) usedByA[mesh.tets(t, c)] = 1;
      if (mesh.labels[t] == labelB) usedByB[mesh.tets(t, c)] = 1;
    }
  std::set<int> split;
  for (Eigen::Index v = 0; v < mesh.vertices.rows(); ++v)
    if (usedByA[v] && usedByB[v] && region.contains(mesh.vertices.row(v).transpose()))
      split.insert(static_cast<int>(v));
  // Each split vertex gets one copy. Around it, the copy goes to the b tets and to every tet
  // reachable from them through faces that contain the vertex without crossing an a tet: a hand
  // leaving the hip takes its forearm along instead of tearing away from it.
  std::map<int, std::vector<int>> around;
  for (Eigen::Index t = 0; t < mesh.tets.rows(); ++t)
    for (int c = 0; c < 4; ++c)
      if (split.count(mesh.tets(t, c))) around[mesh.tets(t, c)].push_back(static_cast<int>(t));
  const Eigen::Index before = mesh.vertices.rows();
  mesh.vertices.conservativeResize(before + static_cast<Eigen::Index>(split.size()), 3);
  int added = 0;
  for (int v : split) {
    const int copy = static_cast<int>(before) + added++;
    mesh.vertices.row(copy) = mesh.vertices.row(v);
    const std::vector<int>& tets = around[v];
    auto shareFace = [&](int t, int u) {  // v plus two more common vertices
      int common = 0;
      for (int a = 0; a < 4; ++a)
        for (int b = 0; b < 4; ++b) common += mesh.tets(t, a) == mesh.tets(u, b);
      return common == 3;
    };
    std::vector<char> reached(tets.size(), 0);
    std::vector<std::size_t> queue;
    for (std::size_t i = 0; i < tets.size(); ++i)
      if (mesh.labels[tets[i]] == labelB) reached[i] = 1, queue.push_back(i);
    while (!queue.empty()) {
      const std::size_t i = queue.back();
      queue.pop_back();
      for (std::size_t j = 0; j < tets.size(); ++j)
        if (!reached[j] && mesh.labels[tets[j]] != labelA && shareFace(tets[i], tets[j]))
          reached[j] = 1, queue.push_back(j);
    }
    for (std::size_t i = 0; i < tets.size(); ++i)
      if (reached[i])
        for (int c = 0; c < 4; ++c)
          if (mesh.tets(tets[i], c) == v) mesh.tets(tets[i], c) = copy;
  }
  return added;
}

}  // namespace repose
