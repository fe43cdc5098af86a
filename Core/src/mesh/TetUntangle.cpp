// untangleTets: Gauss-Seidel sweeps of damped Newton steps per vertex on the regularised
// mean-ratio energy plus the held volumes' misfit (TetUntangle.h).
#include "TetUntangle.h"

#include <Eigen/Dense>

#include <algorithm>
#include <array>
#include <cmath>
#include <map>
#include <set>

namespace repose {
namespace mesh_detail {

std::array<Eigen::Vector3d, 4> volumeGradients(const std::array<Eigen::Vector3d, 4>& x) {
  const Eigen::Vector3d b = x[1] - x[0], c = x[2] - x[0], d = x[3] - x[0];
  std::array<Eigen::Vector3d, 4> g;
  g[1] = c.cross(d) / 6;
  g[2] = d.cross(b) / 6;
  g[3] = b.cross(c) / 6;
  g[0] = -(g[1] + g[2] + g[3]);
  return g;
}

double volumeOf(const std::array<Eigen::Vector3d, 4>& x) {
  return (x[1] - x[0]).cross(x[2] - x[0]).dot(x[3] - x[0]) / 6;
}

}  // namespace mesh_detail

namespace {

using mesh_detail::volumeGradients;
using mesh_detail::volumeOf;

struct TetShape {
  Eigen::Matrix3d restInverse;  // D^-1
  double restInverseDet = 0;    // det D^-1
};

// The tet's energy and its gradient in corner `corner`.
double tetEnergy(const std::array<Eigen::Vector3d, 4>& x, const TetShape& shape, double delta,
                 double volumeWeight, int corner, Eigen::Vector3d* gradient) {
  Eigen::Matrix3d E;
  for (int c = 0; c < 3; ++c) E.col(c) = x[std::size_t(c) + 1] - x[0];
  const Eigen::Matrix3d S = E * shape.restInverse;
  const double d = S.determinant(), F = S.squaredNorm();
  const double root = std::sqrt(d * d + 4 * delta * delta);
  const double sigma = (d + root) / 2;
  const double s23 = std::cbrt(sigma * sigma);
  const double energy = F / (3 * s23) + volumeWeight * (d - 1) * (d - 1);
  if (gradient) {
    Eigen::Matrix3d cof;
    cof.col(0) = E.col(1).cross(E.col(2));
    cof.col(1) = E.col(2).cross(E.col(0));
    cof.col(2) = E.col(0).cross(E.col(1));
    const double dSigma = 0.5 * (1 + d / root);
    const Eigen::Matrix3d dE =
        2 * S * shape.restInverse.transpose() / (3 * s23) -
        ((2.0 / 9.0) * F / (s23 * sigma) * dSigma - 2 * volumeWeight * (d - 1)) *
            shape.restInverseDet * cof;
    *gradient =
        corner == 0 ? Eigen::Vector3d(-dE.rowwise().sum()) : Eigen::Vector3d(dE.col(corner - 1));
  }
  return energy;
}

}  // namespace

UntangleReport untangleTets(const TransferMesh& mesh, const std::vector<int>& freeVertices,
                            const std::vector<int>& tets, UntangleConstraints& held,
                            Eigen::MatrixX3d& deformed, const UntangleOptions& options) {
  UntangleReport report;
  const Eigen::Index nv = mesh.vertices.rows();
  auto corners = [&](const Eigen::MatrixX3d& x, int t) {
    std::array<Eigen::Vector3d, 4> c;
    for (int k = 0; k < 4; ++k) c[std::size_t(k)] = x.row(mesh.tets(t, k)).transpose();
    return c;
  };
  auto countInverted = [&]() {
    int n = 0;
    for (const int t : tets) n += volumeOf(corners(deformed, t)) <= 0;
    return n;
  };
  report.invertedBefore = report.invertedAfter = countInverted();
  if (report.invertedBefore == 0 || freeVertices.empty()) return report;

  std::vector<TetShape> shape(std::size_t(mesh.tets.rows()));
  // Per vertex, the tets given around it and its corner in each.
  std::vector<std::vector<std::pair<int, int>>> around(static_cast<std::size_t>(nv));
  for (const int t : tets) {
    Eigen::Matrix3d D;
    for (int c = 0; c < 3; ++c)
      D.col(c) =
          (mesh.vertices.row(mesh.tets(t, c + 1)) - mesh.vertices.row(mesh.tets(t, 0))).transpose();
    shape[std::size_t(t)].restInverse = D.inverse();
    shape[std::size_t(t)].restInverseDet = 1 / D.determinant();
    for (int k = 0; k < 4; ++k) around[std::size_t(mesh.tets(t, k))].emplace_back(t, k);
  }
  // Each free vertex's shortest rest edge: how far one step may move it.
  std::vector<double> reach(std::size_t(nv), 1e300);
  for (const int v : freeVertices)
    for (const auto& [t, k] : around[std::size_t(v)])
      for (int j = 0; j < 4; ++j)
        if (j != k)
          reach[std::size_t(v)] =
              std::min(reach[std::size_t(v)],
                       (mesh.vertices.row(v) - mesh.vertices.row(mesh.tets(t, j))).norm());

  // f(p) for vertex v at p (the held residuals as they would be), and its gradient.
  std::vector<double> trial(held.amount.size());
  double delta = options.delta;  // lowered when the sweeps stall (see below)
  auto objective = [&](int v, const Eigen::Vector3d& p, Eigen::Vector3d* gradient) {
    double f = 0;
    if (gradient) gradient->setZero();
    std::fill(trial.begin(), trial.end(), 0.0);
    std::vector<std::pair<int, Eigen::Vector3d>> constraintGradient;
    for (const auto& [t, k] : around[std::size_t(v)]) {
      auto x = corners(deformed, t);
      const double before = volumeOf(x);
      x[std::size_t(k)] = p;
      Eigen::Vector3d g;
      f += tetEnergy(x, shape[std::size_t(t)], delta, options.volumeWeight, k,
                     gradient ? &g : nullptr);
      if (gradient) *gradient += g;
      const int from = held.offsets[std::size_t(t)], to = held.offsets[std::size_t(t) + 1];
      if (from == to) continue;
      const double change = volumeOf(x) - before;
      const Eigen::Vector3d dv = gradient ? volumeGradients(x)[std::size_t(k)] : Eigen::Vector3d();
      for (int e = from; e < to; ++e) {
        const auto& [c, w] = held.entries[std::size_t(e)];
        trial[std::size_t(c)] += w * change;
        if (gradient) constraintGradient.emplace_back(c, w * dv);
      }
    }
    for (std::size_t c = 0; c < trial.size(); ++c) {
      if (trial[c] == 0) continue;
      const double before = held.residual[Eigen::Index(c)] / held.amount[c];
      const double after = (held.residual[Eigen::Index(c)] + trial[c]) / held.amount[c];
      f += options.kappa * (after * after - before * before);
    }
    if (gradient)
      for (const auto& [c, g] : constraintGradient) {
        const double after =
            (held.residual[Eigen::Index(c)] + trial[std::size_t(c)]) / held.amount[std::size_t(c)];
        *gradient += options.kappa * 2 * after / held.amount[std::size_t(c)] * g;
      }
    return f;
  };
  auto moveTo = [&](int v, const Eigen::Vector3d& p) {
    for (const auto& [t, k] : around[std::size_t(v)]) {
      auto x = corners(deformed, t);
      const double before = volumeOf(x);
      x[std::size_t(k)] = p;
      const double change = volumeOf(x) - before;
      for (int e = held.offsets[std::size_t(t)]; e < held.offsets[std::size_t(t) + 1]; ++e)
        held.residual[held.entries[std::size_t(e)].first] +=
            held.entries[std::size_t(e)].second * change;
    }
    deformed.row(v) = p.transpose();
  };

  int fewest = report.invertedBefore, stalled = 0;
  for (int sweep = 0; sweep < options.sweeps; ++sweep) {
    // The vertices of the tets inside out or nearly (det S < 0.1), and one ring around them.
    std::vector<char> near(std::size_t(nv), 0), candidate(std::size_t(nv), 0);
    for (const int t : tets) {
      auto x = corners(deformed, t);
      if (6 * volumeOf(x) * shape[std::size_t(t)].restInverseDet < 0.1)
        for (int k = 0; k < 4; ++k) near[std::size_t(mesh.tets(t, k))] = 1;
    }
    for (const int t : tets) {
      bool any = false;
      for (int k = 0; k < 4; ++k) any = any || near[std::size_t(mesh.tets(t, k))];
      if (any)
        for (int k = 0; k < 4; ++k) candidate[std::size_t(mesh.tets(t, k))] = 1;
    }
    double moved = 0;
    for (const int v : freeVertices) {
      if (!candidate[std::size_t(v)]) continue;
      for (int step = 0; step < options.stepsPerVertex; ++step) {
        const Eigen::Vector3d p0 = deformed.row(v).transpose();
        Eigen::Vector3d g;
        const double f0 = objective(v, p0, &g);
        if (!std::isfinite(f0) || g.norm() < 1e-12) break;
        // Newton's direction from a finite-difference Hessian where it is positive definite,
        // else steepest descent.
        const double h = 1e-4 * reach[std::size_t(v)];
        Eigen::Matrix3d H;
        for (int c = 0; c < 3; ++c) {
          Eigen::Vector3d q = p0, gq;
          q[c] += h;
          objective(v, q, &gq);
          H.col(c) = (gq - g) / h;
        }
        H = (H + H.transpose()).eval() / 2;
        Eigen::Vector3d dir = -g;
        const Eigen::LDLT<Eigen::Matrix3d> ldlt(H);
        if (ldlt.info() == Eigen::Success && (ldlt.vectorD().array() > 0).all())
          dir = -ldlt.solve(g);
        if (dir.dot(g) >= 0) dir = -g;
        double length = dir.norm();
        const double cap = 0.5 * reach[std::size_t(v)];
        if (length > cap) dir *= cap / length, length = cap;
        double a = 1;
        bool accepted = false;
        for (int halving = 0; halving < 16; ++halving, a *= 0.5) {
          const Eigen::Vector3d p = p0 + a * dir;
          if (objective(v, p, nullptr) < f0 + 1e-4 * a * dir.dot(g)) {
            moveTo(v, p);
            moved = std::max(moved, a * length);
            accepted = true;
            break;
          }
        }
        if (!accepted) break;
      }
    }
    report.sweeps = sweep + 1;
    report.invertedAfter = countInverted();
    if (options.cancel && options.cancel->load()) break;
    if (report.invertedAfter == 0 && moved < 1e-3) break;
    // Sweeps that turn no more tets back: a sharper barrier (a smaller delta) pushes the tets
    // still slightly inside out harder, as Escobar et al. lower delta as the mesh untangles.
    if (report.invertedAfter < fewest) {
      fewest = report.invertedAfter, stalled = 0;
    } else if (++stalled >= options.stallSweeps || moved < 1e-6) {
      if (delta <= options.smallestDelta) break;
      delta = std::max(options.smallestDelta, delta / 4), stalled = 0;
    }
  }
  return report;
}

int resetInvertedKnots(const TransferMesh& mesh, const std::vector<char>& isFree,
                       const std::vector<int>& tets, Eigen::MatrixX3d& deformed) {
  const Eigen::Index nv = mesh.vertices.rows();
  auto corners = [&](const Eigen::MatrixX3d& x, int t) {
    std::array<Eigen::Vector3d, 4> c;
    for (int k = 0; k < 4; ++k) c[std::size_t(k)] = x.row(mesh.tets(t, k)).transpose();
    return c;
  };
  const Eigen::MatrixX3d rest = mesh.vertices;
  auto inverted = [&](int t) { return volumeOf(corners(deformed, t)) < 0; };
  // The tets given around each vertex.
  std::vector<std::vector<int>> around(static_cast<std::size_t>(nv));
  for (const int t : tets)
    for (int k = 0; k < 4; ++k) around[std::size_t(mesh.tets(t, k))].push_back(t);
  // Knots: inverted tets joined through shared vertices (union-find on the vertices).
  std::vector<int> root(static_cast<std::size_t>(nv));
  for (Eigen::Index v = 0; v < nv; ++v) root[std::size_t(v)] = int(v);
  auto find = [&](int v) {
    while (root[std::size_t(v)] != v)
      v = root[std::size_t(v)] = root[std::size_t(root[std::size_t(v)])];
    return v;
  };
  std::vector<int> bad;
  for (const int t : tets)
    if (inverted(t)) {
      bad.push_back(t);
      for (int k = 1; k < 4; ++k) root[std::size_t(find(mesh.tets(t, k)))] = find(mesh.tets(t, 0));
    }
  std::map<int, std::vector<int>> knots;
  for (const int t : bad) knots[find(mesh.tets(t, 0))].push_back(t);
  int reset = 0;
  for (const auto& [id, knot] : knots) {
    // The knot's vertices and the ring around them move (the free ones); the vertices of the
    // tets around those border it.
    std::set<int> inner;
    for (const int t : knot)
      for (int k = 0; k < 4; ++k)
        for (const int u : around[std::size_t(mesh.tets(t, k))])
          for (int m = 0; m < 4; ++m)
            if (isFree[std::size_t(mesh.tets(u, m))]) inner.insert(mesh.tets(u, m));
    std::set<int> border;
    for (const int v : inner)
      for (const int u : around[std::size_t(v)])
        for (int m = 0; m < 4; ++m)
          if (!inner.count(mesh.tets(u, m))) border.insert(mesh.tets(u, m));
    if (border.size() < 4) continue;
    // The affine map x -> A x + b of least squares from the border's rest to posed positions.
    Eigen::MatrixXd M(border.size(), 4), Y(border.size(), 3);
    Eigen::Index r = 0;
    for (const int v : border) {
      M.row(r) << rest.row(v), 1.0;
      Y.row(r++) = deformed.row(v);
    }
    const Eigen::MatrixXd X = M.colPivHouseholderQr().solve(Y);  // 4 x 3
    const Eigen::Matrix3d A = X.topRows<3>().transpose();
    if (!(A.determinant() > 0)) continue;
    for (const int v : inner)
      deformed.row(v) = (A * rest.row(v).transpose() + X.row(3).transpose()).transpose();
    ++reset;
  }
  return reset;
}

}  // namespace repose
