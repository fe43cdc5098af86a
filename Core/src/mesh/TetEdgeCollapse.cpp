// collapseShortEdges: the clusters of tiny tets Mesh_3 leaves where three or more labels meet,
// merged away (TransferMesh.h).
//
// Without protected features, Mesh_3's facet criteria cannot be met along a curve where several
// label surfaces meet, and it refines there until it gives up: on thick slices (1.8 x 1.8 x 4.8
// mm) balls of tets with edges of hundredths of a millimetre sat at each shoulder, each side of
// the pelvis and each hand. A pose moves such a ball as a whole at the scale of millimetres, so
// its tets turn far inside out, and the untangling did not bring them back.
// They carry no voxel of their own. Each short edge (u, v) is collapsed by moving u onto v, when
// that keeps the mesh a manifold (the link condition of Dey et al., with the boundary coned to a
// vertex at infinity) and leaves no tet around u flatter than the flattest one there before (or
// than a floor). The surface and the label interfaces move by at most the edge's length.
#include "repose/mesh/TransferMesh.h"

#include <Eigen/Dense>

#include <algorithm>
#include <array>
#include <cmath>
#include <set>
#include <utility>
#include <vector>

namespace repose {
namespace {

// 6 sqrt(2) V / l_max^3: 1 for the regular tet, 0 for a flat one, negative inside out.
double shapeQuality(const std::array<Eigen::Vector3d, 4>& x) {
  const double v = (x[1] - x[0]).cross(x[2] - x[0]).dot(x[3] - x[0]) / 6;
  double longest = 0;
  for (int a = 0; a < 4; ++a)
    for (int b = a + 1; b < 4; ++b)
      longest = std::max(longest, (x[std::size_t(a)] - x[std::size_t(b)]).norm());
  return longest > 0 ? 6 * std::sqrt(2.0) * v / (longest * longest * longest) : 0;
}

class Collapser {
 public:
  explicit Collapser(TransferMesh& mesh) : mesh_(mesh), infinity_(int(mesh.vertices.rows())) {
    const Eigen::Index nt = mesh.tets.rows();
    alive_.assign(std::size_t(nt), 1);
    around_.resize(std::size_t(mesh.vertices.rows()));
    for (Eigen::Index t = 0; t < nt; ++t)
      for (int k = 0; k < 4; ++k) around_[std::size_t(mesh.tets(t, k))].push_back(int(t));
  }

  // Moves u onto v if the mesh stays a manifold and no tet around u gets flatter than `floor` or
  // than the flattest there now.
  bool collapse(int u, int v, double floor) {
    if (!linked(u, v) || !linkCondition(u, v)) return false;
    double worstBefore = 1;
    for (const int t : around_[std::size_t(u)])
      if (alive_[std::size_t(t)]) worstBefore = std::min(worstBefore, shapeQuality(corners(t)));
    const double bound = std::min(floor, worstBefore);
    for (const int t : around_[std::size_t(u)]) {
      if (!alive_[std::size_t(t)] || contains(t, v)) continue;
      auto x = corners(t);
      for (int k = 0; k < 4; ++k)
        if (mesh_.tets(t, k) == u) x[std::size_t(k)] = mesh_.vertices.row(v).transpose();
      const double q = shapeQuality(x);
      if (!(q > 0) || q < bound) return false;
    }
    for (const int t : around_[std::size_t(u)]) {
      if (!alive_[std::size_t(t)]) continue;
      if (contains(t, v)) {
        alive_[std::size_t(t)] = 0;
        continue;
      }
      for (int k = 0; k < 4; ++k)
        if (mesh_.tets(t, k) == u) mesh_.tets(t, k) = v;
      around_[std::size_t(v)].push_back(t);
    }
    around_[std::size_t(u)].clear();
    return true;
  }

  bool linked(int u, int v) const {
    for (const int t : around_[std::size_t(u)])
      if (alive_[std::size_t(t)] && contains(t, v)) return true;
    return false;
  }

  // Drops the collapsed tets and the vertices no tet uses (keeping the order of the rest).
  int compact() {
    Eigen::Index kept = 0;
    for (Eigen::Index t = 0; t < mesh_.tets.rows(); ++t) {
      if (!alive_[std::size_t(t)]) continue;
      mesh_.tets.row(kept) = mesh_.tets.row(t);
      mesh_.labels[kept] = mesh_.labels[t];
      if (!mesh_.rigid.empty()) mesh_.rigid[std::size_t(kept)] = mesh_.rigid[std::size_t(t)];
      ++kept;
    }
    const int removed = int(mesh_.tets.rows() - kept);
    mesh_.tets.conservativeResize(kept, 4);
    mesh_.labels.conservativeResize(kept);
    if (!mesh_.rigid.empty()) mesh_.rigid.resize(std::size_t(kept));
    std::vector<int> index(std::size_t(mesh_.vertices.rows()), -1);
    for (Eigen::Index t = 0; t < kept; ++t)
      for (int k = 0; k < 4; ++k) index[std::size_t(mesh_.tets(t, k))] = 0;
    int n = 0;
    for (std::size_t w = 0; w < index.size(); ++w)
      if (index[w] == 0)
        mesh_.vertices.row(n) = mesh_.vertices.row(Eigen::Index(w)), index[w] = n++;
    mesh_.vertices.conservativeResize(n, 3);
    for (Eigen::Index t = 0; t < kept; ++t)
      for (int k = 0; k < 4; ++k) mesh_.tets(t, k) = index[std::size_t(mesh_.tets(t, k))];
    return removed;
  }

 private:
  using Simplex = std::array<int, 3>;  // sorted, -1 padded (vertex, edge, triangle)

