#include "repose/mesh/RigidHandles.h"

#include "repose/mesh/TetAdjacency.h"
#include "repose/cage/TriangleClosestPoint.h"
#include "repose/numerics/SparseCholesky.h"
#include "repose/util/Error.h"
#include "repose/util/Parallel.h"

#include <Eigen/SparseCore>
#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <map>
#include <string>

namespace repose {

int handleGroupOfPart(const std::vector<RigidHandle>& handles, int part) {
  for (std::size_t g = 0; g < handles.size(); ++g)
    if (std::find(handles[g].parts.begin(), handles[g].parts.end(), part) != handles[g].parts.end())
      return int(g);
  return -1;
}
namespace {

// Cage vertex -> group index (or -1), checking the handle list.
std::vector<int> cageOwners(Eigen::Index cageVertices, const std::vector<RigidHandle>& handles) {
  std::vector<int> owner(cageVertices, -1);
  for (std::size_t g = 0; g < handles.size(); ++g)
    for (const int v : handles[g].cageVertices) {
      if (v < 0 || v >= cageVertices)
        throw Error("handle group " + std::to_string(g) + ": cage vertex " + std::to_string(v) +
                    " out of range (the cage has " + std::to_string(cageVertices) + ")");
      if (owner[v] >= 0)
        throw Error("cage vertex " + std::to_string(v) + " is in handle groups " +
                    std::to_string(owner[v]) + " and " + std::to_string(g));
      owner[v] = static_cast<int>(g);
    }
  return owner;
}

// Bones move as whole pieces. Each piece of rigid tissue (tets of one bone label connected
// through faces: a humerus, not the humerus and the scapula it touches) is given to the group
// that selects its body part, else (a piece across parts, or groups of cage vertices) to the
// group that carries most of it (tet volume times the mean membership of the tet's vertices), and
// every vertex of the piece takes that group alone. A vertex shared by pieces given to different
// groups (where two bones touch across a joint) splits evenly between them. The bend of a joint
// then happens in the soft tissue around the bones, never through a bone end.
void lockRigidTissue(const TransferMesh& mesh, const std::vector<RigidHandle>& handles,
                     Eigen::MatrixXd& membership) {
  const Eigen::Index nt = mesh.tets.rows(), groups = membership.cols();
  const TetAdjacency adjacency = TetAdjacency::build(mesh);
  std::vector<int> piece(std::size_t(nt), -1);
  int pieces = 0;
  for (Eigen::Index seed = 0; seed < nt; ++seed) {
    if (!mesh.rigid[seed] || piece[seed] >= 0) continue;
    std::vector<int> stack{int(seed)};
    piece[seed] = pieces;
    while (!stack.empty()) {
      const int t = stack.back();
      stack.pop_back();
      for (const int u : adjacency.faceNeighbours[t])
        if (mesh.rigid[u] == mesh.rigid[t] && piece[u] < 0) piece[u] = pieces, stack.push_back(u);
    }
    ++pieces;
  }
  if (pieces == 0) return;
  Eigen::MatrixXd vote = Eigen::MatrixXd::Zero(pieces, groups);
  for (Eigen::Index t = 0; t < nt; ++t) {
    if (piece[t] < 0) continue;
    Eigen::RowVectorXd mean = Eigen::RowVectorXd::Zero(groups);
    for (int k = 0; k < 4; ++k) mean += membership.row(mesh.tets(t, k));
    vote.row(piece[t]) += std::fabs(tetVolume(mesh.vertices, mesh.tets.row(t))) * mean / 4;
  }
  // A piece lying in one body part goes with the group that selects that part: a thin bone
  // in a small part (a clavicle in its girdle) is mostly surrounded by its neighbours' tissue,
  // and with widened joints their memberships would outvote its own part's group.
  std::vector<int> onlyPart(std::size_t(pieces), 0);  // its one part, -1 for several
  for (Eigen::Index t = 0; t < nt; ++t) {
    if (piece[t] < 0) continue;
    int& p = onlyPart[std::size_t(piece[t])];
    p = p == 0 ? mesh.labels[t] : (p == mesh.labels[t] ? p : -1);
  }
  std::vector<int> carrier(std::size_t(pieces), -1);
  for (int b = 0; b < pieces; ++b) {
    for (std::size_t g = 0; g < handles.size() && onlyPart[std::size_t(b)] > 0; ++g)
      if (std::find(handles[g].parts.begin(), handles[g].parts.end(), onlyPart[std::size_t(b)]) !=
          handles[g].parts.end())
        carrier[std::size_t(b)] = int(g);
    Eigen::Index g = 0;
    if (carrier[std::size_t(b)] < 0 && vote.row(b).maxCoeff(&g) > 0)
      carrier[std::size_t(b)] = int(g);
  }
  Eigen::MatrixXd locked = Eigen::MatrixXd::Zero(membership.rows(), groups);
  for (Eigen::Index t = 0; t < nt; ++t)
    if (piece[t] >= 0 && carrier[piece[t]] >= 0)
      for (int k = 0; k < 4; ++k) locked(mesh.tets(t, k), carrier[piece[t]]) = 1;
  for (Eigen::Index v = 0; v < membership.rows(); ++v) {
    const double n = locked.row(v).sum();
    if (n > 0) membership.row(v) = locked.row(v) / n;
  }
}

}  // namespace

int HandleInfluence::rigidVertices() const {
  int n = 0;
  for (Eigen::Index v = 0; v < membership.rows(); ++v)
    n += membership.cols() > 0 && membership.row(v).maxCoeff() >= 1.0;
  return n;
}

int HandleInfluence::dominantGroup(Eigen::Index vertex) const {
  if (membership.cols() == 0) return -1;
  Eigen::Index g = 0;
  return membership.row(vertex).maxCoeff(&g) > 0 ? int(g) : -1;
}

Eigen::Isometry3d blendMotions(const Eigen::Ref<const Eigen::VectorXd>& weights,
                               const std::vector<RigidHandle>& handles) {
  // Unit dual quaternions q = r + e d with d = t r / 2, summed in r's hemisphere of the
  // heaviest group, normalized (Kavan et al. 2008).
  Eigen::Index heaviest = 0;
  const double total = weights.maxCoeff(&heaviest) > 0 ? weights.sum() : 0;
  if (total <= 0) return Eigen::Isometry3d::Identity();
  const Eigen::Quaterniond pivot(handles[heaviest].motion.rotation());
  Eigen::Vector4d real = Eigen::Vector4d::Zero(), dual = Eigen::Vector4d::Zero();
  for (Eigen::Index g = 0; g < weights.size(); ++g) {
    if (weights[g] <= 0) continue;
    const Eigen::Quaterniond r(handles[g].motion.rotation());
    const Eigen::Vector3d t = handles[g].motion.translation();
    const double sign = r.coeffs().dot(pivot.coeffs()) < 0 ? -1.0 : 1.0;
    const Eigen::Quaterniond d = Eigen::Quaterniond(0, t.x(), t.y(), t.z()) * r;
    real += sign * weights[g] * r.coeffs();
    dual += sign * weights[g] * 0.5 * d.coeffs();
  }
  const double norm = real.norm();
  const Eigen::Quaterniond r(real / norm), d(dual / norm);
  const Eigen::Quaterniond t = d * r.conjugate();  // = (0, t/2)
  Eigen::Isometry3d out = Eigen::Isometry3d::Identity();
  out.linear() = r.toRotationMatrix();
  out.translation() = 2 * t.vec();
  return out;
}

GroupMotions::GroupMotions(const std::vector<RigidHandle>& handles) : handles_(handles) {
  for (std::size_t g = 0; g < handles.size(); ++g)
    alone_.push_back(blendMotions(
        Eigen::VectorXd::Unit(Eigen::Index(handles.size()), Eigen::Index(g)), handles));
}

Eigen::Isometry3d GroupMotions::of(const Eigen::Ref<const Eigen::RowVectorXd>& membership) const {
  Eigen::Index only = -1;
  for (Eigen::Index g = 0; g < membership.size(); ++g) {
    if (membership[g] == 0) continue;
    if (only >= 0 || membership[g] != 1) return blendMotions(membership.transpose(), handles_);
    only = g;
  }
  return only >= 0 ? alone_[std::size_t(only)] : blendMotions(membership.transpose(), handles_);
}

double handleBlendWeight(double membership) {
  const double t = std::clamp(
      (membership - HandleInfluence::kNone) / (HandleInfluence::kFull - HandleInfluence::kNone),
      0.0, 1.0);
  return t * t * (3 - 2 * t);
}

HandleInfluence computeHandleInfluence(const TransferMesh& mesh, const TriangleMesh& cage,
                                       const std::vector<RigidHandle>& handles, int threads,
                                       int jointRings) {
  if (jointRings < 0) throw Error("joint rings must be >= 0");
  const std::vector<int> owner = cageOwners(cage.vertices.rows(), handles);
  const Eigen::Index n = mesh.vertices.rows(), groups = Eigen::Index(handles.size());
  HandleInfluence out;
  out.membership = Eigen::MatrixXd::Zero(n, groups);
  out.weight.assign(n, 0.0);
  if (groups == 0 || n == 0) return out;

  Eigen::MatrixXd membership = Eigen::MatrixXd::Zero(n, groups);
  // Groups with body parts: the share of each vertex's surrounding tet volume in those parts.
  std::vector<char> byParts(groups, 0);
  {
    Eigen::VectorXd around = Eigen::VectorXd::Zero(n);
    for (Eigen::Index t = 0; t < mesh.tets.rows(); ++t) {
      const double volume = std::fabs(tetVolume(mesh.vertices, mesh.tets.row(t)));
      for (int k = 0; k < 4; ++k) around[mesh.tets(t, k)] += volume;
      for (Eigen::Index g = 0; g < groups; ++g) {
        const auto& parts = handles[g].parts;
        if (parts.empty()) continue;
        byParts[g] = 1;
        if (std::find(parts.begin(), parts.end(), mesh.labels[t]) != parts.end())
          for (int k = 0; k < 4; ++k) membership(mesh.tets(t, k), g) += volume;
      }
    }
    for (Eigen::Index v = 0; v < n; ++v)
      if (around[v] > 0) membership.row(v) /= around[v];
  }
  const bool anyByCage = std::count(byParts.begin(), byParts.end(), 0) > 0;

  // Other groups: membership of the nearest rest-cage point on the surface, extended inside.
  const std::vector<char> surface =
      anyByCage ? surfaceVertices(mesh) : std::vector<char>(std::size_t(n), 0);
  if (anyByCage)
    parallelFor(n, threads, [&](std::int64_t begin, std::int64_t end) {
      for (std::int64_t v = begin; v < end; ++v) {
        if (!surface[v]) continue;
        const Eigen::Vector3d p = mesh.vertices.row(v);
        double best = std::numeric_limits<double>::max();
        Eigen::Index face = 0;
        Eigen::Vector3d weights(1, 0, 0);
        for (Eigen::Index f = 0; f < cage.faces.rows(); ++f) {
          const Eigen::Vector3d a = cage.vertices.row(cage.faces(f, 0)),
                                b = cage.vertices.row(cage.faces(f, 1)),
                                c = cage.vertices.row(cage.faces(f, 2));
          const Eigen::Vector3d w = closestPointWeights(p, a, b, c);
          const double d = (p - (w.x() * a + w.y() * b + w.z() * c)).squaredNorm();
          if (d < best) best = d, face = f, weights = w;
        }
        for (int k = 0; k < 3; ++k) {
          const int g = owner[cage.faces(face, k)];
          if (g >= 0 && !byParts[g]) membership(v, g) += weights[k];
        }
      }
    });

  // Harmonic extension inside: L_II m_I = -L_IB m_B with unit edge weights.
  std::vector<int> slot(n, -1);
  int unknowns = 0;
  for (Eigen::Index v = 0; v < n && anyByCage; ++v)
    if (!surface[v]) slot[v] = unknowns++;
  if (unknowns > 0) {
    const TetAdjacency adjacency = TetAdjacency::build(mesh);
    std::vector<Eigen::Triplet<double>> entries;
    Eigen::MatrixXd rhs = Eigen::MatrixXd::Zero(unknowns, groups);
    for (const auto& [i, j] : adjacency.edges)
      for (const auto& [a, b] : {std::pair{i, j}, std::pair{j, i}}) {
        if (slot[a] < 0) continue;
        entries.emplace_back(slot[a], slot[a], 1.0);
        if (slot[b] >= 0) {
          if (slot[b] < slot[a]) entries.emplace_back(slot[a], slot[b], -1.0);  // lower triangle
        } else {
          rhs.row(slot[a]) += membership.row(b);
        }
      }
    Eigen::SparseMatrix<double> L(unknowns, unknowns);
    L.setFromTriplets(entries.begin(), entries.end());
    SparseCholesky cholesky;
    cholesky.factorize(L, "handle influence (a part of the transfer mesh has no surface)");
    const Eigen::MatrixXd inside = cholesky.solve(rhs);
    for (Eigen::Index v = 0; v < n; ++v)
      if (slot[v] >= 0)
        for (Eigen::Index g = 0; g < groups; ++g)
          if (!byParts[g]) membership(v, g) = inside(slot[v], g);
  }

  // Optional widening of the joints: each ring averages every vertex's memberships with its
  // edge neighbours', spreading the bend over one more ring of tets on both sides.
  if (jointRings > 0) {
    const TetAdjacency adjacency = TetAdjacency::build(mesh);
    for (int ring = 0; ring < jointRings; ++ring) {
      Eigen::MatrixXd sum = membership;
      Eigen::VectorXd count = Eigen::VectorXd::Ones(n);
      for (const auto& [i, j] : adjacency.edges) {
        sum.row(i) += membership.row(j), sum.row(j) += membership.row(i);
        count[i] += 1, count[j] += 1;
      }
      membership = count.cwiseInverse().asDiagonal() * sum;
    }
  }
  // A group's own widening: its transitions only, averaged over more rings, where the group or
  // a neighbour carries a vertex.
  int widest = 0;
  for (const RigidHandle& h : handles) widest = std::max(widest, h.widen);
  if (widest > 0) {
    const TetAdjacency adjacency = TetAdjacency::build(mesh);
    for (int ring = 0; ring < widest; ++ring) {
      std::vector<char> near(std::size_t(n), 0);
      for (std::size_t g = 0; g < handles.size(); ++g) {
        if (handles[g].widen <= ring) continue;
        for (Eigen::Index v = 0; v < n; ++v)
          near[std::size_t(v)] |= membership(v, Eigen::Index(g)) > 0;
      }
      std::vector<char> grown = near;
      for (const auto& [i, j] : adjacency.edges)
        if (near[std::size_t(i)] || near[std::size_t(j)])
          grown[std::size_t(i)] = grown[std::size_t(j)] = 1;
      Eigen::MatrixXd sum = membership;
      Eigen::VectorXd count = Eigen::VectorXd::Ones(n);
      for (const auto& [i, j] : adjacency.edges) {
        sum.row(i) += membership.row(j), sum.row(j) += membership.row(i);
        count[i] += 1, count[j] += 1;
      }
      for (Eigen::Index v = 0; v < n; ++v)
        if (grown[std::size_t(v)]) membership.row(v) = sum.row(v) / count[v];
    }
  }
  if (!mesh.rigid.empty()) lockRigidTissue(mesh, handles, membership);
  // Memberships in [0, 1] summing to at most 1 (a part named by two groups counts once).
  for (Eigen::Index v = 0; v < n; ++v) {
    auto row = membership.row(v);
    row = row.cwiseMax(0.0).cwiseMin(1.0);
    const double sum = row.sum();
    if (sum > 1) row /= sum;
    for (Eigen::Index g = 0; g < groups; ++g)
      if (row[g] > 1 - 1e-9) row.setZero(), row[g] = 1;  // carried by one group alone: exactly
    out.weight[v] = handleBlendWeight(std::min(1.0, sum));
  }
  out.membership = membership;
  return out;
}

Eigen::MatrixX3d moveHandles(const Eigen::MatrixX3d& restCage,
                             const std::vector<RigidHandle>& handles) {
  cageOwners(restCage.rows(), handles);  // validates
  Eigen::MatrixX3d out = restCage;
  for (const RigidHandle& h : handles)
    for (const int v : h.cageVertices)
      out.row(v) = (h.motion * Eigen::Vector3d(restCage.row(v))).transpose();
  return out;
}

}  // namespace repose
