// The volume restoration (mesh/VolumeRestoration.h) on a box of tets whose middle is crushed, as a
// joint's crease is: every part it reaches gets its rest volume back, tets as nearly as the free
// vertices allow and never turned more inside out; vertices it may not move (a bone's) stay
// where they were; and a volume change it cannot reach (tissue dragged elsewhere) is left for
// the report to show.
#include "repose/mesh/VolumeRestoration.h"

#include "../TestTetMeshes.h"

#include <gtest/gtest.h>

using namespace repose;

namespace {

// 80 x 40 x 40 mm, two parts (x < 40: 3, else 4), 5 mm cubes.
TransferMesh twoParts() {
  TransferMesh m = test::tetBox({0, 0, 0}, {80, 40, 40}, {16, 8, 8}, 3);
  for (Eigen::Index t = 0; t < m.tets.rows(); ++t) {
    double x = 0;
    for (int k = 0; k < 4; ++k) x += m.vertices(m.tets(t, k), 0) / 4;
    m.labels[t] = x < 40 ? 3 : 4;
  }
  return m;
}

double partVolume(const TransferMesh& m, const Eigen::MatrixX3d& x, int part) {
  double v = 0;
  for (Eigen::Index t = 0; t < m.tets.rows(); ++t)
    if (m.labels[t] == part) v += tetVolume(x, m.tets.row(t));
  return v;
}

// Squeezes the vertices within `radius` of `centre` towards the plane y = 20 by `factor` (at the
// centre; less further out), the box's faces y = 0 and 40 with them where the radius reaches.
Eigen::MatrixX3d crushed(const TransferMesh& m, const Eigen::Vector3d& centre, double radius,
                         double factor) {
  Eigen::MatrixX3d x = m.vertices;
  for (Eigen::Index v = 0; v < x.rows(); ++v) {
    const double d = (Eigen::Vector3d(x.row(v)) - centre).norm();
    if (d < radius) x(v, 1) = 20 + (x(v, 1) - 20) * (1 - (1 - factor) * (1 - d / radius));
  }
  return x;
}

}  // namespace

TEST(VolumeRestoration, EveryPartItReachesGetsItsRestVolumeBackAndFixedVerticesStay) {
  const TransferMesh m = twoParts();
  const Eigen::Vector3d centre(40, 20, 20);
  Eigen::MatrixX3d x = crushed(m, centre, 30, 0.6);
  const double rest3 = partVolume(m, m.vertices, 3), rest4 = partVolume(m, m.vertices, 4);
  ASSERT_LT(partVolume(m, x, 3), 0.97 * rest3);  // the crush costs each part several percent
  ASSERT_LT(partVolume(m, x, 4), 0.97 * rest4);
  // Free: the soft tissue around the crush; the vertices of the central column (a "bone" along
  // z through the crush) and everything far away stay.
  std::vector<char> movable(std::size_t(m.vertices.rows()), 0);
  std::vector<char> bone(movable.size(), 0);
  for (Eigen::Index v = 0; v < m.vertices.rows(); ++v) {
    const Eigen::Vector3d p = m.vertices.row(v);
    bone[std::size_t(v)] = std::abs(p.x() - 40) < 1e-9 && std::abs(p.y() - 20) < 1e-9;
    movable[std::size_t(v)] = (p - centre).norm() < 36 && !bone[std::size_t(v)];
  }
  const Eigen::MatrixX3d before = x;
  const VolumeRestorationReport r = restoreVolumes(m, movable, x);
  EXPECT_GT(r.freeVertices, 50);
  EXPECT_EQ(r.parts, 2);
  EXPECT_GT(r.worstPartBefore, 3);
  EXPECT_LT(r.worstPartAfter, 1e-3);
  EXPECT_NEAR(partVolume(m, x, 3), rest3, 1e-5 * rest3);
  EXPECT_NEAR(partVolume(m, x, 4), rest4, 1e-5 * rest4);
  EXPECT_LE(r.invertedAfter, r.invertedBefore);
  for (Eigen::Index v = 0; v < x.rows(); ++v) {
    if (!movable[std::size_t(v)]) {
      EXPECT_EQ((x.row(v) - before.row(v)).norm(), 0) << v;
    }
  }
  // Each tet nearer its own volume: the summed squared relative misfit falls several times.
  double misfitBefore = 0, misfitAfter = 0;
  for (Eigen::Index t = 0; t < m.tets.rows(); ++t) {
    const double v0 = tetVolume(m.vertices, m.tets.row(t));
    misfitBefore += std::pow(tetVolume(before, m.tets.row(t)) / v0 - 1, 2);
    misfitAfter += std::pow(tetVolume(x, m.tets.row(t)) / v0 - 1, 2);
  }
  EXPECT_LT(misfitAfter, 0.2 * misfitBefore);
  EXPECT_LE(r.maxCorrectionMm, 12);  // smooth: about what the crush took, not more
}

