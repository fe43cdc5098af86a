// The seed's tetrahedral solver pinned to its equations (issue 29, item 1). A plain reference,
// written from the paper and not from src/mesh/RigiditySolver.cpp, builds eq. 3 and eq. 4 as dense
// least-squares systems (the constraints of T_c and V_c eliminated: their B and positions are
// known) and solves them with a dense QR of the rectangular system (no normal equations). The
// production solver (sparse, normal equations, CHOLMOD) must give the same B_t and positions to
// 1e-9 relative on hand-made tets of unequal volumes, jittered random meshes and random Delaunay
// meshes (CGAL) with random inside sets, and a part of the phantom's transfer mesh, for rigid,
// affine and random motions of V_c. Eq. 1-2 are computed directly: the solution makes the eq. 3
// energy stationary (no perturbation of the free B_t lowers it) and ErrorMetric's e_t (eq. 5) is
// |ΔB_t| of eq. 1.
#include "TestDelaunay.h"
#include "TestTetMeshes.h"

#include "repose/mesh/ErrorMetric.h"
#include "repose/mesh/RigiditySolver.h"
#include "repose/mesh/TransferMesh.h"
#include "repose/phantom/Phantom.h"

#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <Eigen/Geometry>

#include <algorithm>
#include <cmath>
#include <map>
#include <optional>
#include <random>
#include <set>

using namespace repose;
using namespace repose::test;

