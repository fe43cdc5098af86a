// The crease untangling (mesh/TetUntangle.h) on a box of tets folded inside out in a band, as the
// inner side of a bent elbow folds: every tet comes back right side out, the volumes held (the
// box's and a "vessel" crossing the band) stay within 0.01 %, vertices not given stay put, and
// the held residuals it keeps up to date equal the ones recomputed from the positions.
#include "mesh/TetUntangle.h"

#include "../TestTetMeshes.h"

#include <gtest/gtest.h>

#include <cmath>

using namespace repose;

namespace {

// 60 x 30 x 30 mm in 5 mm cubes; the vertices of the band 20 < x < 40 (not on the box's faces)
// pushed through the plane y = 15 towards and beyond their neighbours: tets turn inside out.
struct Folded {
  TransferMesh mesh = test::tetBox({0, 0, 0}, {60, 30, 30}, {12, 6, 6}, 1);
  Eigen::MatrixX3d posed;
  std::vector<int> freeVertices, tets;
  Folded() {
    posed = mesh.vertices;
    for (Eigen::Index v = 0; v < posed.rows(); ++v) {
      const Eigen::Vector3d p = mesh.vertices.row(v);
      const bool inside =
          p.x() > 1 && p.x() < 59 && p.y() > 1 && p.y() < 29 && p.z() > 1 && p.z() < 29;
      if (inside && p.x() > 17 && p.x() < 43) freeVertices.push_back(int(v));
      if (inside && p.x() > 22 && p.x() < 38) posed(v, 1) = 15 - 1.6 * (p.y() - 15) + 2;
    }
    for (Eigen::Index t = 0; t < mesh.tets.rows(); ++t) tets.push_back(int(t));
  }
  int inverted(const Eigen::MatrixX3d& x) const {
    int n = 0;
    for (const int t : tets) n += tetVolume(x, mesh.tets.row(t)) <= 0;
    return n;
  }
};

// Two held volumes: the whole box (constraint 0) and the tets whose centroid lies within 6 mm of
// the line y = z = 15 (a vessel along x, constraint 1), counted as the restoration counts them
// (volume changes, weight 1).
UntangleConstraints boxAndVessel(const TransferMesh& m, const Eigen::MatrixX3d& x) {
  UntangleConstraints c;
  c.amount = {0, 0};
  c.residual = Eigen::VectorXd::Zero(2);
  c.offsets.push_back(0);
  for (Eigen::Index t = 0; t < m.tets.rows(); ++t) {
    Eigen::Vector3d centroid = Eigen::Vector3d::Zero();
    for (int k = 0; k < 4; ++k) centroid += m.vertices.row(m.tets(t, k)).transpose() / 4;
    const double rest = tetVolume(m.vertices, m.tets.row(t));
    const double change = tetVolume(x, m.tets.row(t)) - rest;
    c.entries.emplace_back(0, 1.0);
    c.amount[0] += rest, c.residual[0] += change;
    if (std::hypot(centroid.y() - 15, centroid.z() - 15) < 6) {
      c.entries.emplace_back(1, 1.0);
      c.amount[1] += rest, c.residual[1] += change;
    }
    c.offsets.push_back(int(c.entries.size()));
  }
  return c;
}

}  // namespace

TEST(TetUntangle, AFoldedBandComesBackRightSideOutWithItsHeldVolumesKept) {
  const Folded f;
  Eigen::MatrixX3d x = f.posed;
  ASSERT_GT(f.inverted(x), 20);
  UntangleConstraints held = boxAndVessel(f.mesh, x);
  // Start from the fold with its volumes met (as the restoration leaves them): the residuals
  // are the fold's own; the untangling must not make them worse than 0.01 % of each amount.
  const Eigen::VectorXd start = held.residual;
  const UntangleReport r = untangleTets(f.mesh, f.freeVertices, f.tets, held, x);
  EXPECT_EQ(r.invertedBefore, f.inverted(f.posed));
  EXPECT_EQ(r.invertedAfter, 0);
  EXPECT_EQ(f.inverted(x), 0);
  for (int c = 0; c < 2; ++c) {
    EXPECT_LE(std::fabs(held.residual[c]), std::fabs(start[c]) + 1e-4 * held.amount[std::size_t(c)])
        << c;
  }
  // The residuals it kept are the positions' own.
  const UntangleConstraints recomputed = boxAndVessel(f.mesh, x);
  EXPECT_NEAR(held.residual[0], recomputed.residual[0], 1e-6 * held.amount[0]);
  EXPECT_NEAR(held.residual[1], recomputed.residual[1], 1e-6 * held.amount[1]);
  // Only the vertices given moved.
  std::vector<char> given(std::size_t(x.rows()), 0);
  for (const int v : f.freeVertices) given[std::size_t(v)] = 1;
  for (Eigen::Index v = 0; v < x.rows(); ++v)
    if (!given[std::size_t(v)]) {
      EXPECT_EQ((x.row(v) - f.posed.row(v)).norm(), 0) << v;
    }
}

