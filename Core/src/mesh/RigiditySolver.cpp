// Eq. 3 and eq. 4 of the seed with their constraints eliminated: the unknowns are only the tets
// outside T_c and the vertices outside V_c, so both factorizations and every frame's solves scale
// with the part of the body the cage misses, not with the whole mesh.
#include "repose/mesh/RigiditySolver.h"

#include "CompactGreenMatrix.h"
#include "GreenCoordinatesFile.h"
#include "repose/mesh/TetAdjacency.h"
#include "repose/numerics/SparseCholesky.h"
#include "repose/util/Error.h"
#include "repose/util/Parallel.h"

#include <Eigen/LU>
#include <algorithm>
#include <array>
#include <filesystem>
#include <numeric>
#include <optional>
#include <sstream>

namespace repose {
namespace {

// Union-find over indices, for the connected parts of the unknowns.
struct Components {
  std::vector<int> parent;
  explicit Components(int n) : parent(n) { std::iota(parent.begin(), parent.end(), 0); }
  int find(int x) {
    while (parent[x] != x) x = parent[x] = parent[parent[x]];
    return x;
  }
  void join(int a, int b) { parent[find(a)] = find(b); }
};

Eigen::Matrix<double, 1, 9> flatten(const Eigen::Matrix3d& B) {
  return Eigen::Map<const Eigen::Matrix<double, 1, 9>>(B.data());
}
Eigen::Matrix3d unflatten(const Eigen::Matrix<double, 1, 9>& row) {
  return Eigen::Map<const Eigen::Matrix3d>(row.data());
}

}  // namespace

Eigen::Matrix3d tetLinearMap(const Eigen::MatrixX3d& rest, const Eigen::MatrixX3d& deformed,
                             const Eigen::RowVector4i& tet) {
  Eigen::Matrix3d E, D;
  for (int c = 0; c < 3; ++c) {
    E.col(c) = (rest.row(tet[c + 1]) - rest.row(tet[0])).transpose();
    D.col(c) = (deformed.row(tet[c + 1]) - deformed.row(tet[0])).transpose();
  }
  return D * E.inverse();
}

struct RigiditySolver::Impl {
  const TransferMesh* mesh = nullptr;
  Eigen::VectorXd volume;                    // |t|
  std::vector<Eigen::Matrix3d> restInverse;  // E_t^-1 per tet
  std::vector<int> constrainedVertices, constrainedTets;
  std::vector<int> vertexSlot;  // vertex -> row among unknown vertices, or -1 if constrained
  std::vector<int> tetSlot;     // tet -> row among unknown tets, or -1 if in T_c
  std::vector<int> unknownTets, unknownVertices;
  std::vector<int> constrainedIndex;  // vertex -> index in constrainedVertices, or -1

