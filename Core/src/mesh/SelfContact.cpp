// SelfContactFinder: surface vertices inside the posed tets of another layer of tissue, each with
// the nearest point of that layer's surface (SelfContact.h). Two dense bucket grids over the posed
// positions (the candidate vertices, then the surface faces), a cell of the surface's mean edge.
#include "repose/mesh/SelfContact.h"

#include "repose/cage/TriangleClosestPoint.h"

#include <Eigen/Dense>

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <unordered_map>

namespace repose {

namespace {

// Items bucketed by the cells their boxes cover, as one array per cell (CSR).
struct BucketGrid {
  Eigen::Vector3d origin = Eigen::Vector3d::Zero();
  double cell = 1;
  std::array<int, 3> size{1, 1, 1};
  std::vector<int> start, items;

  std::array<int, 3> cellOf(const Eigen::Vector3d& p) const {
    std::array<int, 3> c{};
    for (int k = 0; k < 3; ++k)
      c[std::size_t(k)] =
          std::clamp(int(std::floor((p[k] - origin[k]) / cell)), 0, size[std::size_t(k)] - 1);
    return c;
  }
  std::size_t at(int i, int j, int k) const {
    return (std::size_t(k) * std::size_t(size[1]) + std::size_t(j)) * std::size_t(size[0]) +
           std::size_t(i);
  }
  // Boxes (lo, hi) per item; the grid spans all of them.
  void build(const std::vector<std::pair<Eigen::Vector3d, Eigen::Vector3d>>& boxes, double cellMm) {
    cell = cellMm;
    Eigen::Vector3d lo = Eigen::Vector3d::Constant(std::numeric_limits<double>::max());
    Eigen::Vector3d hi = -lo;
    for (const auto& [a, b] : boxes) lo = lo.cwiseMin(a), hi = hi.cwiseMax(b);
    if (boxes.empty()) lo = hi = Eigen::Vector3d::Zero();
    origin = lo;
    for (int k = 0; k < 3; ++k)
      size[std::size_t(k)] = std::max(1, int(std::ceil((hi[k] - lo[k]) / cell)) + 1);
    const std::size_t cells = std::size_t(size[0]) * std::size_t(size[1]) * std::size_t(size[2]);
    std::vector<int> count(cells + 1, 0);
    auto each = [&](const std::pair<Eigen::Vector3d, Eigen::Vector3d>& box, auto&& f) {
      const auto a = cellOf(box.first), b = cellOf(box.second);
      for (int k = a[2]; k <= b[2]; ++k)
        for (int j = a[1]; j <= b[1]; ++j)
          for (int i = a[0]; i <= b[0]; ++i) f(at(i, j, k));
    };
    for (const auto& box : boxes) each(box, [&](std::size_t c) { ++count[c + 1]; });
    for (std::size_t c = 0; c < cells; ++c) count[c + 1] += count[c];
    start = count;
    items.assign(std::size_t(count[cells]), 0);
    for (std::size_t n = 0; n < boxes.size(); ++n)
      each(boxes[n], [&](std::size_t c) { items[std::size_t(count[c]++)] = int(n); });
  }
};

}  // namespace

SelfContactFinder::SelfContactFinder(const TransferMesh& mesh, SelfContactOptions options)
    : rest_(mesh.vertices), tets_(mesh.tets), options_(options) {
  const Eigen::Index nv = mesh.vertices.rows(), nt = mesh.tets.rows();
  // The surface: faces of one tet only (every face sorted, then runs of one).
  std::vector<std::array<int, 3>> all;
  all.reserve(std::size_t(4 * nt));
  for (Eigen::Index t = 0; t < nt; ++t)
    for (int skip = 0; skip < 4; ++skip) {
      std::array<int, 3> f{};
      int n = 0;
      for (int k = 0; k < 4; ++k)
        if (k != skip) f[std::size_t(n++)] = mesh.tets(t, k);
      std::sort(f.begin(), f.end());
      all.push_back(f);
    }
  std::sort(all.begin(), all.end());
  std::vector<char> onSurface(std::size_t(nv), 0);
  double edgeSum = 0;
  for (std::size_t i = 0; i < all.size();) {
    std::size_t j = i + 1;
    while (j < all.size() && all[j] == all[i]) ++j;
    const std::size_t count = j - i;
    const std::array<int, 3> f = all[i];
    i = j;
    if (count != 1) continue;
    surfaceFaces_.push_back(f);
    for (int k = 0; k < 3; ++k) {
      onSurface[std::size_t(f[std::size_t(k)])] = 1;
      edgeSum +=
          (mesh.vertices.row(f[std::size_t(k)]) - mesh.vertices.row(f[std::size_t((k + 1) % 3)]))
              .norm();
    }
  }
  for (Eigen::Index v = 0; v < nv; ++v)
    if (onSurface[std::size_t(v)]) surfaceVertices_.push_back(int(v));
  cellMm_ = surfaceFaces_.empty() ? 1.0 : std::max(1e-3, edgeSum / (3.0 * surfaceFaces_.size()));
  // Each vertex's neighbours through the tets' edges (sorted, unique), for the rings of own layer.
  std::vector<std::vector<int>> near{std::size_t(nv)};
  for (Eigen::Index t = 0; t < nt; ++t)
    for (int a = 0; a < 4; ++a)
      for (int b = 0; b < 4; ++b)
        if (a != b) near[std::size_t(mesh.tets(t, a))].push_back(mesh.tets(t, b));
  adjacencyStart_.assign(std::size_t(nv) + 1, 0);
  for (Eigen::Index v = 0; v < nv; ++v) {
    auto& n = near[std::size_t(v)];
    std::sort(n.begin(), n.end());
    n.erase(std::unique(n.begin(), n.end()), n.end());
    adjacencyStart_[std::size_t(v) + 1] = adjacencyStart_[std::size_t(v)] + int(n.size());
  }
  adjacency_.reserve(std::size_t(adjacencyStart_.back()));
  for (const auto& n : near) adjacency_.insert(adjacency_.end(), n.begin(), n.end());
}

std::vector<SelfContact> SelfContactFinder::find(const Eigen::MatrixX3d& posed,
                                                 const std::vector<char>* candidates) const {
  std::vector<int> tested;
  for (const int v : surfaceVertices_)
    if (!candidates || (*candidates)[std::size_t(v)]) tested.push_back(v);
  std::vector<SelfContact> contacts;
  if (tested.empty()) return contacts;
  // The tested vertices in cells; each posed tet looks up the cells its box covers.
  std::vector<std::pair<Eigen::Vector3d, Eigen::Vector3d>> points;
  points.reserve(tested.size());
  for (const int v : tested) {
    const Eigen::Vector3d p = posed.row(v).transpose();
    points.emplace_back(p, p);
  }
  BucketGrid vertexGrid;
  vertexGrid.build(points, cellMm_);
  Eigen::Vector3d testedLo = points.front().first, testedHi = testedLo;
  for (const auto& [p, q] : points)
    testedLo = testedLo.cwiseMin(p), testedHi = testedHi.cwiseMax(q);
  // Each vertex's own layer (the vertices within `ownRings` edges), found when first needed.
  std::unordered_map<int, std::vector<int>> rings;
  std::vector<int> stamp(std::size_t(rest_.rows()), -1);
  auto ringOf = [&](int v) -> const std::vector<int>& {
    auto [it, added] = rings.try_emplace(v);
    if (!added) return it->second;
    std::vector<int>& ring = it->second;
    ring.push_back(v);
    stamp[std::size_t(v)] = v;
    std::size_t begin = 0;
    for (int r = 0; r < options_.ownRings; ++r) {
      const std::size_t end = ring.size();
      for (std::size_t i = begin; i < end; ++i)
        for (int e = adjacencyStart_[std::size_t(ring[i])];
             e < adjacencyStart_[std::size_t(ring[i]) + 1]; ++e) {
          const int w = adjacency_[std::size_t(e)];
          if (stamp[std::size_t(w)] != v) stamp[std::size_t(w)] = v, ring.push_back(w);
        }
      begin = end;
    }
    std::sort(ring.begin(), ring.end());
    return ring;
  };
  auto ownLayer = [&](int v, std::initializer_list<int> corners) {
    const std::vector<int>& ring = ringOf(v);
    for (const int c : corners)
      if (std::binary_search(ring.begin(), ring.end(), c)) return true;
    return false;
  };
  std::vector<char> inside(tested.size(), 0);
  for (Eigen::Index t = 0; t < tets_.rows(); ++t) {
    std::array<Eigen::Vector3d, 4> x;
    for (int k = 0; k < 4; ++k) x[std::size_t(k)] = posed.row(tets_(t, k)).transpose();
    Eigen::Vector3d lo = x[0], hi = x[0];
    for (const auto& p : x) lo = lo.cwiseMin(p), hi = hi.cwiseMax(p);
    // Most tets are nowhere near the few vertices tested (the restoration's zone).
    if ((hi.array() < testedLo.array()).any() || (lo.array() > testedHi.array()).any()) continue;
    Eigen::Matrix3d E;
    for (int c = 0; c < 3; ++c) E.col(c) = x[std::size_t(c) + 1] - x[0];
    const double det = E.determinant();
    if (!(det > 0)) continue;  // inside out: the untangling's
    const auto a = vertexGrid.cellOf(lo), b = vertexGrid.cellOf(hi);
    const Eigen::Matrix3d inverse = E.inverse();
    for (int k = a[2]; k <= b[2]; ++k)
      for (int j = a[1]; j <= b[1]; ++j)
        for (int i = a[0]; i <= b[0]; ++i) {
          const std::size_t c = vertexGrid.at(i, j, k);
          for (int s = vertexGrid.start[c]; s < vertexGrid.start[c + 1]; ++s) {
            const int n = vertexGrid.items[std::size_t(s)];
            if (inside[std::size_t(n)]) continue;
            const int v = tested[std::size_t(n)];
            if (v == tets_(t, 0) || v == tets_(t, 1) || v == tets_(t, 2) || v == tets_(t, 3))
              continue;
            const Eigen::Vector3d p = posed.row(v).transpose();
            if ((p.array() < lo.array()).any() || (p.array() > hi.array()).any()) continue;
            const Eigen::Vector3d w = inverse * (p - x[0]);
            const double w0 = 1 - w.sum();
            // Inside or on the tet: a vertex on a face shared by two tets of the other layer
            // lies strictly inside neither. One merely touching the other layer (the two sides
            // of a cut at rest) is on its surface: depth 0, no contact (below).
            constexpr double kOn = 1e-9;
            if (w.minCoeff() < -kOn || w0 < -kOn) continue;
            if (ownLayer(v, {tets_(t, 0), tets_(t, 1), tets_(t, 2), tets_(t, 3)})) continue;
            inside[std::size_t(n)] = 1;
          }
        }
  }
  std::vector<int> overlapping;
  for (std::size_t n = 0; n < tested.size(); ++n)
    if (inside[n]) overlapping.push_back(tested[n]);
  if (overlapping.empty()) return contacts;

  // The way out: the nearest surface face of another layer (no corner in the vertex's rings).
  std::vector<std::pair<Eigen::Vector3d, Eigen::Vector3d>> boxes;
  boxes.reserve(surfaceFaces_.size());
  for (const auto& f : surfaceFaces_) {
    Eigen::Vector3d lo = posed.row(f[0]).transpose(), hi = lo;
    for (int k = 1; k < 3; ++k) {
      lo = lo.cwiseMin(posed.row(f[std::size_t(k)]).transpose());
      hi = hi.cwiseMax(posed.row(f[std::size_t(k)]).transpose());
    }
    boxes.emplace_back(lo, hi);
  }
  BucketGrid faceGrid;
  faceGrid.build(boxes, cellMm_);
  std::vector<int> seen(surfaceFaces_.size(), -1);
  constexpr int kMaxRings = 12;
  for (const int v : overlapping) {
    const Eigen::Vector3d p = posed.row(v).transpose();
    const auto centre = faceGrid.cellOf(p);
    double best = std::numeric_limits<double>::max();
    Eigen::Vector3d bestPoint = p;
    for (int ring = 0; ring <= kMaxRings; ++ring) {
      // The cells at Chebyshev distance `ring` from the vertex's own.
      for (int k = centre[2] - ring; k <= centre[2] + ring; ++k)
        for (int j = centre[1] - ring; j <= centre[1] + ring; ++j)
          for (int i = centre[0] - ring; i <= centre[0] + ring; ++i) {
            if (std::max({std::abs(i - centre[0]), std::abs(j - centre[1]),
                          std::abs(k - centre[2])}) != ring)
              continue;
            if (i < 0 || j < 0 || k < 0 || i >= faceGrid.size[0] || j >= faceGrid.size[1] ||
                k >= faceGrid.size[2])
              continue;
            const std::size_t c = faceGrid.at(i, j, k);
            for (int s = faceGrid.start[c]; s < faceGrid.start[c + 1]; ++s) {
              const int f = faceGrid.items[std::size_t(s)];
              if (seen[std::size_t(f)] == v) continue;
              seen[std::size_t(f)] = v;
              const auto& tri = surfaceFaces_[std::size_t(f)];
              if (ownLayer(v, {tri[0], tri[1], tri[2]})) continue;
              const Eigen::Vector3d a = posed.row(tri[0]).transpose(),
                                    b = posed.row(tri[1]).transpose(),
                                    d = posed.row(tri[2]).transpose();
              const Eigen::Vector3d wp = closestPointWeights(p, a, b, d);
              const Eigen::Vector3d q = wp[0] * a + wp[1] * b + wp[2] * d;
              const double distance = (q - p).norm();
              if (distance < best) best = distance, bestPoint = q;
            }
          }
      // Every face nearer than `ring` cells has been seen.
      if (best <= ring * faceGrid.cell) break;
    }
    if (best == std::numeric_limits<double>::max() || best <= 0) continue;
    SelfContact contact;
    contact.vertex = v;
    contact.point = bestPoint;
    contact.normal = (bestPoint - p) / best;
    contact.depthMm = best;
    contacts.push_back(contact);
  }
  return contacts;
}

}  // namespace repose