TEST(TetUntangle, NothingInsideOutIsLeftAsItIs) {
  const Folded f;
  Eigen::MatrixX3d x = f.mesh.vertices;
  UntangleConstraints held = boxAndVessel(f.mesh, x);
  const UntangleReport r = untangleTets(f.mesh, f.freeVertices, f.tets, held, x);
  EXPECT_EQ(r.invertedBefore, 0);
  EXPECT_EQ(r.sweeps, 0);
  EXPECT_EQ((x - f.mesh.vertices).norm(), 0);
}

TEST(TetUntangle, WithNoVertexFreeTheFoldStays) {
  const Folded f;
  Eigen::MatrixX3d x = f.posed;
  UntangleConstraints held = boxAndVessel(f.mesh, x);
  const UntangleReport r = untangleTets(f.mesh, {}, f.tets, held, x);
  EXPECT_EQ(r.invertedAfter, r.invertedBefore);
  EXPECT_EQ((x - f.posed).norm(), 0);
}

// Tets crushed towards a point (the fold the real adult female's shoulders settled on with both
// arms up, issue 64): the vertices of a 10 mm block in the box's middle pulled to within 0.05 mm
// of its centre and turned through it, so the block's tets are tiny and inside out. The shape
// energy is scale invariant and, regularised, costs a crushed tet almost nothing; with each
// tet's own volume weighed (the restoration's third untangling) every tet comes back right side
// out and the tets' volumes end nearer their rest volumes: the sum of (V / V0 - 1)^2 at most 0.6
// of the shape energy's alone (0.50 when written).
TEST(TetUntangle, TetsCrushedTowardsAPointComeBackNearerTheirVolumesWithTheirOwnVolumeWeighed) {
  const TransferMesh mesh = test::tetBox({0, 0, 0}, {60, 30, 30}, {12, 6, 6}, 1);
  const Eigen::Vector3d centre(30, 15, 15);
  Eigen::MatrixX3d crushed = mesh.vertices;
  std::vector<int> freeVertices, tets;
  for (Eigen::Index v = 0; v < crushed.rows(); ++v) {
    const Eigen::Vector3d p = mesh.vertices.row(v);
    if ((p - centre).cwiseAbs().maxCoeff() < 12) freeVertices.push_back(int(v));
    if ((p - centre).cwiseAbs().maxCoeff() < 6)
      crushed.row(v) = (centre - 0.01 * (p - centre)).transpose();
  }
  for (Eigen::Index t = 0; t < mesh.tets.rows(); ++t) tets.push_back(int(t));
  auto run = [&](double volumeWeight, Eigen::MatrixX3d& x) {
    x = crushed;
    UntangleConstraints held = boxAndVessel(mesh, x);
    UntangleOptions o;  // the restoration's weaker hold (VolumeRestorationOptions)
    o.kappa = 3e6, o.sweeps = 600, o.stallSweeps = 32, o.smallestDelta = 0.00125 / 128;
    o.volumeWeight = volumeWeight;
    return untangleTets(mesh, freeVertices, tets, held, x, o);
  };
  auto volumeMisfit = [&](const Eigen::MatrixX3d& x) {
    double sum = 0;
    for (const int t : tets) {
      const double r = tetVolume(x, mesh.tets.row(t)) / tetVolume(mesh.vertices, mesh.tets.row(t));
      sum += (r - 1) * (r - 1);
    }
    return sum;
  };
  Eigen::MatrixX3d shapeOnly, weighed;
  const UntangleReport a = run(0, shapeOnly), b = run(10, weighed);
  ASSERT_GT(b.invertedBefore, 100);
  EXPECT_EQ(b.invertedAfter, 0);
  EXPECT_EQ(a.invertedAfter, 0);
  EXPECT_LT(volumeMisfit(weighed), 0.6 * volumeMisfit(shapeOnly));
}

