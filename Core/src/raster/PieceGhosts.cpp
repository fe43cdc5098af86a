#include "PieceGhosts.h"

#include <Eigen/LU>
#include <algorithm>
#include <cmath>
#include <limits>
#include <map>
#include <set>
#include <utility>

namespace repose::raster {

std::vector<PieceGhost> pieceGhosts(const TransferMesh& mesh, const Volume& pieceLabels,
                                    const std::vector<int>& pieceOf, const Volume* restParts,
                                    int rings) {
  std::vector<PieceGhost> out;
  const Eigen::Index nt = mesh.tets.rows(), nv = mesh.vertices.rows();
  if (mesh.rigid.size() != std::size_t(nt) || nt == 0) return out;
  if (restParts && restParts->dims() != pieceLabels.dims()) restParts = nullptr;
  const Eigen::Matrix4d toIjk = pieceLabels.geometry().ijkToRas.inverse();
  const auto d = pieceLabels.dims();
  // A piece's tissue where it is held: (piece, body part of its voxels).
  using Held = std::pair<int, int>;
  auto heldAt = [&](const Eigen::Vector3d& ras, int ownPart) -> Held {
    const Eigen::Vector3d p = toIjk.block<3, 3>(0, 0) * ras + toIjk.block<3, 1>(0, 3);
    std::int64_t x[3];
    for (int c = 0; c < 3; ++c) {
      x[c] = std::int64_t(std::floor(p[c] + 0.5));
      if (x[c] < 0 || x[c] >= d[c]) return {0, 0};
    }
    const std::int64_t at = pieceLabels.index(x[0], x[1], x[2]);
    const double v = pieceLabels.valueAsDouble(at);
    const int piece = v > 0 && v < double(pieceOf.size()) ? pieceOf[std::size_t(v)] : 0;
    if (!piece) return {0, 0};
    return {piece, restParts ? int(restParts->valueAsDouble(at)) : ownPart};
  };
  // Per soft tet, the pieces its rest volume holds (usually none or one). Per piece tet, the
  // pieces of other body parts it holds: Mesh_3 lets a bone of one part into another part's piece
  // tets where they lie on each other (a scapula's tets on the ribs of an 8 mm grid); the piece
  // tet does not write them (Rasterizer.cpp, foreignPiece), so their own part's ghost does. A
  // bone one voxel thick can slip between 13 samples, and the piece tets are few: theirs are also
  // sampled on a lattice of about half a voxel.
  const double voxelMm = pieceLabels.geometry().spacing().minCoeff();
  std::vector<std::vector<Held>> holds(static_cast<std::size_t>(nt));
  bool any = false;
  for (Eigen::Index t = 0; t < nt; ++t) {
    const bool piece = mesh.rigid[std::size_t(t)] != 0;
    if (piece && !restParts) continue;
    Eigen::Vector3d x[4], c = Eigen::Vector3d::Zero();
    for (int k = 0; k < 4; ++k) c += (x[k] = mesh.vertices.row(mesh.tets(t, k)).transpose());
    c /= 4;
    std::set<Held> found;
    auto sample = [&](const Eigen::Vector3d& ras) {
      const Held h = heldAt(ras, mesh.labels[t]);
      if (h.first && (!piece || h.second != mesh.labels[t])) found.insert(h);
    };
    sample(c);
    for (int k = 0; k < 4; ++k) {
      sample(0.5 * (c + x[k]));
      const Eigen::Vector3d face = (4 * c - x[k]) / 3;  // the centre of the face opposite k
      sample(face + 0.25 * (c - face));
    }
    if (piece) {
      double edge = 0;
      for (int a = 0; a < 4; ++a)
        for (int b = a + 1; b < 4; ++b) edge = std::max(edge, (x[a] - x[b]).norm());
      const int n = std::clamp(int(std::ceil(2 * edge / voxelMm)), 2, 16);
      for (int a = 0; a <= n; ++a)
        for (int b = 0; a + b <= n; ++b)
          for (int e = 0; a + b + e <= n; ++e)
            sample((double(a) * x[1] + double(b) * x[2] + double(e) * x[3] +
                    double(n - a - b - e) * x[0]) /
                   double(n));
    }
    holds[std::size_t(t)].assign(found.begin(), found.end());
    any = any || !found.empty();
  }
  if (!any) return out;
  // Tets around each vertex (CSR).
  std::vector<std::int64_t> start(std::size_t(nv) + 1, 0);
  for (Eigen::Index t = 0; t < nt; ++t)
    for (int k = 0; k < 4; ++k) ++start[std::size_t(mesh.tets(t, k)) + 1];
  for (std::size_t v = 0; v < std::size_t(nv); ++v) start[v + 1] += start[v];
  std::vector<std::int32_t> around(std::size_t(start.back()));
  {
    std::vector<std::int64_t> fill(start.begin(), start.end() - 1);
    for (Eigen::Index t = 0; t < nt; ++t)
      for (int k = 0; k < 4; ++k)
        around[std::size_t(fill[std::size_t(mesh.tets(t, k))]++)] = std::int32_t(t);
  }
  // Hosts spread from the piece's own tets through the soft tets holding it, ring by ring: a
  // demoted bone end can be a layer of tets deep. A piece of one body part hosts only its own
  // part's voxels (a bone label of both sides is two pieces moving apart).
  std::vector<std::map<Held, std::int32_t>> host(static_cast<std::size_t>(nt));
  for (Eigen::Index t = 0; t < nt; ++t)
    if (const int p = mesh.rigid[std::size_t(t)])
      host[std::size_t(t)][{p, mesh.labels[t]}] = std::int32_t(t);
  for (int ring = 0; ring < rings; ++ring) {
    std::vector<std::pair<std::int32_t, std::pair<Held, std::int32_t>>> found;
    for (Eigen::Index t = 0; t < nt; ++t)
      for (const Held& h : holds[std::size_t(t)]) {
        if (host[std::size_t(t)].count(h)) continue;
        std::int32_t by = -1;
        for (int k = 0; k < 4 && by < 0; ++k) {
          const std::size_t v = std::size_t(mesh.tets(t, k));
          for (std::int64_t a = start[v]; a < start[v + 1] && by < 0; ++a) {
            const auto it = host[std::size_t(around[std::size_t(a)])].find(h);
            if (it != host[std::size_t(around[std::size_t(a)])].end()) by = it->second;
          }
        }
        if (by >= 0) found.push_back({std::int32_t(t), {h, by}});
      }
    if (found.empty()) break;
    for (const auto& [t, hb] : found) host[std::size_t(t)].insert(hb);
  }
  // A soft tet holding a piece that no piece tet reaches within the rings (a rib one voxel thick
  // on 8 mm slices, which Mesh_3 gives a handful of tets of its own; a pelvis in the torso's
  // tets) takes any tet of that piece in its body part as host: a piece moves whole with one
  // group, so every one of its tets has the same rigid map. Without, such a bone bent with the
  // soft tissue around it (the ribs' Dice 0.65 under arms raised 160 degrees on the ICRP adult
  // male's grid).
  std::map<Held, std::int32_t> anyTetOf;  // (piece, body part) -> a tet of it
  for (Eigen::Index t = 0; t < nt; ++t)
    if (const int p = mesh.rigid[std::size_t(t)])
      anyTetOf.try_emplace({p, mesh.labels[t]}, std::int32_t(t));
  // A bone with no tet of its own in that part moves with the part's nearest piece tet: every
  // piece of a body part moves with the part's group. Mesh_3 gives a one-voxel bone tets or none
  // as the labels around it change: the ICRP grid's ribs got none once its phantom had one-voxel
  // limb vessels and the sacrum up to its disc, and both arms up 160 degrees bent them with the
  // chest wall.
  std::map<int, std::vector<std::pair<Eigen::Vector3d, std::int32_t>>> piecesOfPart;
  auto centroid = [&](Eigen::Index t) {
    Eigen::Vector3d c = Eigen::Vector3d::Zero();
    for (int k = 0; k < 4; ++k) c += mesh.vertices.row(mesh.tets(t, k)).transpose();
    return Eigen::Vector3d(c / 4);
  };
  for (Eigen::Index t = 0; t < nt; ++t)
    if (mesh.rigid[std::size_t(t)])
      piecesOfPart[mesh.labels[t]].push_back({centroid(t), std::int32_t(t)});
  for (Eigen::Index t = 0; t < nt; ++t)
    for (const Held& h : holds[std::size_t(t)]) {
      if (host[std::size_t(t)].count(h)) continue;
      if (const auto it = anyTetOf.find(h); it != anyTetOf.end()) {
        host[std::size_t(t)][h] = it->second;
        continue;
      }
      const auto part = piecesOfPart.find(h.second);
      if (part == piecesOfPart.end()) continue;
      const Eigen::Vector3d c = centroid(t);
      double best = std::numeric_limits<double>::infinity();
      std::int32_t nearest = -1;
      for (const auto& [at, u] : part->second)
        if (const double d2 = (at - c).squaredNorm(); d2 < best) best = d2, nearest = u;
      host[std::size_t(t)][h] = nearest;
    }
  for (Eigen::Index t = 0; t < nt; ++t)
    for (const auto& [h, by] : host[std::size_t(t)])
      if (by != std::int32_t(t) && by >= 0) out.push_back({std::int32_t(t), by});
  return out;
}

ScanInput ghostScanInput(const ScanInput& in, const std::vector<PieceGhost>& ghosts,
                         Eigen::MatrixX4i& tets) {
  ScanInput g;
  g.dims = in.dims;
  tets.resize(Eigen::Index(ghosts.size()), 4);
  g.tets = &tets;
  g.out.reserve(4 * ghosts.size());
  g.rest.reserve(4 * ghosts.size());
  const Eigen::MatrixX4i& T = *in.tets;
  for (std::size_t n = 0; n < ghosts.size(); ++n) {
    // The host's map from rest (input IJK) to output IJK: affine, and rigid in RAS.
    const std::int32_t h = ghosts[n].host;
    Eigen::Matrix3d R, O;
    for (int c = 0; c < 3; ++c) {
      R.col(c) = in.rest[std::size_t(T(h, c + 1))] - in.rest[std::size_t(T(h, 0))];
      O.col(c) = in.out[std::size_t(T(h, c + 1))] - in.out[std::size_t(T(h, 0))];
    }
    const Eigen::Matrix3d B = O * R.inverse();
    const Eigen::Vector3d r0 = in.rest[std::size_t(T(h, 0))], o0 = in.out[std::size_t(T(h, 0))];
    for (int k = 0; k < 4; ++k) {
      const Eigen::Vector3d& r = in.rest[std::size_t(T(ghosts[n].soft, k))];
      tets(Eigen::Index(n), k) = int(g.out.size());
      g.rest.push_back(r);
      g.out.push_back(o0 + B * (r - r0));
    }
  }
  return g;
}

}  // namespace repose::raster