  bool contains(int t, int w) const {
    for (int k = 0; k < 4; ++k)
      if (mesh_.tets(t, k) == w) return true;
    return false;
  }
  std::array<Eigen::Vector3d, 4> corners(int t) const {
    std::array<Eigen::Vector3d, 4> x;
    for (int k = 0; k < 4; ++k)
      x[std::size_t(k)] = mesh_.vertices.row(mesh_.tets(t, k)).transpose();
    return x;
  }
  // A face of tet t (its corners but `skip`) is on the boundary when no other tet has it.
  bool boundaryFace(int t, int skip) const {
    std::array<int, 3> f{};
    int n = 0;
    for (int k = 0; k < 4; ++k)
      if (k != skip) f[std::size_t(n++)] = mesh_.tets(t, k);
    for (const int s : around_[std::size_t(f[0])])
      if (s != t && alive_[std::size_t(s)] && contains(s, f[1]) && contains(s, f[2])) return false;
    return true;
  }
  static Simplex simplex(int a, int b = -1, int c = -1) {
    Simplex s{a, b, c};
    std::sort(s.begin(), s.end(), [](int x, int y) {
      return (x < 0) != (y < 0) ? x >= 0 : x < y;  // -1 last
    });
    return s;
  }
  static void addFace(std::set<Simplex>& link, int a, int b, int c) {
    link.insert(simplex(a, b, c));
    link.insert(simplex(a, b)), link.insert(simplex(b, c)), link.insert(simplex(a, c));
    link.insert(simplex(a)), link.insert(simplex(b)), link.insert(simplex(c));
  }
  // The link of vertex u: the faces opposite u in its tets, and for each boundary face around u
  // the cone of its edge opposite u to the vertex at infinity.
  std::set<Simplex> vertexLink(int u) const {
    std::set<Simplex> link;
    for (const int t : around_[std::size_t(u)]) {
      if (!alive_[std::size_t(t)]) continue;
      std::array<int, 3> o{};
      int n = 0, at = 0;
      for (int k = 0; k < 4; ++k)
        if (mesh_.tets(t, k) != u)
          o[std::size_t(n++)] = mesh_.tets(t, k);
        else
          at = k;
      addFace(link, o[0], o[1], o[2]);
      for (int k = 0; k < 4; ++k) {
        if (k == at || !boundaryFace(t, k)) continue;
        std::array<int, 2> e{};
        int m = 0;
        for (int j = 0; j < 4; ++j)
          if (j != k && j != at) e[std::size_t(m++)] = mesh_.tets(t, j);
        addFace(link, e[0], e[1], infinity_);
      }
    }
    return link;
  }
  std::set<Simplex> edgeLink(int u, int v) const {
    std::set<Simplex> link;
    for (const int t : around_[std::size_t(u)]) {
      if (!alive_[std::size_t(t)] || !contains(t, v)) continue;
      std::array<int, 2> o{};
      int n = 0;
      for (int k = 0; k < 4; ++k)
        if (mesh_.tets(t, k) != u && mesh_.tets(t, k) != v) o[std::size_t(n++)] = mesh_.tets(t, k);
      link.insert(simplex(o[0], o[1])), link.insert(simplex(o[0])), link.insert(simplex(o[1]));
      for (int k = 0; k < 4; ++k) {
        const int w = mesh_.tets(t, k);
        if (w == u || w == v || !boundaryFace(t, k)) continue;
        // The face without w holds u, v and the other corner: its edge opposite (u, v) is that
        // corner to infinity.
        const int other = o[0] == w ? o[1] : o[0];
        link.insert(simplex(other, infinity_)), link.insert(simplex(infinity_));
      }
    }
    return link;
  }
  bool linkCondition(int u, int v) const {
    const std::set<Simplex> lu = vertexLink(u), lv = vertexLink(v), luv = edgeLink(u, v);
    for (const Simplex& s : lu) {
      if (std::find(s.begin(), s.end(), u) != s.end() ||
          std::find(s.begin(), s.end(), v) != s.end())
        continue;  // u and v are in each other's link, not in the edge's
      if (lv.count(s) && !luv.count(s)) return false;
    }
    return true;
  }

  TransferMesh& mesh_;
  const int infinity_;
  std::vector<char> alive_;
  std::vector<std::vector<int>> around_;
};

}  // namespace

int collapseShortEdges(TransferMesh& mesh, double minEdgeMm, double qualityFloor) {
  if (!(minEdgeMm > 0) || mesh.tets.rows() == 0) return 0;
  Collapser collapser(mesh);
  int collapsed = 0;
  for (int pass = 0; pass < 8; ++pass) {
    std::vector<std::pair<double, std::pair<int, int>>> edges;
    std::set<std::pair<int, int>> seen;
    for (Eigen::Index t = 0; t < mesh.tets.rows(); ++t)
      for (int a = 0; a < 4; ++a)
        for (int b = a + 1; b < 4; ++b) {
          const int u = std::min(mesh.tets(t, a), mesh.tets(t, b)),
                    v = std::max(mesh.tets(t, a), mesh.tets(t, b));
          const double l = (mesh.vertices.row(u) - mesh.vertices.row(v)).norm();
          if (l < minEdgeMm && seen.insert({u, v}).second) edges.push_back({l, {u, v}});
        }
    std::sort(edges.begin(), edges.end());
    int now = 0;
    for (const auto& [length, e] : edges) {
      const auto [a, b] = e;
      if (!collapser.linked(a, b)) continue;  // a vertex of it went in an earlier collapse
      if (collapser.collapse(a, b, qualityFloor) || collapser.collapse(b, a, qualityFloor)) ++now;
    }
    collapsed += now;
    if (now == 0) break;
  }
  collapser.compact();
  return collapsed;
}

}  // namespace repose