namespace {

// ---------------------------------------------------------------------------------------------
// The reference, from the paper's text.

struct Problem {
  TransferMesh mesh;
  std::vector<int> Vc;  // vertices inside the cage
  std::vector<int> Tc;  // tets whose four vertices are in Vc
};

double volumeOf(const TransferMesh& m, int t) {  // |t|
  Eigen::Matrix3d E;
  for (int c = 0; c < 3; ++c)
    E.col(c) = (m.vertices.row(m.tets(t, c + 1)) - m.vertices.row(m.tets(t, 0))).transpose();
  return E.determinant() / 6;
}

// B of a tet from its four rest and four deformed vertices.
Eigen::Matrix3d mapOf(const TransferMesh& m, const Eigen::MatrixX3d& x, int t) {
  Eigen::Matrix3d E, D;
  for (int c = 0; c < 3; ++c) {
    E.col(c) = (m.vertices.row(m.tets(t, c + 1)) - m.vertices.row(m.tets(t, 0))).transpose();
    D.col(c) = (x.row(m.tets(t, c + 1)) - x.row(m.tets(t, 0))).transpose();
  }
  return D * E.inverse();
}

// T_1(t): the tets sharing a face (three vertices) with t, by brute force.
std::vector<std::vector<int>> faceNeighbours(const TransferMesh& m) {
  const int nt = int(m.tets.rows());
  std::vector<std::set<int>> verts(nt);
  for (int t = 0; t < nt; ++t)
    for (int c = 0; c < 4; ++c) verts[t].insert(m.tets(t, c));
  std::vector<std::vector<int>> n(nt);
  for (int a = 0; a < nt; ++a)
    for (int b = 0; b < nt; ++b) {
      if (a == b) continue;
      int shared = 0;
      for (int v : verts[a]) shared += int(verts[b].count(v));
      if (shared == 3) n[a].push_back(b);
    }
  return n;
}

// Every edge e_ij of the tets with T_1(e_ij), the tets holding both ends.
std::map<std::pair<int, int>, std::vector<int>> edgesWithTets(const TransferMesh& m) {
  std::map<std::pair<int, int>, std::vector<int>> e;
  for (int t = 0; t < int(m.tets.rows()); ++t)
    for (int a = 0; a < 4; ++a)
      for (int b = a + 1; b < 4; ++b) {
        const int i = m.tets(t, a), j = m.tets(t, b);
        e[{std::min(i, j), std::max(i, j)}].push_back(t);
      }
  return e;
}

// Eq. 1: ΔB_t = B_t - Σ_{n∈T1(t)} |n| B_n / Σ |n|.
Eigen::Matrix3d deltaB(const TransferMesh& m, const std::vector<std::vector<int>>& T1,
                       const std::vector<Eigen::Matrix3d>& B, int t) {
  Eigen::Matrix3d mean = Eigen::Matrix3d::Zero();
  double total = 0;
  for (int n : T1[t]) mean += volumeOf(m, n) * B[n], total += volumeOf(m, n);
  return T1[t].empty() ? Eigen::Matrix3d::Zero() : Eigen::Matrix3d(B[t] - mean / total);
}

// The energy eq. 3 minimizes: Σ_{t∉T_c} |t| |ΔB_t|² (eq. 2 over the free tets).
double freeEnergy(const Problem& p, const std::vector<std::vector<int>>& T1,
                  const std::vector<Eigen::Matrix3d>& B) {
  const std::set<int> fixed(p.Tc.begin(), p.Tc.end());
  double e = 0;
  for (int t = 0; t < int(p.mesh.tets.rows()); ++t)
    if (!fixed.count(t)) e += volumeOf(p.mesh, t) * deltaB(p.mesh, T1, B, t).squaredNorm();
  return e;
}

struct Solution {
  std::vector<Eigen::Matrix3d> B;
  Eigen::MatrixX3d x;
};

// Eq. 3 then eq. 4, densely. The meshes here are connected and T_c, V_c not empty, so every free
// tet and vertex is driven.
Solution referenceSolve(const Problem& p, const Eigen::MatrixX3d& targets) {
  const TransferMesh& m = p.mesh;
  const int nt = int(m.tets.rows()), nv = int(m.vertices.rows());
  const auto T1 = faceNeighbours(m);
  Solution s;
  s.B.assign(nt, Eigen::Matrix3d::Zero());
  s.x = Eigen::MatrixX3d::Zero(nv, 3);
  std::vector<int> vcIndex(nv, -1);
  for (std::size_t k = 0; k < p.Vc.size(); ++k) vcIndex[p.Vc[k]] = int(k);
  for (int v = 0; v < nv; ++v)
    if (vcIndex[v] >= 0) s.x.row(v) = targets.row(vcIndex[v]);
  // Eq. 3. Known: B~ of T_c from the GC positions. Unknown: the others, one column per tet, the
  // nine entries of B solved as nine right-hand sides (the rows treat every entry alike).
  std::vector<int> freeTet(nt, -1), freeTets;
  const std::set<int> fixed(p.Tc.begin(), p.Tc.end());
  for (int t = 0; t < nt; ++t)
    if (fixed.count(t))
      s.B[t] = mapOf(m, s.x, t);
    else
      freeTet[t] = int(freeTets.size()), freeTets.push_back(t);
  if (!freeTets.empty()) {
    std::vector<int> rows;  // free tets with a face neighbour (others have ΔB = 0 by eq. 1)
    for (int t : freeTets)
      if (!T1[t].empty()) rows.push_back(t);
    Eigen::MatrixXd A =
        Eigen::MatrixXd::Zero(Eigen::Index(rows.size()), Eigen::Index(freeTets.size()));
    Eigen::MatrixXd b = Eigen::MatrixXd::Zero(Eigen::Index(rows.size()), 9);
    for (std::size_t r = 0; r < rows.size(); ++r) {
      const int t = rows[r];
      const double w = std::sqrt(volumeOf(m, t));
      double total = 0;
      for (int n : T1[t]) total += volumeOf(m, n);
      A(Eigen::Index(r), freeTet[t]) += w;
      for (int n : T1[t]) {
        const double a = w * volumeOf(m, n) / total;
        if (freeTet[n] >= 0)
          A(Eigen::Index(r), freeTet[n]) -= a;
        else
          b.row(Eigen::Index(r)) +=
              a * Eigen::Map<const Eigen::Matrix<double, 1, 9>>(s.B[n].data());
      }
    }
    const Eigen::MatrixXd X = A.colPivHouseholderQr().solve(b);
    for (std::size_t k = 0; k < freeTets.size(); ++k)
      s.B[freeTets[k]] = Eigen::Map<const Eigen::Matrix3d>(X.row(Eigen::Index(k)).eval().data());
  }
  // Eq. 4. Known: V_c's positions. Unknown: the other vertices. One row per edge with a free end.
  std::vector<int> freeVertex(nv, -1), freeVertices;
  for (int v = 0; v < nv; ++v)
    if (vcIndex[v] < 0) freeVertex[v] = int(freeVertices.size()), freeVertices.push_back(v);
  if (!freeVertices.empty()) {
    const auto edges = edgesWithTets(m);
    std::vector<std::pair<std::pair<int, int>, std::vector<int>>> used;
    for (const auto& e : edges)
      if (freeVertex[e.first.first] >= 0 || freeVertex[e.first.second] >= 0) used.push_back(e);
    Eigen::MatrixXd A =
        Eigen::MatrixXd::Zero(Eigen::Index(used.size()), Eigen::Index(freeVertices.size()));
    Eigen::MatrixXd b = Eigen::MatrixXd::Zero(Eigen::Index(used.size()), 3);
    for (std::size_t r = 0; r < used.size(); ++r) {
      const auto [i, j] = used[r].first;
      double W = 0;
      Eigen::Matrix3d sum = Eigen::Matrix3d::Zero();
      for (int t : used[r].second) W += volumeOf(m, t), sum += volumeOf(m, t) * s.B[t];
      const Eigen::Vector3d e0 = (m.vertices.row(i) - m.vertices.row(j)).transpose();
      const Eigen::RowVector3d rhs = (sum * e0).transpose() / std::sqrt(W);
      const Eigen::Index row = Eigen::Index(r);
      b.row(row) = rhs;
      if (freeVertex[i] >= 0)
        A(row, freeVertex[i]) += std::sqrt(W);
      else
        b.row(row) -= std::sqrt(W) * s.x.row(i);
      if (freeVertex[j] >= 0)
        A(row, freeVertex[j]) -= std::sqrt(W);
      else
        b.row(row) += std::sqrt(W) * s.x.row(j);
    }
    const Eigen::MatrixXd X = A.colPivHouseholderQr().solve(b);
    for (std::size_t k = 0; k < freeVertices.size(); ++k)
      s.x.row(freeVertices[k]) = X.row(Eigen::Index(k));
  }
  return s;
}

// ---------------------------------------------------------------------------------------------
// Meshes and motions.

// T_c for a V_c: the tets with all four vertices in it.
std::vector<int> insideTets(const TransferMesh& m, const std::vector<int>& Vc) {
  std::set<int> in(Vc.begin(), Vc.end());
  std::vector<int> Tc;
  for (int t = 0; t < int(m.tets.rows()); ++t) {
    bool all = true;
    for (int c = 0; c < 4; ++c) all &= in.count(m.tets(t, c)) > 0;
    if (all) Tc.push_back(t);
  }
  return Tc;
}

// Five tets of very different volumes in a fan around one edge (each shares a face with the two
// beside it), two of them inside the cage: a free tet's face neighbours differ in volume, so the
// volume weights of eq. 1, 3 and 4 all matter.
Problem handMade() {
  Problem p;
  p.mesh.vertices.resize(7, 3);
  p.mesh.vertices << 0, 0, 0,  // the shared edge's ends
      0, 0, 12,                //
      10, 0, 3,                // the ring, at radii 10, 4, 25, 7 and 15
      1.2, 3.8, 5,             //
      -20, 15, -2,             //
      -2, -6.7, 8,             //
      9, -12, 4;
  p.mesh.tets.resize(5, 4);
  for (int k = 0; k < 5; ++k) p.mesh.tets.row(k) << 0, 1, 2 + k, 2 + (k + 1) % 5;
  for (int t = 0; t < 5; ++t)
    if (volumeOf(p.mesh, t) < 0) std::swap(p.mesh.tets(t, 2), p.mesh.tets(t, 3));
  p.mesh.labels = Eigen::VectorXi::Ones(5);
  p.Vc = {0, 1, 2, 3, 4};
  p.Tc = insideTets(p.mesh, p.Vc);
  return p;
}

// A box of Kuhn-split cubes with every vertex jittered (still positively oriented: the jitter is
// a fifth of a cell), and a random 60 % of its vertices inside the cage.
Problem jittered(unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> u(-1, 1);
  Problem p;
  p.mesh = tetBox({0, 0, 0}, {40, 30, 30}, {4, 3, 3});
  for (Eigen::Index v = 0; v < p.mesh.vertices.rows(); ++v)
    p.mesh.vertices.row(v) += 2.0 * Eigen::RowVector3d(u(rng), u(rng), u(rng));
  for (int v = 0; v < int(p.mesh.vertices.rows()); ++v)
    if (std::uniform_real_distribution<double>(0, 1)(rng) < 0.6) p.Vc.push_back(v);
  p.Tc = insideTets(p.mesh, p.Vc);
  return p;
}

// The Delaunay tetrahedralization (CGAL) of random points in a 40 x 30 x 30 mm box, kept at least
// 3 mm apart, its corners included so the hull is the box; V_c a random 60 % of the vertices.
// Unlike the Kuhn boxes, vertex valences and tet shapes are irregular (slivers included), as a
// Mesh_3 mesh's are. Nothing when the random V_c leaves a free part undriven.
std::optional<Problem> delaunay(unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> x(0, 40), y(0, 30), z(0, 30);
  std::vector<Eigen::Vector3d> points;
  for (int c = 0; c < 8; ++c) points.emplace_back(c & 1 ? 40 : 0, c & 2 ? 30 : 0, c & 4 ? 30 : 0);
  for (int tries = 0; points.size() < 70 && tries < 20000; ++tries) {
    const Eigen::Vector3d p(x(rng), y(rng), z(rng));
    bool apart = true;
    for (const Eigen::Vector3d& q : points) apart &= (p - q).norm() >= 3;
    if (apart) points.push_back(p);
  }
  Problem p;
  p.mesh = delaunayMesh(points);
  for (int v = 0; v < int(p.mesh.vertices.rows()); ++v)
    if (std::uniform_real_distribution<double>(0, 1)(rng) < 0.6) p.Vc.push_back(v);
  p.Tc = insideTets(p.mesh, p.Vc);
  if (p.Tc.empty() || RigiditySolver(p.mesh, p.Vc, p.Tc).unconstrainedVertices() > 0)
    return std::nullopt;
  return p;
}

// The 4 mm phantom's transfer mesh around the left elbow: the largest face-connected piece of
// the tets whose centroids lie in a box about the elbow, reindexed; V_c is its upper half (the
// cage covers the upper arm, the forearm is recovered by the solver).
Problem phantomElbowPart() {
  PhantomOptions o;
  o.voxelMm = 4;
  const Phantom phantom(o);
  TransferMeshOptions mo;
  mo.sizeMm = 20;
  const TransferMesh full = buildTransferMesh(phantom.makeVolumes().second, mo);
  const Eigen::Vector3d elbow = phantom.joint("elbow_left").ras;
  std::vector<int> kept;
  for (int t = 0; t < int(full.tets.rows()); ++t) {
    Eigen::Vector3d c = Eigen::Vector3d::Zero();
    for (int k = 0; k < 4; ++k) c += full.vertices.row(full.tets(t, k)).transpose() / 4;
    if (((c - elbow).cwiseAbs().array() < Eigen::Array3d(60, 60, 90)).all()) kept.push_back(t);
  }
  TransferMesh part;
  part.tets.resize(Eigen::Index(kept.size()), 4);
  for (std::size_t k = 0; k < kept.size(); ++k)
    part.tets.row(Eigen::Index(k)) = full.tets.row(kept[k]);
  part.vertices = full.vertices;
  part.labels = Eigen::VectorXi::Ones(Eigen::Index(kept.size()));
  // Largest face-connected piece.
  const auto T1 = faceNeighbours(part);
  std::vector<int> component(kept.size(), -1), sizes;
  for (int s = 0; s < int(kept.size()); ++s) {
    if (component[s] >= 0) continue;
    const int id = int(sizes.size());
    sizes.push_back(0);
    std::vector<int> stack{s};
    component[s] = id;
    while (!stack.empty()) {
      const int t = stack.back();
      stack.pop_back();
      ++sizes[id];
      for (int n : T1[t])
        if (component[n] < 0) component[n] = id, stack.push_back(n);
    }
  }
  const int largest = int(std::max_element(sizes.begin(), sizes.end()) - sizes.begin());
  std::vector<int> newIndex(full.vertices.rows(), -1);
  Problem p;
  std::vector<Eigen::RowVector4i> tets;
  std::vector<Eigen::RowVector3d> vertices;
  for (int t = 0; t < int(kept.size()); ++t) {
    if (component[t] != largest) continue;
    Eigen::RowVector4i tet;
    for (int c = 0; c < 4; ++c) {
      int& v = newIndex[part.tets(t, c)];
      if (v < 0) v = int(vertices.size()), vertices.push_back(full.vertices.row(part.tets(t, c)));
      tet[c] = v;
    }
    tets.push_back(tet);
  }
  p.mesh.vertices.resize(Eigen::Index(vertices.size()), 3);
  for (std::size_t v = 0; v < vertices.size(); ++v)
    p.mesh.vertices.row(Eigen::Index(v)) = vertices[v];
  p.mesh.tets.resize(Eigen::Index(tets.size()), 4);
  for (std::size_t t = 0; t < tets.size(); ++t) p.mesh.tets.row(Eigen::Index(t)) = tets[t];
  p.mesh.labels = Eigen::VectorXi::Ones(Eigen::Index(tets.size()));
  for (int v = 0; v < int(vertices.size()); ++v)
    if (vertices[std::size_t(v)].z() > elbow.z()) p.Vc.push_back(v);
  p.Tc = insideTets(p.mesh, p.Vc);
  return p;
}

enum class Motion { Rigid, Affine, Random };

// Targets for V_c: a rigid motion, a general affine map, or independent random displacements.
Eigen::MatrixX3d targetsFor(const Problem& p, Motion motion, unsigned seed, Eigen::Matrix3d* A,
                            Eigen::Vector3d* shift) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> u(-1, 1);
  *A = Eigen::Matrix3d::Identity();
  *shift = Eigen::Vector3d(u(rng), u(rng), u(rng)) * 20;
  if (motion == Motion::Rigid)
    *A = Eigen::AngleAxisd(0.7 * u(rng), Eigen::Vector3d(u(rng), u(rng), 1).normalized())
             .toRotationMatrix();
  if (motion == Motion::Affine)
    *A = Eigen::Matrix3d::Identity() + 0.3 * Eigen::Matrix3d::NullaryExpr([&] { return u(rng); });
  Eigen::MatrixX3d targets(Eigen::Index(p.Vc.size()), 3);
  for (std::size_t k = 0; k < p.Vc.size(); ++k) {
    Eigen::Vector3d x = *A * p.mesh.vertices.row(p.Vc[k]).transpose() + *shift;
    if (motion == Motion::Random) x += 3.0 * Eigen::Vector3d(u(rng), u(rng), u(rng));
    targets.row(Eigen::Index(k)) = x.transpose();
  }
  return targets;
}