TEST(VolumeRestoration, AChangeItCannotReachIsLeftAsItIs) {
  const TransferMesh m = twoParts();
  // Part 4 crushed near x = 70 (dragged tissue, say), the correction free only near x = 10.
  Eigen::MatrixX3d x = crushed(m, {70, 20, 20}, 25, 0.5);
  const double posed4 = partVolume(m, x, 4);
  ASSERT_LT(posed4, 0.99 * partVolume(m, m.vertices, 4));
  std::vector<char> movable(std::size_t(m.vertices.rows()), 0);
  for (Eigen::Index v = 0; v < m.vertices.rows(); ++v)
    movable[std::size_t(v)] = m.vertices(v, 0) < 20;
  const VolumeRestorationReport r = restoreVolumes(m, movable, x);
  EXPECT_EQ(r.freeVertices, 0);  // nothing off its volume where it may move
  EXPECT_EQ(partVolume(m, x, 4), posed4);
  // Nothing off its volume at all: nothing to do.
  Eigen::MatrixX3d rest = m.vertices;
  std::vector<char> all(movable.size(), 1);
  EXPECT_EQ(restoreVolumes(m, all, rest).freeVertices, 0);
  EXPECT_EQ((rest - m.vertices).norm(), 0);
}

TEST(VolumeRestoration, TetsHeldBesideTheReachedOnesAreMadeUpForByTheirPart) {
  // The crush's middle column cannot move (every vertex of its tets fixed): its loss is made up
  // for by the free tissue around it when those tets are held in the part's volume.
  const TransferMesh m = twoParts();
  const Eigen::Vector3d centre(20, 20, 20);
  Eigen::MatrixX3d x = crushed(m, centre, 25, 0.6);
  std::vector<char> movable(std::size_t(m.vertices.rows()), 0), held(std::size_t(m.tets.rows()), 0);
  for (Eigen::Index v = 0; v < m.vertices.rows(); ++v) {
    const Eigen::Vector3d p = m.vertices.row(v);
    movable[std::size_t(v)] = (p - centre).norm() < 32 && (p - centre).norm() > 10;
  }
  for (Eigen::Index t = 0; t < m.tets.rows(); ++t) held[std::size_t(t)] = 1;
  Eigen::MatrixX3d without = x;
  restoreVolumes(m, movable, without);
  restoreVolumes(m, movable, x, {}, held);
  const double rest3 = partVolume(m, m.vertices, 3);
  EXPECT_NEAR(partVolume(m, x, 3), rest3, 1e-5 * rest3);
  EXPECT_LT(partVolume(m, without, 3), rest3 * (1 - 1e-4));  // the column's loss stays
}

TEST(VolumeRestoration, ACreaseFoldedInsideOutIsUntangledWithItsPartsVolumesKept) {
  // Crushed past flat (factor -0.4: the middle's vertices pushed through the plane y = 20), as
  // the inner side of a bend folds: the restoration's linearised rounds leave tets inside out;
  // the untangling turns every one back and the parts keep their rest volumes within 0.1 %.
  const TransferMesh m = twoParts();
  const Eigen::Vector3d centre(40, 20, 20);
  const Eigen::MatrixX3d folded = crushed(m, centre, 18, -0.4);
  std::vector<char> movable(std::size_t(m.vertices.rows()), 0);
  for (Eigen::Index v = 0; v < m.vertices.rows(); ++v) {
    const Eigen::Vector3d p = m.vertices.row(v);
    movable[std::size_t(v)] =
        (p - centre).norm() < 30 && p.y() > 1 && p.y() < 39 && p.z() > 1 && p.z() < 39;
  }
  VolumeRestorationOptions without;
  without.untangleRounds = 0;
  Eigen::MatrixX3d plain = folded, untangled = folded;
  const VolumeRestorationReport a = restoreVolumes(m, movable, plain, without);
  const VolumeRestorationReport b = restoreVolumes(m, movable, untangled);
  ASSERT_GT(a.invertedBefore, 0);
  EXPECT_GT(a.invertedAfter, 0);  // what the linearised rounds alone leave
  EXPECT_EQ(b.invertedAfter, 0);
  EXPECT_EQ(b.untangled, a.invertedAfter);
  for (const int part : {3, 4}) {
    const double rest = partVolume(m, m.vertices, part);
    EXPECT_NEAR(partVolume(m, untangled, part), rest, 1e-3 * rest) << part;
  }
  EXPECT_LT(b.worstPartAfter, 0.1);
}