// A knot (resetInvertedKnots): under an affine pose (a turn and a stretch), the vertices around
// the box's centre crushed through a point, tets inside out. Set back on the affine map its
// border carries, every vertex is where the pose puts it again and no tet is inside out; vertices
// not free stay where they were; a border whose map turns space over (a mirror) leaves the knot.
TEST(TetUntangle, AKnotCrushedThroughAPointIsSetBackOnItsBordersAffineMap) {
  const TransferMesh mesh = test::tetBox({0, 0, 0}, {60, 30, 30}, {12, 6, 6}, 1);
  const Eigen::Vector3d centre(30, 15, 15);
  Eigen::Matrix3d A = Eigen::AngleAxisd(0.7, Eigen::Vector3d(1, 2, 3).normalized()).matrix();
  A.col(0) *= 1.3;
  const Eigen::Vector3d b(5, -2, 7);
  auto posedBy = [&](const Eigen::Matrix3d& M) {
    Eigen::MatrixX3d x(mesh.vertices.rows(), 3);
    for (Eigen::Index v = 0; v < x.rows(); ++v)
      x.row(v) = (M * mesh.vertices.row(v).transpose() + b).transpose();
    return x;
  };
  const Eigen::MatrixX3d posed = posedBy(A);
  std::vector<char> isFree(std::size_t(mesh.vertices.rows()), 0);
  std::vector<int> tets;
  for (Eigen::Index t = 0; t < mesh.tets.rows(); ++t) tets.push_back(int(t));
  auto crush = [&](const Eigen::MatrixX3d& from) {
    Eigen::MatrixX3d x = from;
    const Eigen::Vector3d c = A * centre + b;
    for (Eigen::Index v = 0; v < x.rows(); ++v) {
      const Eigen::Vector3d p = mesh.vertices.row(v);
      if ((p - centre).cwiseAbs().maxCoeff() < 6)
        x.row(v) = (c - 0.01 * (x.row(v).transpose() - c)).transpose();
    }
    return x;
  };
  auto inverted = [&](const Eigen::MatrixX3d& x) {
    int n = 0;
    for (const int t : tets) n += tetVolume(x, mesh.tets.row(t)) * A.determinant() < 0;
    return n;
  };
  // Free: the crushed vertices and the ring beyond them (the knot's ring), with one vertex held.
  int held = -1;
  for (Eigen::Index v = 0; v < mesh.vertices.rows(); ++v) {
    const Eigen::Vector3d p = mesh.vertices.row(v);
    if ((p - centre).cwiseAbs().maxCoeff() < 12) isFree[std::size_t(v)] = 1;
    if ((p - centre - Eigen::Vector3d(10, 0, 0)).norm() < 1e-9) held = int(v);
  }
  ASSERT_GE(held, 0);
  isFree[std::size_t(held)] = 0;
  Eigen::MatrixX3d x = crush(posed);
  x.row(held) += Eigen::RowVector3d(0.5, 0, 0);  // not on the pose: it must stay so
  const Eigen::RowVector3d heldAt = x.row(held);
  ASSERT_GT(inverted(x), 50);
  EXPECT_EQ(resetInvertedKnots(mesh, isFree, tets, x), 1);
  EXPECT_EQ(inverted(x), 0);
  EXPECT_EQ(x.row(held), heldAt);
  double off = 0;
  for (Eigen::Index v = 0; v < x.rows(); ++v)
    if (int(v) != held) off = std::max(off, (x.row(v) - posed.row(v)).norm());
  EXPECT_LT(off, 0.02);  // the held vertex's 0.5 mm shifts the least-squares map a little
  // A mirrored pose: the knot is left as it is.
  Eigen::Matrix3d mirror = A;
  mirror.col(2) *= -1;
  const Eigen::MatrixX3d mirrored = crush(posedBy(mirror));
  Eigen::MatrixX3d y = mirrored;
  EXPECT_EQ(resetInvertedKnots(mesh, isFree, tets, y), 0);
  EXPECT_EQ(y, mirrored);
}