double relativeDifference(const Eigen::MatrixXd& a, const Eigen::MatrixXd& b) {
  return (a - b).cwiseAbs().maxCoeff() / std::max(1.0, b.cwiseAbs().maxCoeff());
}

// Production against the reference for every motion; and what eq. 1-3 say of the result.
void checkAgainstReference(const Problem& p, const std::string& name) {
  ASSERT_FALSE(p.Tc.empty()) << name;
  ASSERT_LT(p.Vc.size(), std::size_t(p.mesh.vertices.rows())) << name << ": nothing to solve";
  const RigiditySolver solver(p.mesh, p.Vc, p.Tc);
  ASSERT_EQ(solver.unconstrainedVertices(), 0) << name;
  const auto T1 = faceNeighbours(p.mesh);
  for (const Motion motion : {Motion::Rigid, Motion::Affine, Motion::Random}) {
    const std::string what = name + (motion == Motion::Rigid    ? ", rigid"
                                     : motion == Motion::Affine ? ", affine"
                                                                : ", random");
    Eigen::Matrix3d A;
    Eigen::Vector3d shift;
    const Eigen::MatrixX3d targets = targetsFor(p, motion, 7, &A, &shift);
    std::vector<Eigen::Matrix3d> B;
    const Eigen::MatrixX3d x = solver.solve(targets, &B);
    const Solution ref = referenceSolve(p, targets);
    double worstB = 0;
    for (int t = 0; t < int(B.size()); ++t)
      worstB = std::max(worstB, relativeDifference(B[t], ref.B[t]));
    EXPECT_LT(worstB, 1e-9) << what << ": B_t (eq. 3)";
    EXPECT_LT(relativeDifference(x, ref.x), 1e-9) << what << ": positions (eq. 4)";
    // An affine motion of V_c is reproduced everywhere: every B_t is A, every vertex A x + t.
    if (motion != Motion::Random) {
      for (int t = 0; t < int(B.size()); ++t)
        EXPECT_LT(relativeDifference(B[t], A), 1e-9) << what << ": tet " << t;
      const Eigen::MatrixX3d expected =
          (p.mesh.vertices * A.transpose()).rowwise() + shift.transpose();
      EXPECT_LT(relativeDifference(x, expected), 1e-9) << what;
    }
    // Eq. 1 directly against ErrorMetric's e_t (eq. 5), and eq. 3's energy stationary at B.
    const Eigen::VectorXd e = tetErrors(p.mesh, B);
    for (int t = 0; t < int(B.size()); ++t)
      EXPECT_NEAR(e[t], deltaB(p.mesh, T1, B, t).norm(), 1e-9 * std::max(1.0, e[t])) << what;
    const double E0 = freeEnergy(p, T1, B);
    std::mt19937 rng(11);
    std::normal_distribution<double> g;
    const std::set<int> fixed(p.Tc.begin(), p.Tc.end());
    for (int trial = 0; trial < 3; ++trial) {
      std::vector<Eigen::Matrix3d> moved = B;
      for (int t = 0; t < int(B.size()); ++t)
        if (!fixed.count(t))
          moved[t] += 1e-3 * Eigen::Matrix3d::NullaryExpr([&] { return g(rng); });
      EXPECT_GE(freeEnergy(p, T1, moved), E0 * (1 - 1e-12)) << what << ": eq. 3 not minimal";
    }
  }
}

}  // namespace