  // Step 1: rows  sqrt|t| (B_t - sum_n a_tn B_n) = 0  for t outside T_c; a_tn = |n| / sum |n|.
  Eigen::SparseMatrix<double> A1u;  // rows x unknown tets
  Eigen::SparseMatrix<double> A1k;  // rows x constrained tets (their B are known)
  // The constrained tets step 1 reads (A1k's nonzero columns, in order: the product sums in the
  // same order as with A1k) and A1k restricted to them; and every tet of T_c a solve reads (those
  // and the ones around step 2's edges). A frame that does not ask for B computes only these.
  std::vector<int> step1Known;
  Eigen::SparseMatrix<double> A1kUsed;
  std::vector<int> readTets;
  Eigen::MatrixXd reg1;  // A1^T b from identity rows of unconstrained components
  SparseCholesky llt1;
  // Step 2: rows  sqrt(W_e) (v_i - v_j) = g_e / sqrt(W_e)  for edges touching an unknown vertex.
  std::vector<std::array<int, 2>> edges;
  std::vector<std::vector<std::pair<int, double>>> edgeTets;  // (tet, |t|) around each edge
  Eigen::VectorXd edgeWeight;                                 // W_e
  Eigen::SparseMatrix<double> A2u, A2k;
  Eigen::MatrixXd reg2;
  SparseCholesky llt2;
  int unconstrained = 0;
};

RigiditySolver::RigiditySolver(const TransferMesh& mesh,
                               const std::vector<int>& constrainedVertices,
                               const std::vector<int>& constrainedTets)
    : impl_(std::make_unique<Impl>()) {
  Impl& m = *impl_;
  m.mesh = &mesh;
  const int nv = static_cast<int>(mesh.vertices.rows()), nt = static_cast<int>(mesh.tets.rows());
  if (constrainedVertices.empty())
    throw Error("rigidity solver: no constrained vertex (nothing inside the cage)");
  m.constrainedVertices = constrainedVertices;
  m.constrainedTets = constrainedTets;
  m.volume.resize(nt);
  m.restInverse.resize(nt);
  for (int t = 0; t < nt; ++t) {
    Eigen::Matrix3d E;
    for (int c = 0; c < 3; ++c)
      E.col(c) =
          (mesh.vertices.row(mesh.tets(t, c + 1)) - mesh.vertices.row(mesh.tets(t, 0))).transpose();
    m.volume[t] = E.determinant() / 6;
    if (!(m.volume[t] > 0))
      throw Error("rigidity solver: tet " + std::to_string(t) + " is degenerate or inverted");
    m.restInverse[t] = E.inverse();
  }
  m.tetSlot.assign(nt, 0);
  std::vector<int> constrainedTetIndex(nt, -1);
  for (std::size_t k = 0; k < constrainedTets.size(); ++k) {
    m.tetSlot.at(constrainedTets[k]) = -1;
    constrainedTetIndex[constrainedTets[k]] = static_cast<int>(k);
  }
  for (int t = 0; t < nt; ++t)
    if (m.tetSlot[t] == 0)
      m.tetSlot[t] = static_cast<int>(m.unknownTets.size()), m.unknownTets.push_back(t);
  m.constrainedIndex.assign(nv, -1);
  for (std::size_t i = 0; i < constrainedVertices.size(); ++i)
    m.constrainedIndex.at(constrainedVertices[i]) = static_cast<int>(i);
  m.vertexSlot.assign(nv, -1);
  for (int v = 0; v < nv; ++v)
    if (m.constrainedIndex[v] < 0)
      m.vertexSlot[v] = static_cast<int>(m.unknownVertices.size()), m.unknownVertices.push_back(v);

  const TetAdjacency adjacency = TetAdjacency::build(mesh);
  const std::vector<std::vector<int>>& neighbours = adjacency.faceNeighbours;
  m.edges = adjacency.edges;
  m.edgeTets.resize(m.edges.size());
  for (std::size_t e = 0; e < m.edges.size(); ++e)
    for (int t : adjacency.edgeTets[e]) m.edgeTets[e].emplace_back(t, m.volume[t]);

  // Step 1 system. Unknown tets whose face-connected part touches no T_c tet get B = I.
  const int nu = static_cast<int>(m.unknownTets.size());
  Components tetParts(nu);
  std::vector<char> tetDriven(nu, 0);
  std::vector<Eigen::Triplet<double>> u1, k1;
  int row = 0;
  for (int r = 0; r < nu; ++r) {
    const int t = m.unknownTets[r];
    double total = 0;
    for (int n : neighbours[t]) total += m.volume[n];
    if (neighbours[t].empty()) continue;
    const double s = std::sqrt(m.volume[t]);
    u1.emplace_back(row, r, s);
    for (int n : neighbours[t]) {
      const double a = -s * m.volume[n] / total;
      if (m.tetSlot[n] >= 0) {
        u1.emplace_back(row, m.tetSlot[n], a);
        tetParts.join(r, m.tetSlot[n]);
      } else {
        k1.emplace_back(row, constrainedTetIndex[n], a);
        tetDriven[r] = 1;
      }
    }
    ++row;
  }
  for (int r = 0; r < nu; ++r)
    if (tetDriven[r]) tetDriven[tetParts.find(r)] = 1;
  m.reg1 = Eigen::MatrixXd::Zero(nu, 9);
  const Eigen::Matrix<double, 1, 9> identity = flatten(Eigen::Matrix3d::Identity());
  for (int r = 0; r < nu; ++r)
    if (!tetDriven[tetParts.find(r)]) {
      const double s = std::sqrt(m.volume[m.unknownTets[r]]);
      u1.emplace_back(row++, r, s);
      m.reg1.row(r) += s * s * identity;
    }
  m.A1u.resize(row, nu);
  m.A1u.setFromTriplets(u1.begin(), u1.end());
  m.A1k.resize(row, static_cast<Eigen::Index>(constrainedTets.size()));
  m.A1k.setFromTriplets(k1.begin(), k1.end());
  if (nu > 0)
    m.llt1.factorize(Eigen::SparseMatrix<double>(m.A1u.transpose() * m.A1u),
                     "rigidity solver step 1");

  // Step 2 system over the vertices outside V_c; parts with no edge to V_c stay at rest.
  const int no = static_cast<int>(m.unknownVertices.size());
  Components vertexParts(no);
  std::vector<char> vertexDriven(no, 0);
  std::vector<Eigen::Triplet<double>> u2, k2;
  m.edgeWeight.resize(static_cast<Eigen::Index>(m.edges.size()));
  row = 0;
  std::vector<int> usedEdges;
  for (std::size_t e = 0; e < m.edges.size(); ++e) {
    double W = 0;
    for (const auto& [t, vol] : m.edgeTets[e]) W += vol;
    m.edgeWeight[e] = W;
    const int i = m.edges[e][0], j = m.edges[e][1];
    const int si = m.vertexSlot[i], sj = m.vertexSlot[j];
    if (si < 0 && sj < 0) continue;
    const double s = std::sqrt(W);
    if (si >= 0)
      u2.emplace_back(row, si, s);
    else
      k2.emplace_back(row, m.constrainedIndex[i], s);
    if (sj >= 0)
      u2.emplace_back(row, sj, -s);
    else
      k2.emplace_back(row, m.constrainedIndex[j], -s);
    // An edge to a constrained vertex drives its part; one between unknowns joins their parts.
    if (si >= 0 && sj >= 0)
      vertexParts.join(si, sj);
    else if (si >= 0)
      vertexDriven[si] = 1;
    else if (sj >= 0)
      vertexDriven[sj] = 1;
    usedEdges.push_back(static_cast<int>(e));
    ++row;
  }
  for (int r = 0; r < no; ++r)
    if (vertexDriven[r]) vertexDriven[vertexParts.find(r)] = 1;
  m.reg2 = Eigen::MatrixXd::Zero(no, 3);
  std::vector<double> vertexWeight(nv, 0);
  for (int t = 0; t < nt; ++t)
    for (int c = 0; c < 4; ++c) vertexWeight[mesh.tets(t, c)] += m.volume[t];
  for (int r = 0; r < no; ++r)
    if (!vertexDriven[vertexParts.find(r)]) {
      const int v = m.unknownVertices[r];
      const double w = std::max(vertexWeight[v], 1e-12);
      u2.emplace_back(row++, r, std::sqrt(w));
      m.reg2.row(r) += w * mesh.vertices.row(v);
      ++m.unconstrained;
    }
  // Keep only the edges that have rows, in row order.
  std::vector<std::array<int, 2>> keptEdges;
  std::vector<std::vector<std::pair<int, double>>> keptTets;
  Eigen::VectorXd keptWeight(static_cast<Eigen::Index>(usedEdges.size()));
  for (std::size_t k = 0; k < usedEdges.size(); ++k) {
    keptEdges.push_back(m.edges[usedEdges[k]]);
    keptTets.push_back(std::move(m.edgeTets[usedEdges[k]]));
    keptWeight[static_cast<Eigen::Index>(k)] = m.edgeWeight[usedEdges[k]];
  }
  m.edges = std::move(keptEdges);
  m.edgeTets = std::move(keptTets);
  m.edgeWeight = keptWeight;
  m.A2u.resize(row, no);
  m.A2u.setFromTriplets(u2.begin(), u2.end());
  m.A2k.resize(row, static_cast<Eigen::Index>(constrainedVertices.size()));
  m.A2k.setFromTriplets(k2.begin(), k2.end());
  if (no > 0)
    m.llt2.factorize(Eigen::SparseMatrix<double>(m.A2u.transpose() * m.A2u),
                     "rigidity solver step 2");

  // What a frame reads of T_c's maps.
  std::vector<int> usedColumn(constrainedTets.size(), -1);
  for (Eigen::Index k = 0; k < m.A1k.outerSize(); ++k)
    for (Eigen::SparseMatrix<double>::InnerIterator it(m.A1k, k); it; ++it)
      if (usedColumn[k] < 0) {
        usedColumn[k] = static_cast<int>(m.step1Known.size());
        m.step1Known.push_back(static_cast<int>(k));
      }
  std::vector<Eigen::Triplet<double>> used;
  for (Eigen::Index k = 0; k < m.A1k.outerSize(); ++k)
    for (Eigen::SparseMatrix<double>::InnerIterator it(m.A1k, k); it; ++it)
      used.emplace_back(static_cast<int>(it.row()), usedColumn[k], it.value());
  m.A1kUsed.resize(m.A1k.rows(), static_cast<Eigen::Index>(m.step1Known.size()));
  m.A1kUsed.setFromTriplets(used.begin(), used.end());
  std::vector<char> read(nt, 0);
  for (const int k : m.step1Known) read[constrainedTets[k]] = 1;
  for (const auto& around : m.edgeTets)
    for (const auto& [t, vol] : around)
      if (m.tetSlot[t] < 0) read[t] = 1;
  for (int t = 0; t < nt; ++t)
    if (read[t]) m.readTets.push_back(t);
  m.A1k = Eigen::SparseMatrix<double>();  // A1kUsed holds what is needed
}

RigiditySolver::~RigiditySolver() = default;
RigiditySolver::RigiditySolver(RigiditySolver&&) noexcept = default;
RigiditySolver& RigiditySolver::operator=(RigiditySolver&&) noexcept = default;

int RigiditySolver::unconstrainedVertices() const {
  return impl_->unconstrained;
}

Eigen::MatrixX3d RigiditySolver::solve(const Eigen::MatrixX3d& targets,
                                       std::vector<Eigen::Matrix3d>* Bout) const {
  const Impl& m = *impl_;
  const TransferMesh& mesh = *m.mesh;
  if (targets.rows() != static_cast<Eigen::Index>(m.constrainedVertices.size()))
    throw Error("rigidity solver: " + std::to_string(targets.rows()) + " targets for " +
                std::to_string(m.constrainedVertices.size()) + " constrained vertices");
  if (!targets.allFinite()) throw Error("rigidity solver: target positions are not finite");
  Eigen::MatrixX3d positions(mesh.vertices.rows(), 3);
  for (std::size_t i = 0; i < m.constrainedVertices.size(); ++i)
    positions.row(m.constrainedVertices[i]) = targets.row(i);

  // Step 1: B of T_c from the targets (all of them when asked for, else those the solves read),
  // then the others.
  std::vector<Eigen::Matrix3d> B(static_cast<std::size_t>(mesh.tets.rows()));
  const auto mapOf = [&](int t) {
    Eigen::Matrix3d D;
    for (int c = 0; c < 3; ++c)
      D.col(c) = (positions.row(mesh.tets(t, c + 1)) - positions.row(mesh.tets(t, 0))).transpose();
    B[t] = D * m.restInverse[t];
  };
  if (Bout)
    for (const int t : m.constrainedTets) mapOf(t);
  else
    for (const int t : m.readTets) mapOf(t);
  Eigen::MatrixXd known(m.step1Known.size(), 9);
  for (std::size_t j = 0; j < m.step1Known.size(); ++j)
    known.row(static_cast<Eigen::Index>(j)) = flatten(B[m.constrainedTets[m.step1Known[j]]]);
  if (!m.unknownTets.empty()) {
    const Eigen::MatrixXd rhs = m.reg1 - Eigen::MatrixXd(m.A1u.transpose() * (m.A1kUsed * known));
    const Eigen::MatrixXd x = m.llt1.solve(rhs);
    for (std::size_t r = 0; r < m.unknownTets.size(); ++r)
      B[m.unknownTets[r]] = unflatten(x.row(r));
  }

  // Step 2: each edge row wants v_i - v_j = (sum |t| B_t e0) / W_e.
  if (!m.unknownVertices.empty()) {
    Eigen::MatrixXd b(static_cast<Eigen::Index>(m.edges.size()), 3);
    for (std::size_t e = 0; e < m.edges.size(); ++e) {
      const Eigen::Vector3d e0 =
          (mesh.vertices.row(m.edges[e][0]) - mesh.vertices.row(m.edges[e][1])).transpose();
      Eigen::Matrix3d sum = Eigen::Matrix3d::Zero();
      for (const auto& [t, vol] : m.edgeTets[e]) sum += vol * B[t];
      b.row(static_cast<Eigen::Index>(e)) =
          (sum * e0).transpose() / std::sqrt(m.edgeWeight[static_cast<Eigen::Index>(e)]);
    }
    // Rows past the edges are the rest-position anchors of undriven parts; their b is in reg2.
    Eigen::MatrixXd full = Eigen::MatrixXd::Zero(m.A2u.rows(), 3);
    full.topRows(b.rows()) = b;
    const Eigen::MatrixXd rhs =
        Eigen::MatrixXd(m.A2u.transpose() * (full - m.A2k * targets)) + m.reg2;
    const Eigen::MatrixXd x = m.llt2.solve(rhs);
    for (std::size_t r = 0; r < m.unknownVertices.size(); ++r)
      positions.row(m.unknownVertices[r]) = x.row(r);
  }
  if (Bout) *Bout = std::move(B);
  return positions;
}

namespace {

// The values the Green coordinates multiply: cage vertices, then each face's stretched normal.
Eigen::MatrixX3d greenCageValues(const TriangleMesh& rest, const Eigen::MatrixX3d& deformed) {
  const Eigen::VectorXd stretch = greenFaceStretch(rest, deformed);
  Eigen::MatrixX3d x(deformed.rows() + rest.faces.rows(), 3);
  x.topRows(deformed.rows()) = deformed;
  x.bottomRows(rest.faces.rows()) = stretch.asDiagonal() * faceNormals(deformed, rest.faces);
  return x;
}

}  // namespace

CageDeformation::CageDeformation(const TransferMesh& mesh, const TriangleMesh& cage, int threads,
                                 const std::string& coordinatesFile, const ProgressFn& progress)
    : cage_(cage), threads_(threads) {
  restCageValues_ = greenCageValues(cage_, cage_.vertices);
  key_ = greenCoordinatesKey(mesh, cage_);
  meshVertices_ = mesh.vertices.rows();
  std::optional<SavedGreenCoordinates> saved;
  if (!coordinatesFile.empty())
    saved = readGreenCoordinatesFile(coordinatesFile, key_, meshVertices_, cage_, threads,
                                     &coordinatesNote_);
  if (saved) {
    // V_c as the run that saved it found it (winding numbers, then the unreproduced dropped).
    embedding_.inside.assign(static_cast<std::size_t>(meshVertices_), 0);
    for (const int v : saved->cageVertices) embedding_.inside[v] = 1;
    embedding_.cageVertices = std::move(saved->cageVertices);
    for (Eigen::Index t = 0; t < mesh.tets.rows(); ++t) {
      bool all = true;
      for (int c = 0; c < 4; ++c) all &= embedding_.inside[mesh.tets(t, c)] != 0;
      if (all) embedding_.cageTets.push_back(static_cast<int>(t));
    }
    unreproduced_ = saved->unreproduced;
    restPositions_ = std::move(saved->restPositions);
    restVertices_.resize(restPositions_.rows(), 3);
    for (Eigen::Index r = 0; r < restVertices_.rows(); ++r)
      restVertices_.row(r) = mesh.vertices.row(embedding_.cageVertices[r]);
    coefficients_ = std::make_unique<CompactGreenMatrix>(std::move(saved->coefficients));
    coordinatesRead_ = true;
  } else {
    computeCoordinates(mesh, threads, progress);
  }
  solver_ = std::make_unique<RigiditySolver>(mesh, embedding_.cageVertices, embedding_.cageTets);
}

void CageDeformation::computeCoordinates(const TransferMesh& mesh, int threads,
                                         const ProgressFn& progress) {
  embedding_ = embedInCage(mesh, cage_, threads, false);
  // Green coordinates of V_c in blocks of rows, each compacted at once, so the double matrix
  // (12 bytes more per coefficient) never exists for the whole mesh: at the seed's sizes it would
  // be ~430 MB, more than the rest of a posing job.
  constexpr Eigen::Index kBlock = 1024;
  // Green coordinates reproduce every point inside the cage; a vertex they miss by more than
  // this (1e-5 of the cage's size; good vertices are within ~1e-6 mm) is treated as outside.
  const double tolerance =
      1e-5 * (cage_.vertices.colwise().maxCoeff() - cage_.vertices.colwise().minCoeff()).norm();
  for (int pass = 0; pass < 2; ++pass) {
    const Eigen::Index n = static_cast<Eigen::Index>(embedding_.cageVertices.size());
    restPositions_.resize(n, 3);
    restVertices_.resize(n, 3);
    coefficients_ =
        std::make_unique<CompactGreenMatrix>(n, cage_.vertices.rows(), cage_.faces.rows());
    std::vector<int> missed;
    for (Eigen::Index first = 0; first < n; first += kBlock) {
      // Also the stop point of an interrupt or a cancel (a second pass, rare, starts over).
      reportProgress(progress, double(first) / double(n), "Green coordinates");
      const Eigen::Index rows = std::min(kBlock, n - first);
      Eigen::MatrixX3d points(rows, 3);
      for (Eigen::Index r = 0; r < rows; ++r)
        points.row(r) = mesh.vertices.row(embedding_.cageVertices[first + r]);
      const GreenCoordinates gc = computeGreenCoordinates(cage_, points, threads);
      restPositions_.middleRows(first, rows) = applyGreenCoordinates(gc, cage_, cage_.vertices);
      restVertices_.middleRows(first, rows) = points;
      coefficients_->setRows(first, gc.phi, gc.psi);
      for (Eigen::Index r = 0; r < rows; ++r)
        if (!((restPositions_.row(first + r) - points.row(r)).norm() <= tolerance))
          missed.push_back(embedding_.cageVertices[first + r]);
    }
    if (missed.empty() || pass == 1) break;
    // Once: drop them from V_c (and their tets from T_c) and compute the rows again.
    unreproduced_ = static_cast<int>(missed.size());
    for (const int v : missed) embedding_.inside[v] = 0;
    std::vector<int> kept;
    for (const int v : embedding_.cageVertices)
      if (embedding_.inside[v]) kept.push_back(v);
    embedding_.cageVertices = std::move(kept);
    if (embedding_.cageVertices.empty())
      throw Error("no transfer-mesh vertex has usable Green coordinates in this cage");
    std::vector<int> tets;
    for (const int t : embedding_.cageTets) {
      bool all = true;
      for (int c = 0; c < 4; ++c) all &= embedding_.inside[mesh.tets(t, c)] != 0;
      if (all) tets.push_back(t);
    }
    embedding_.cageTets = std::move(tets);
  }
  reportProgress(progress, 1.0, "Green coordinates");
}

void CageDeformation::saveCoordinates(const std::string& path) const {
  writeGreenCoordinatesFile(path, key_, meshVertices_, embedding_.cageVertices, unreproduced_,
                            restPositions_, *coefficients_, threads_);
}

std::string greenCoordinatesFileFor(const std::string& meshPath) {
  std::filesystem::path p(meshPath);
  return p.replace_extension(".green").string();
}

CageDeformation::~CageDeformation() = default;
CageDeformation::CageDeformation(CageDeformation&&) noexcept = default;
CageDeformation& CageDeformation::operator=(CageDeformation&&) noexcept = default;

std::size_t CageDeformation::coefficientBytes() const {
  return coefficients_->bytes();
}

void CageDeformation::checkPosedCage(const Eigen::MatrixX3d& deformedCage) const {
  if (deformedCage.rows() != cage_.vertices.rows())
    throw Error("deformed cage has the wrong number of vertices");
  // A drag can put a handle anywhere; beyond 1000 cage sizes from rest nothing a body can do is
  // left, and the products that follow (stretch, normals, a grid around the body) would lose
  // their precision or overflow. Refused by vertex, with the distance (docs/RELIABILITY.md).
  const Eigen::RowVector3d lo = cage_.vertices.colwise().minCoeff();
  const Eigen::RowVector3d hi = cage_.vertices.colwise().maxCoeff();
  const double size = (hi - lo).norm(), reach = 1000 * size;
  for (Eigen::Index v = 0; v < deformedCage.rows(); ++v) {
    const Eigen::RowVector3d p = deformedCage.row(v);
    if (!p.allFinite())
      throw Error("posed cage: vertex " + std::to_string(v) + " has a non-finite position");
    const double away = (p - p.cwiseMax(lo).cwiseMin(hi)).stableNorm();  // no overflow at 1e300
    if (away > reach) {
      std::ostringstream m;
      m.precision(3);
      m << "posed cage: vertex " << v << " is " << away << " mm from the rest cage, more than 1000 "
        << "times the cage's size (" << size << " mm): a handle moved too far";
      throw Error(m.str());
    }
  }
}

Eigen::MatrixX3d CageDeformation::greenPositions(const Eigen::MatrixX3d& deformedCage,
                                                 GreenPrecision precision) const {
  checkPosedCage(deformedCage);
  // Linear in the cage values: p = p_rest + C (x - x_rest). An unmoved cage gives p_rest exactly.
  const Eigen::MatrixX3d delta = greenCageValues(cage_, deformedCage) - restCageValues_;
  return restPositions_ +
         coefficients_->multiply(delta, precision == GreenPrecision::Preview, threads_);
}

Eigen::MatrixX3d CageDeformation::deform(const Eigen::MatrixX3d& deformedCage,
                                         std::vector<Eigen::Matrix3d>* B,
                                         GreenPrecision precision) const {
  return solver_->solve(greenPositions(deformedCage, precision), B);
}

Eigen::MatrixX3d CageDeformation::deform(const Eigen::MatrixX3d& deformedCage,
                                         const HandleInfluence& influence,
                                         const std::vector<RigidHandle>& handles,
                                         std::vector<Eigen::Matrix3d>* B,
                                         GreenPrecision precision) const {
  if (influence.membership.rows() != Eigen::Index(embedding_.inside.size()))
    throw Error("handle influence computed for another transfer mesh");
  if (influence.membership.cols() != Eigen::Index(handles.size()))
    throw Error("handle influence computed for another list of handle groups");
  checkPosedCage(deformedCage);
  // Green positions only where the groups do not carry a vertex alone: in a pose of rigid
  // groups that is the joints' few rows, so the frame skips most of the dense product.
  const Eigen::Index n = Eigen::Index(embedding_.cageVertices.size());
  std::vector<std::int64_t> greenRows;
  for (Eigen::Index r = 0; r < n; ++r)
    if (influence.weight[embedding_.cageVertices[r]] < 1) greenRows.push_back(r);
  const Eigen::MatrixX3d delta = greenCageValues(cage_, deformedCage) - restCageValues_;
  const Eigen::MatrixX3d green = coefficients_->multiplyRows(
      delta, precision == GreenPrecision::Preview, threads_, &greenRows);
  Eigen::MatrixX3d targets(n, 3);
  const GroupMotions motions(handles);
  std::vector<std::int64_t> greenIndex(n, -1);
  for (std::size_t k = 0; k < greenRows.size(); ++k) greenIndex[greenRows[k]] = std::int64_t(k);
  parallelFor(n, threads_, [&](std::int64_t begin, std::int64_t end) {
    for (std::int64_t r = begin; r < end; ++r) {
      const int v = embedding_.cageVertices[r];
      const double w = influence.weight[v];
      Eigen::RowVector3d g = Eigen::RowVector3d::Zero();
      if (greenIndex[r] >= 0) g = restPositions_.row(r) + green.row(greenIndex[r]);
      if (w <= 0) {
        targets.row(r) = g;
        continue;
      }
      const Eigen::RowVector3d carried =
          (motions.of(influence.membership.row(v)) * Eigen::Vector3d(restVertices_.row(r)))
              .transpose();
      targets.row(r) = w == 1 ? carried : (g + w * (carried - g)).eval();
    }
  });
  return solver_->solve(targets, B);
}

}  // namespace repose