// A fold pinned by vertices that may not move (a bone's, here a plate crushed with the tissue
// and held where the crush put it): the untangling cannot turn every tet back. Its second sweeps
// under a weaker hold (VolumeRestorationOptions::relaxedKappa) are tried and never leave more
// tets inside out than the first did; unpinned, the first sweeps suffice and no second is tried.
TEST(VolumeRestoration, ASecondUntanglingUnderAWeakerHoldNeverLeavesMoreTetsInsideOut) {
  const TransferMesh m = twoParts();
  const Eigen::Vector3d centre(40, 20, 20);
  const Eigen::MatrixX3d folded = crushed(m, centre, 18, -0.8);
  std::vector<char> free(std::size_t(m.vertices.rows()), 0), pinned;
  for (Eigen::Index v = 0; v < m.vertices.rows(); ++v) {
    const Eigen::Vector3d p = m.vertices.row(v);
    free[std::size_t(v)] =
        (p - centre).norm() < 30 && p.y() > 1 && p.y() < 39 && p.z() > 1 && p.z() < 39;
  }
  pinned = free;
  for (Eigen::Index v = 0; v < m.vertices.rows(); ++v) {
    const Eigen::Vector3d p = m.vertices.row(v);
    if (std::fabs(p.z() - 20) < 1 && std::fabs(p.x() - 40) < 12) pinned[std::size_t(v)] = 0;
  }
  VolumeRestorationOptions strictOnly;
  strictOnly.relaxedKappa = 0;
  Eigen::MatrixX3d a = folded, b = folded, c = folded;
  const VolumeRestorationReport strict = restoreVolumes(m, pinned, a, strictOnly);
  const VolumeRestorationReport both = restoreVolumes(m, pinned, b);
  ASSERT_GT(strict.invertedAfter, 0);
  EXPECT_FALSE(strict.relaxedUntangle);
  EXPECT_TRUE(both.relaxedUntangle);
  EXPECT_LE(both.invertedAfter, strict.invertedAfter);
  EXPECT_LT(both.worstPartAfter, 0.1);
  const VolumeRestorationReport unpinned = restoreVolumes(m, free, c);
  EXPECT_EQ(unpinned.invertedAfter, 0);
  EXPECT_FALSE(unpinned.relaxedUntangle);
}

TEST(VolumeRestoration, ALayerPressedIntoAnotherIsPushedOutWithItsVolumeKept) {
  // A fold (mesh/SelfContact.h): a soft box pressed 3 mm into a fixed one (a bone's tissue,
  // say). Without the contacts the restoration sees every tet at its volume and does nothing; with
  // them the pressed face is pushed out of the other box and the soft box keeps its volume.
  TransferMesh m = test::concatenate(test::tetBox({0, 0, 0}, {40, 40, 40}, {8, 8, 8}, 3),
                                     test::tetBox({50, 0, 0}, {90, 40, 40}, {8, 8, 8}, 4));
  const Eigen::Index half = m.vertices.rows() / 2;
  Eigen::MatrixX3d x = m.vertices;
  x.bottomRows(m.vertices.rows() - half).col(0).array() -= 13;
  std::vector<char> movable(std::size_t(m.vertices.rows()), 0);
  for (Eigen::Index v = half; v < m.vertices.rows(); ++v)
    movable[std::size_t(v)] = m.vertices(v, 0) < 70;  // the far half stays: a bone's end
  const Eigen::MatrixX3d pressed = x;
  Eigen::MatrixX3d without = x;
  EXPECT_EQ(restoreVolumes(m, movable, without).freeVertices, 0);
  const SelfContactFinder finder(m);
  VolumeRestorationOptions options;
  options.contacts = &finder;
  const VolumeRestorationReport r = restoreVolumes(m, movable, x, options);
  EXPECT_EQ(r.contactsBefore, 7 * 7);  // the soft box's movable face vertices inside the other
  EXPECT_NEAR(r.deepestContactBeforeMm, 3, 1e-9);
  EXPECT_EQ(r.contactsAfter, 0);
  EXPECT_TRUE(finder.find(x, &movable).empty());
  EXPECT_EQ(r.invertedAfter, 0);
  const double rest4 = partVolume(m, m.vertices, 4);
  EXPECT_NEAR(partVolume(m, x, 4), rest4, 1e-4 * rest4);
  for (Eigen::Index v = 0; v < half; ++v) EXPECT_EQ((x.row(v) - pressed.row(v)).norm(), 0);
  // Every vertex of the pressed face that was inside now at or beyond the other's face x = 40.
  for (Eigen::Index v = half; v < m.vertices.rows(); ++v) {
    const Eigen::Vector3d p = m.vertices.row(v);
    if (p.x() == 50 && p.y() > 0 && p.y() < 40 && p.z() > 0 && p.z() < 40) {
      EXPECT_GE(x(v, 0), 40 - 1e-6) << v;
    }
  }
}