TEST(RigiditySolverReference, HandMadeTetsOfUnequalVolumes) {
  const Problem p = handMade();
  double lo = 1e300, hi = 0;
  for (int t = 0; t < 5; ++t)
    lo = std::min(lo, volumeOf(p.mesh, t)), hi = std::max(hi, volumeOf(p.mesh, t));
  ASSERT_GT(hi / lo, 3) << "the volumes must differ for the weights to matter";
  ASSERT_EQ(p.Tc.size(), 2u);
  checkAgainstReference(p, "hand-made");
}

TEST(RigiditySolverReference, JitteredMeshesWithRandomInsideSets) {
  for (unsigned seed : {1u, 2u, 3u})
    checkAgainstReference(jittered(seed), "jittered " + std::to_string(seed));
}

TEST(RigiditySolverReference, RandomDelaunayMeshesWithRandomInsideSets) {
  int tested = 0;
  for (unsigned seed = 1; seed <= 40 && tested < 4; ++seed) {  // the first four usable seeds
    const std::optional<Problem> p = delaunay(seed);
    if (!p) continue;
    ++tested;
    double lo = 1e300, hi = 0;
    for (int t = 0; t < int(p->mesh.tets.rows()); ++t)
      lo = std::min(lo, volumeOf(p->mesh, t)), hi = std::max(hi, volumeOf(p->mesh, t));
    EXPECT_GT(hi / lo, 100) << "seed " << seed << ": tets of very unequal volumes";
    checkAgainstReference(*p, "Delaunay " + std::to_string(seed) + " (" +
                                  std::to_string(p->mesh.tets.rows()) + " tets)");
  }
  EXPECT_EQ(tested, 4) << "too few of 40 seeds gave an inside set that drives every part";
}

TEST(RigiditySolverReference, ThePhantomsTransferMeshAroundTheElbow) {
  const Problem p = phantomElbowPart();
  ASSERT_GT(p.mesh.tets.rows(), 100);
  checkAgainstReference(p, "phantom elbow (" + std::to_string(p.mesh.tets.rows()) + " tets)");
}
