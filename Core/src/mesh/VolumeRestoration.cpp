// restoreVolumes: Gauss-Newton on the tets' volumes with every touched body part's volume held
// exactly (VolumeRestoration.h).
#include "repose/mesh/VolumeRestoration.h"

#include "TetUntangle.h"
#include "repose/numerics/SparseCholesky.h"

#include <Eigen/Dense>
#include <Eigen/SparseCore>

#include <algorithm>
#include <cmath>
#include <map>
#include <unordered_map>
#include <utility>

namespace repose {

using mesh_detail::volumeGradients;
using mesh_detail::volumeOf;

VolumeRestorationReport restoreVolumes(const TransferMesh& mesh, const std::vector<char>& movable,
                                       Eigen::MatrixX3d& deformed,
                                       const VolumeRestorationOptions& options,
                                       const std::vector<char>& held, const TetTissues* tissues) {
  VolumeRestorationReport report;
  const Eigen::Index nv = mesh.vertices.rows(), nt = mesh.tets.rows();
  auto corners = [&](const Eigen::MatrixX3d& x, Eigen::Index t) {
    std::array<Eigen::Vector3d, 4> c;
    for (int k = 0; k < 4; ++k) c[std::size_t(k)] = x.row(mesh.tets(t, k)).transpose();
    return c;
  };
  std::vector<double> rest(static_cast<std::size_t>(nt)), posed(static_cast<std::size_t>(nt));
  std::map<int, std::pair<double, double>> partVolume;  // label -> (rest, posed)
  for (Eigen::Index t = 0; t < nt; ++t) {
    rest[std::size_t(t)] = volumeOf(corners(mesh.vertices, t));
    posed[std::size_t(t)] = volumeOf(corners(deformed, t));
    auto& p = partVolume[mesh.labels[t]];
    p.first += rest[std::size_t(t)], p.second += posed[std::size_t(t)];
    report.invertedBefore += posed[std::size_t(t)] < 0;
  }
  for (const auto& [label, v] : partVolume)
    if (v.first > 0)
      report.worstPartBefore =
          std::max(report.worstPartBefore, std::fabs(100 * (v.second / v.first - 1)));
  report.worstPartAfter = report.worstPartBefore;
  report.invertedAfter = report.invertedBefore;
  // Folds: the movable surface vertices inside another layer of tissue.
  const auto deepest = [](const std::vector<SelfContact>& c) {
    double d = 0;
    for (const SelfContact& x : c) d = std::max(d, x.depthMm);
    return d;
  };
  const bool withContacts = options.contacts && options.contactWeight > 0;
  std::vector<SelfContact> contacts;
  if (withContacts) {
    contacts = options.contacts->find(deformed, &movable);
    report.contactsBefore = report.contactsAfter = int(contacts.size());
    report.deepestContactBeforeMm = report.deepestContactAfterMm = deepest(contacts);
  }

  // Free vertices: those of tets off their volume, grown by `rings`, that may move.
  std::vector<char> free(std::size_t(nv), 0);
  for (Eigen::Index t = 0; t < nt; ++t)
    if (std::fabs(posed[std::size_t(t)] / rest[std::size_t(t)] - 1) > options.tolerance)
      for (int k = 0; k < 4; ++k) free[std::size_t(mesh.tets(t, k))] = 1;
  for (const SelfContact& c : contacts) free[std::size_t(c.vertex)] = 1;
  for (int ring = 0; ring < options.rings; ++ring) {
    std::vector<char> grown = free;
    for (Eigen::Index t = 0; t < nt; ++t) {
      bool any = false;
      for (int k = 0; k < 4; ++k) any = any || free[std::size_t(mesh.tets(t, k))];
      if (any)
        for (int k = 0; k < 4; ++k) grown[std::size_t(mesh.tets(t, k))] = 1;
    }
    free.swap(grown);
  }
  std::vector<int> index(std::size_t(nv), -1);
  int n = 0;
  for (Eigen::Index v = 0; v < nv; ++v)
    if (free[std::size_t(v)] && movable[std::size_t(v)]) index[std::size_t(v)] = n++;
  report.freeVertices = n;
  if (n == 0) return report;

  // The tets a free vertex touches, and the parts they belong to (each held at its rest volume).
  std::vector<Eigen::Index> active;
  std::map<int, int> partRow;
  for (Eigen::Index t = 0; t < nt; ++t) {
    bool any = false;
    for (int k = 0; k < 4; ++k) any = any || index[std::size_t(mesh.tets(t, k))] >= 0;
    if (!any) continue;
    active.push_back(t);
    partRow.try_emplace(mesh.labels[t], int(partRow.size()));
  }
  report.parts = int(partRow.size());
  // The tets each part's constraint sums: the reached ones, and those held besides (of the parts
  // reached).
  std::vector<Eigen::Index> summed = active;
  if (!held.empty()) {
    std::vector<char> isActive(std::size_t(nt), 0);
    for (const Eigen::Index t : active) isActive[std::size_t(t)] = 1;
    for (Eigen::Index t = 0; t < nt; ++t)
      if (held[std::size_t(t)] && !isActive[std::size_t(t)] && partRow.count(mesh.labels[t]))
        summed.push_back(t);
  }
  // Edges with a free end: the correction's smoothness.
  std::vector<std::pair<int, int>> edges;
  {
    std::vector<std::pair<int, int>> all;
    for (const Eigen::Index t : active)
      for (int a = 0; a < 4; ++a)
        for (int b = a + 1; b < 4; ++b) {
          int u = mesh.tets(t, a), w = mesh.tets(t, b);
          if (u > w) std::swap(u, w);
          all.emplace_back(u, w);
        }
    std::sort(all.begin(), all.end());
    all.erase(std::unique(all.begin(), all.end()), all.end());
    edges = std::move(all);
  }
  double meanRest = 0, meanEdge2 = 0;
  for (const Eigen::Index t : active) meanRest += rest[std::size_t(t)];
  meanRest /= double(active.size());
  for (const auto& [a, b] : edges)
    meanEdge2 += (mesh.vertices.row(a) - mesh.vertices.row(b)).squaredNorm();
  meanEdge2 /= double(std::max<std::size_t>(1, edges.size()));
  const double lambda = options.smoothness * meanRest / std::max(1e-12, meanEdge2);
  // Each free vertex's shortest rest edge: how far one round may move it.
  std::vector<double> shortest(std::size_t(n), 1e300);
  for (const auto& [a, b] : edges) {
    const double length = (mesh.vertices.row(a) - mesh.vertices.row(b)).norm();
    for (const int v : {a, b})
      if (index[std::size_t(v)] >= 0)
        shortest[std::size_t(index[std::size_t(v)])] =
            std::min(shortest[std::size_t(index[std::size_t(v)])], length);
  }

  // The tissues held besides the parts: each label of G in the summed tets with enough voxels
  // there to be counted (64: a handful of voxels would only add noise). Each constraint is scaled
  // by its rest amount, so all say a fraction.
  std::map<int, int> tissueRow;
  std::vector<double> amount;  // per constraint: the part's rest volume or the tissue's voxels
  amount.assign(partRow.size(), 0.0);
  for (const Eigen::Index t : summed)
    amount[std::size_t(partRow.at(mesh.labels[t]))] += rest[std::size_t(t)];
  if (tissues && !tissues->empty()) {
    std::map<int, double> voxels;
    for (const Eigen::Index t : summed)
      for (int e = tissues->offsets[std::size_t(t)]; e < tissues->offsets[std::size_t(t) + 1]; ++e)
        voxels[tissues->entries[std::size_t(e)].first] += tissues->entries[std::size_t(e)].second;
    for (const auto& [label, count] : voxels)
      if (count >= 64) {
        tissueRow[label] = int(amount.size());
        amount.push_back(count);
      }
  }
  report.tissues = int(tissueRow.size());

  const Eigen::MatrixX3d start = deformed;
  const int unknowns = 3 * n, constraints = int(amount.size());
  // The worst part's misfit (a fraction) of the positions at hand: the rounds keep the
  // best positions they saw, so a round that goes astray (a constraint no step can meet, a tet
  // far inside out) never leaves the mesh worse than it found it.
  // Each constraint's volume change (mm^3) at positions x, over the tets the correction reaches:
  // a change elsewhere in the part (tissue dragged along a contact) is not made up for here.
  auto residual = [&](const Eigen::MatrixX3d& x) {
    Eigen::VectorXd r = Eigen::VectorXd::Zero(constraints);
    for (const Eigen::Index t : summed) {
      const double change = volumeOf(corners(x, t)) - rest[std::size_t(t)];
      r[partRow.at(mesh.labels[t])] += change;
      if (!tissueRow.empty())
        for (int e = tissues->offsets[std::size_t(t)]; e < tissues->offsets[std::size_t(t) + 1];
             ++e) {
          const auto it = tissueRow.find(tissues->entries[std::size_t(e)].first);
          if (it != tissueRow.end())
            r[it->second] +=
                change / rest[std::size_t(t)] * tissues->entries[std::size_t(e)].second;
        }
    }
    return r;
  };
  auto misfit = [&](const Eigen::MatrixX3d& x) {
    const Eigen::VectorXd r = residual(x);
    // The parts' rows: the tissues' follow them (a tissue whose few voxels lie in tets turned
    // inside out may stay far off whatever a round does).
    double worst = 0;
    for (std::size_t c = 0; c < partRow.size(); ++c)
      worst = std::max(worst, std::fabs(r[Eigen::Index(c)]) / amount[c]);
    return worst;
  };
  // The contacts of the free vertices at the positions at hand (SelfContact.h). Those found
  // above among the movable vertices are all free already: they seeded the free set.
  std::vector<char> isFree(std::size_t(nv), 0);
  for (Eigen::Index v = 0; v < nv; ++v) isFree[std::size_t(v)] = index[std::size_t(v)] >= 0;
  const auto findContacts = [&](const Eigen::MatrixX3d& x) {
    return withContacts ? options.contacts->find(x, &isFree) : std::vector<SelfContact>();
  };
  // Every contact found in a round stays as a one-sided plane (the other layer's surface there)
  // until the end: pushed out, a vertex the planes forgot would be pulled back in by the rest of
  // the step, and the rounds would swing.
  std::unordered_map<int, SelfContact> planes;
  const auto remember = [&] {
    for (const SelfContact& c : contacts) planes[c.vertex] = c;
  };
  remember();
  // One Gauss-Newton step from the positions at hand: the correction of every free vertex
  // (3 unknowns each, index order).
  auto gaussNewtonStep = [&]() -> Eigen::VectorXd {
    std::vector<Eigen::Triplet<double>> triplets;
    triplets.reserve(active.size() * 78 + edges.size() * 12 + std::size_t(unknowns));
    Eigen::VectorXd rhs = Eigen::VectorXd::Zero(unknowns);
    Eigen::MatrixXd C = Eigen::MatrixXd::Zero(unknowns, constraints);  // columns: parts' gradients
    Eigen::VectorXd partResidual = residual(deformed);
    std::vector<double> stiffness(planes.empty() ? 0 : std::size_t(n), 0.0);
    for (int c = 0; c < constraints; ++c) partResidual[c] /= amount[std::size_t(c)];
    for (const Eigen::Index t : active) {
      const auto x = corners(deformed, t);
      const auto g = volumeGradients(x);
      const double r = volumeOf(x) - rest[std::size_t(t)];
      const double w = 1 / rest[std::size_t(t)];
      const int column = partRow.at(mesh.labels[t]);
      // The tissues this tet holds: their constraints' gradients, voxels over the rest volume.
      std::vector<std::pair<int, double>> carried;
      if (!tissueRow.empty())
        for (int e = tissues->offsets[std::size_t(t)]; e < tissues->offsets[std::size_t(t) + 1];
             ++e) {
          const auto it = tissueRow.find(tissues->entries[std::size_t(e)].first);
          if (it != tissueRow.end())
            carried.emplace_back(it->second, tissues->entries[std::size_t(e)].second /
                                                 rest[std::size_t(t)] /
                                                 amount[std::size_t(it->second)]);
        }
      for (int a = 0; a < 4; ++a) {
        const int ia = index[std::size_t(mesh.tets(t, a))];
        if (ia < 0) continue;
        if (!stiffness.empty())
          stiffness[std::size_t(ia)] += w * g[std::size_t(a)].squaredNorm() / 3;
        for (int c = 0; c < 3; ++c) {
          rhs[3 * ia + c] -= w * r * g[std::size_t(a)][c];
          C(3 * ia + c, column) += g[std::size_t(a)][c] / amount[std::size_t(column)];
          for (const auto& [row, scale] : carried)
            C(3 * ia + c, row) += scale * g[std::size_t(a)][c];
        }
        for (int b = 0; b < 4; ++b) {
          const int ib = index[std::size_t(mesh.tets(t, b))];
          if (ib < 0) continue;
          for (int c = 0; c < 3; ++c)
            for (int e = 0; e < 3; ++e)
              triplets.emplace_back(3 * ia + c, 3 * ib + e,
                                    w * g[std::size_t(a)][c] * g[std::size_t(b)][e]);
        }
      }
    }
    // Smoothness of the whole correction so far (deformed - start), edge by edge.
    for (const auto& [u, w] : edges) {
      const int iu = index[std::size_t(u)], iw = index[std::size_t(w)];
      const Eigen::Vector3d du = deformed.row(u) - start.row(u),
                            dw = deformed.row(w) - start.row(w);
      const Eigen::Vector3d diff = du - dw;
      for (int c = 0; c < 3; ++c) {
        if (iu >= 0) {
          triplets.emplace_back(3 * iu + c, 3 * iu + c, lambda);
          rhs[3 * iu + c] -= lambda * diff[c];
        }
        if (iw >= 0) {
          triplets.emplace_back(3 * iw + c, 3 * iw + c, lambda);
          rhs[3 * iw + c] += lambda * diff[c];
        }
        if (iu >= 0 && iw >= 0) {
          triplets.emplace_back(3 * iu + c, 3 * iw + c, -lambda);
          triplets.emplace_back(3 * iw + c, 3 * iu + c, -lambda);
        }
      }
    }
    // Folds: each contact pulls its vertex along its way out to `contactMarginMm` beyond the
    // other layer's surface, as stiff as `contactWeight` times the tets' volumes around it.
    for (const auto& [vertex, contact] : planes) {
      const int i = index[std::size_t(vertex)];
      if (i < 0) continue;
      const Eigen::Vector3d p = deformed.row(vertex).transpose();
      const double gap = (contact.point - p).dot(contact.normal) + options.contactMarginMm;
      if (gap <= 0) continue;  // beyond the plane by the margin: free to move
      const double k = options.contactWeight * std::max(stiffness[std::size_t(i)], lambda);
      for (int c = 0; c < 3; ++c) {
        rhs[3 * i + c] += k * gap * contact.normal[c];
        for (int e = 0; e < 3; ++e)
          triplets.emplace_back(3 * i + c, 3 * i + e, k * contact.normal[c] * contact.normal[e]);
      }
    }
    for (int i = 0; i < unknowns; ++i) triplets.emplace_back(i, i, 1e-9 * lambda + 1e-12);
    Eigen::SparseMatrix<double> A(unknowns, unknowns);
    A.setFromTriplets(triplets.begin(), triplets.end());
    SparseCholesky llt;
    llt.factorize(A, "the volume restoration");
    // min 1/2 d'Ad - rhs'd  subject to  C'd = -partResidual.
    Eigen::MatrixXd B(unknowns, constraints + 1);
    B.col(0) = rhs;
    B.rightCols(constraints) = C;
    const Eigen::MatrixXd S = llt.solve(B);  // A^-1 rhs, A^-1 C
    // Constraints that cannot all be met (two nearly alike, or a tissue no free vertex reaches)
    // are met as nearly as they can: a ridge on the Schur complement.
    Eigen::MatrixXd schur = C.transpose() * S.rightCols(constraints);
    const double ridge = 1e-9 * std::max(1e-300, schur.diagonal().cwiseAbs().maxCoeff());
    schur.diagonal().array() += ridge;
    const Eigen::VectorXd mu = schur.ldlt().solve(C.transpose() * S.col(0) + partResidual);
    return S.col(0) - S.rightCols(constraints) * mu;
  };
  // With contacts the rounds keep the positions of least misfit plus contact depth: an edge's
  // length of depth in all weighs as much as the tolerance on a part's volume.
  double meanEdge = 0;
  for (const auto& [a, b] : edges) meanEdge += (mesh.vertices.row(a) - mesh.vertices.row(b)).norm();
  meanEdge /= double(std::max<std::size_t>(1, edges.size()));
  const auto score = [&](const Eigen::MatrixX3d& x, const std::vector<SelfContact>& c) {
    double depth = 0;
    for (const SelfContact& s : c) depth += s.depthMm;
    return misfit(x) + options.tolerance * depth / std::max(1e-9, meanEdge);
  };
  Eigen::MatrixX3d best = deformed;
  double bestMisfit = score(deformed, contacts);
  const auto cancelled = [&] { return options.cancel && options.cancel->load(); };
  const int rounds =
      planes.empty() ? options.iterations : std::max(options.iterations, options.contactIterations);
  for (int round = 0; round < rounds; ++round) {
    if (cancelled()) {
      report.cancelled = true;
      return report;
    }
    const Eigen::VectorXd delta = gaussNewtonStep();
    // A linearised step is trusted only so far: no vertex moves more than its shortest rest edge
    // in one round (a tet turned far inside out, or constraints at odds, would otherwise
    // send a vertex across the body); the next round starts from where the vertices are.
    double moved = 0;
    for (Eigen::Index v = 0; v < nv; ++v) {
      const int i = index[std::size_t(v)];
      if (i < 0) continue;
      Eigen::RowVector3d d(delta[3 * i], delta[3 * i + 1], delta[3 * i + 2]);
      const double limit = shortest[std::size_t(i)];
      if (d.norm() > limit) d *= limit / d.norm();
      deformed.row(v) += d;
      moved = std::max(moved, d.norm());
    }
    report.iterations = round + 1;
    contacts = findContacts(deformed);
    remember();
    const double now = score(deformed, contacts);
    if (now < bestMisfit) bestMisfit = now, best = deformed;
    if (moved < 1e-4) break;  // settled
    // The volumes' rounds are done and no contact is left.
    if (contacts.empty() && round + 1 >= options.iterations) break;
  }
  deformed = best;

  // Creases (TetUntangle.h): the tets the restoration left inside out are untangled with every
  // held volume kept.
  if (options.untangleRounds > 0 && !cancelled()) {
    std::vector<int> freeVertices;
    for (Eigen::Index v = 0; v < nv; ++v)
      if (index[std::size_t(v)] >= 0) freeVertices.push_back(int(v));
    std::vector<int> activeTets(active.begin(), active.end());
    // Per summed tet, the constraints its volume enters and with what weight (volume change to
    // constraint change), the same sums the residual makes.
    UntangleConstraints held;
    held.offsets.assign(std::size_t(nt) + 1, 0);
    std::vector<std::vector<std::pair<int, double>>> perTet(static_cast<std::size_t>(nt));
    for (const Eigen::Index t : summed) {
      auto& rows = perTet[std::size_t(t)];
      rows.emplace_back(partRow.at(mesh.labels[t]), 1.0);
      if (!tissueRow.empty())
        for (int e = tissues->offsets[std::size_t(t)]; e < tissues->offsets[std::size_t(t) + 1];
             ++e) {
          const auto it = tissueRow.find(tissues->entries[std::size_t(e)].first);
          if (it != tissueRow.end())
            rows.emplace_back(it->second,
                              tissues->entries[std::size_t(e)].second / rest[std::size_t(t)]);
        }
    }
    for (Eigen::Index t = 0; t < nt; ++t)
      held.offsets[std::size_t(t) + 1] =
          held.offsets[std::size_t(t)] + int(perTet[std::size_t(t)].size());
    for (auto& rows : perTet) held.entries.insert(held.entries.end(), rows.begin(), rows.end());
    held.amount = amount;
    held.residual = residual(deformed);
    UntangleOptions uo;
    uo.sweeps = options.untangleRounds;
    uo.cancel = options.cancel;
    const UntangleReport u = untangleTets(mesh, freeVertices, activeTets, held, deformed, uo);
    report.untangled = u.invertedBefore - u.invertedAfter;
    // A fold the held volumes keep closed: untangled again under a weaker hold, with a sharper
    // barrier and more patience. On the 2 mm arms-resting phantom with both arms up 160 degrees
    // 6 tets stayed inside out at the shoulders, each with one to three free corners against a
    // bone's face; these sweeps turned every one back, the worst part then 0.03 % off its
    // volume (the gap variant's suites: 2 and 1 tets before, none after; docs/QUALITY.md).
    if (u.invertedAfter > 0 && options.relaxedKappa > 0 && !cancelled()) {
      UntangleOptions relaxed = uo;
      relaxed.kappa = options.relaxedKappa;
      relaxed.sweeps = options.relaxedSweeps;
      relaxed.stallSweeps = 4 * uo.stallSweeps;
      relaxed.smallestDelta = uo.smallestDelta / 128;
      // Kept only if it leaves fewer tets inside out: where bone corners pin a fold, the sweeps
      // can trade one inverted tet for others (VolumeRestorationTest).
      const Eigen::MatrixX3d strict = deformed;
      const UntangleReport again =
          untangleTets(mesh, freeVertices, activeTets, held, deformed, relaxed);
      report.relaxedUntangle = true;
      if (again.invertedAfter < u.invertedAfter)
        report.untangled += again.invertedBefore - again.invertedAfter;
      else
        deformed = strict;
      // Tets crushed towards a point: the shape energy is scale invariant and, regularised,
      // no longer rises as a tet shrinks to nothing, so a fold can settle on tets collapsed flat
      // and a hair inside out. On the real adult female's grid (1.775 x 1.775 x 4.84 mm) with
      // both arms up 160 degrees, 12 such tets stayed at the shoulders, 0.1 to 13 mm^3 at rest
      // and a few thousandths of a mm^3 inside out; a weight on each tet's own volume turned
      // every one back (measured before the tissues of the shell's voxels were held too, which
      // leaves 7 there: docs/ARCHITECTURE.md, "Creases"). Kept only if it leaves fewer inside out.
      const int left = std::min(u.invertedAfter, again.invertedAfter);
      if (left > 0 && options.crushedVolumeWeight > 0 && !cancelled()) {
        UntangleOptions crushed = relaxed;
        crushed.volumeWeight = options.crushedVolumeWeight;
        const Eigen::MatrixX3d before = deformed;
        held.residual = residual(deformed);
        const UntangleReport third =
            untangleTets(mesh, freeVertices, activeTets, held, deformed, crushed);
        report.crushedUntangle = true;
        if (third.invertedAfter < left)
          report.untangled += third.invertedBefore - third.invertedAfter;
        else
          deformed = before;
      }
    }
    // Knots the sweeps could not open (TetUntangle.h: resetInvertedKnots): set back on their
    // border's affine map and swept again; kept only if fewer tets are left inside out.
    auto insideOut = [&]() {
      int n = 0;
      for (const int t : activeTets) n += volumeOf(corners(deformed, t)) < 0;
      return n;
    };
    if (const int left = insideOut(); left > 0 && !cancelled()) {
      std::vector<char> isFree(std::size_t(nv), 0);
      for (const int v : freeVertices) isFree[std::size_t(v)] = 1;
      const Eigen::MatrixX3d before = deformed;
      if (const int knots = resetInvertedKnots(mesh, isFree, activeTets, deformed); knots > 0) {
        held.residual = residual(deformed);
        untangleTets(mesh, freeVertices, activeTets, held, deformed, uo);
        const int now = insideOut();
        if (now < left)
          report.untangled += left - now, report.knotsReset = knots;
        else
          deformed = before;
      }
    }
  }

  if (cancelled()) {
    report.cancelled = true;
    return report;
  }
  std::map<int, std::pair<double, double>> after;
  report.invertedAfter = 0;
  for (Eigen::Index t = 0; t < nt; ++t) {
    const double v = volumeOf(corners(deformed, t));
    auto& p = after[mesh.labels[t]];
    p.first += rest[std::size_t(t)], p.second += v;
    report.invertedAfter += v < 0;
  }
  report.worstPartAfter = 0;
  for (const auto& [label, v] : after)
    if (v.first > 0)
      report.worstPartAfter =
          std::max(report.worstPartAfter, std::fabs(100 * (v.second / v.first - 1)));
  if (withContacts) {
    const std::vector<SelfContact> left = options.contacts->find(deformed, &movable);
    report.contactsAfter = int(left.size());
    report.deepestContactAfterMm = deepest(left);
  }
  for (Eigen::Index v = 0; v < nv; ++v)
    report.maxCorrectionMm =
        std::max(report.maxCorrectionMm, (deformed.row(v) - start.row(v)).norm());
  return report;
}

}  // namespace repose
