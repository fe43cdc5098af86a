// Self-contact (mesh/SelfContact.h): surface vertices inside another layer of the same mesh's
// tissue, and the way out of it; a tet turned inside out next to a vertex is not a contact.
#include "repose/mesh/SelfContact.h"

#include "../TestTetMeshes.h"

#include <gtest/gtest.h>

#include <cstdio>
#include <set>

using namespace repose;

namespace {

// Two 40 mm boxes of 5 mm cubes side by side along x, 10 mm apart at rest: a finger and a thigh.
TransferMesh twoBoxes() {
  return test::concatenate(test::tetBox({0, 0, 0}, {40, 40, 40}, {8, 8, 8}),
                           test::tetBox({50, 0, 0}, {90, 40, 40}, {8, 8, 8}));
}

}  // namespace

TEST(SelfContact, ARestMeshHasNone) {
  const TransferMesh m = twoBoxes();
  const SelfContactFinder finder(m);
  EXPECT_FALSE(finder.surfaceVertices().empty());
  EXPECT_TRUE(finder.find(m.vertices).empty());
}

TEST(SelfContact, TwoLayersPressedIntoEachOtherAreFoundWithTheWayOut) {
  const TransferMesh m = twoBoxes();
  const SelfContactFinder finder(m);
  // The second box 13 mm towards the first: 3 mm into it (its face x = 50 now at x = 37).
  Eigen::MatrixX3d x = m.vertices;
  const Eigen::Index half = m.vertices.rows() / 2;
  x.bottomRows(m.vertices.rows() - half).col(0).array() -= 13;
  const std::vector<SelfContact> contacts = finder.find(x);
  ASSERT_FALSE(contacts.empty());
  std::set<int> vertices;
  for (const SelfContact& c : contacts) {
    vertices.insert(c.vertex);
    EXPECT_NEAR(c.normal.norm(), 1, 1e-12);
    // Strictly inside the other box, at most 3 mm deep, and the way out is the nearest face.
    const Eigen::Vector3d p = x.row(c.vertex);
    EXPECT_GT(c.depthMm, 0);
    EXPECT_LE(c.depthMm, 3 + 1e-9);
    EXPECT_NEAR((c.point - p).norm(), c.depthMm, 1e-9);
    if (std::abs(c.depthMm - 3) > 1e-9)
      std::printf("DBG %d p=%g %g %g q=%g %g %g d=%g\n", c.vertex, p.x(), p.y(), p.z(), c.point.x(),
                  c.point.y(), c.point.z(), c.depthMm);
    if (c.vertex < half) {  // the first box's face x = 40 inside the second, out along -x
      EXPECT_NEAR(p.x(), 40, 1e-9);
      EXPECT_NEAR(c.depthMm, 3, 1e-9);
      EXPECT_NEAR(c.normal.x(), -1, 1e-9);
    } else {  // the second box's face at x = 37 inside the first, out along +x
      EXPECT_NEAR(p.x(), 37, 1e-9);
      EXPECT_NEAR(c.depthMm, 3, 1e-9);
      EXPECT_NEAR(c.normal.x(), 1, 1e-9);
    }
  }
  // Each face's vertices strictly inside the other box: 7 x 7 interior grid points each.
  EXPECT_EQ(vertices.size(), 2u * 7 * 7);
  EXPECT_EQ(contacts.size(), vertices.size());
  // Only the candidates asked about.
  std::vector<char> firstOnly(std::size_t(m.vertices.rows()), 0);
  for (Eigen::Index v = 0; v < half; ++v) firstOnly[std::size_t(v)] = 1;
  for (const SelfContact& c : finder.find(x, &firstOnly)) EXPECT_LT(c.vertex, half);
}

TEST(SelfContact, AVertexPushedIntoItsOwnNeighboursTetsIsNotAContact) {
  // A surface vertex pushed 6 mm into its own box (through its tets, turning some inside out and
  // lying inside others of its neighbourhood): the untangling's business, not a fold.
  const TransferMesh m = test::tetBox({0, 0, 0}, {40, 40, 40}, {8, 8, 8});
  const SelfContactFinder finder(m);
  Eigen::MatrixX3d x = m.vertices;
  Eigen::Index top = -1;
  for (Eigen::Index v = 0; v < m.vertices.rows(); ++v)
    if ((m.vertices.row(v) - Eigen::RowVector3d(20, 20, 40)).norm() < 1e-9) top = v;
  ASSERT_GE(top, 0);
  x(top, 2) -= 6;
  EXPECT_TRUE(finder.find(x).empty());
}
