// The phantom's analytic elbow flexion (phantom/PhantomPoses.h), the posed-cage fixture of the
// rasterizer's and the refinement's tests: its two groups split the cage and the body parts, the
// turned group holds only cage vertices below the elbow and turns rigidly about the elbow's x
// axis, forward, and the rest of the cage stays where it is.
#include "repose/cage/CageBuilder.h"
#include "repose/phantom/Phantom.h"
#include "repose/phantom/PhantomPoses.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <numeric>

using namespace repose;

namespace {

struct Body {
  Phantom phantom;
  TriangleMesh cage;
  Body()
      : phantom([] {
          PhantomOptions o;
          o.voxelMm = 8;
          return o;
        }()) {
    cage = buildCage(phantom.makeVolumes().second, {}).mesh;
  }
};

const Body& body() {
  static const Body b;
  return b;
}

}  // namespace

TEST(PhantomPoses, TwoGroupsSplitTheCageAndTheParts) {
  const Body& b = body();
  const std::vector<RigidHandle> h = phantomElbowFlexionHandles(b.phantom, b.cage, 90);
  ASSERT_EQ(h.size(), 2u);
  EXPECT_EQ(h[0].parts, (std::vector<int>{kPartForearmLeft, kPartHandLeft}));
  for (int part = kPartHead; part <= kPartFootRight; ++part) {
    const bool turned = part == kPartForearmLeft || part == kPartHandLeft;
    EXPECT_EQ(std::count(h[1].parts.begin(), h[1].parts.end(), part), turned ? 0 : 1) << part;
  }
  // Every cage vertex in exactly one group; the turned ones below the elbow.
  std::vector<int> all = h[0].cageVertices;
  all.insert(all.end(), h[1].cageVertices.begin(), h[1].cageVertices.end());
  std::sort(all.begin(), all.end());
  std::vector<int> expected(std::size_t(b.cage.vertices.rows()));
  std::iota(expected.begin(), expected.end(), 0);
  EXPECT_EQ(all, expected);
  ASSERT_FALSE(h[0].cageVertices.empty());
  const Eigen::Vector3d elbow = b.phantom.joint("elbow_left").ras;
  for (const int v : h[0].cageVertices) EXPECT_LT(b.cage.vertices(v, 2), elbow.z()) << v;
  EXPECT_TRUE(h[1].motion.isApprox(Eigen::Isometry3d::Identity()));
}

TEST(PhantomPoses, TheForearmTurnsForwardAboutTheElbowAndTheRestStays) {
  const Body& b = body();
  const Eigen::MatrixX3d& rest = b.cage.vertices;
  EXPECT_TRUE(phantomElbowFlexion(b.phantom, b.cage, 0).isApprox(rest));
  const std::vector<RigidHandle> h = phantomElbowFlexionHandles(b.phantom, b.cage, 90);
  const Eigen::MatrixX3d posed = phantomElbowFlexion(b.phantom, b.cage, 90);
  ASSERT_EQ(posed.rows(), rest.rows());
  for (const int v : h[1].cageVertices) EXPECT_EQ(posed.row(v), rest.row(v)) << v;
  const Eigen::Vector3d elbow = b.phantom.joint("elbow_left").ras;
  double forward = 0, up = 0;
  for (const int v : h[0].cageVertices) {
    const Eigen::Vector3d p = rest.row(v).transpose(), q = posed.row(v).transpose();
    EXPECT_NEAR(q.x(), p.x(), 1e-9) << v;  // about the x axis
    // Rigid about the elbow's axis: the distance to it is kept, a quarter turn made.
    const Eigen::Vector2d a(p.y() - elbow.y(), p.z() - elbow.z()),
        c(q.y() - elbow.y(), q.z() - elbow.z());
    EXPECT_NEAR(c.norm(), a.norm(), 1e-9) << v;
    EXPECT_NEAR(a.dot(c), 0, 1e-6 * std::max(1.0, a.squaredNorm())) << v;
    forward += q.y() - p.y(), up += q.z() - p.z();
  }
  // The hanging forearm comes forward (+y, anterior) and up to the elbow's height.
  EXPECT_GT(forward / double(h[0].cageVertices.size()), 50);
  EXPECT_GT(up / double(h[0].cageVertices.size()), 50);
}
