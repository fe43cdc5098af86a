// Handle influence (RigidHandles.h): tissue of a rigidly moved group follows it exactly, by body
// parts or by the cage, with a smooth transition and checked inputs.
#include "TestMeshes.h"
#include "TestTetMeshes.h"

#include "repose/mesh/RigidHandles.h"
#include "repose/mesh/RigiditySolver.h"
#include "repose/util/Error.h"

#include <gtest/gtest.h>

#include <cmath>

using namespace repose;
using namespace repose::test;

namespace {

// A 100 x 20 x 20 mm bar of tets, label 2 for x > 50 and 1 below, inside a box cage.
struct Bar {
  TransferMesh mesh;
  TriangleMesh cage;
  Bar() {
    mesh = tetBox({0, 0, 0}, {100, 20, 20}, {20, 4, 4});
    for (Eigen::Index t = 0; t < mesh.tets.rows(); ++t) {
      double x = 0;
      for (int k = 0; k < 4; ++k) x += mesh.vertices(mesh.tets(t, k), 0) / 4;
      mesh.labels[t] = x > 50 ? 2 : 1;
    }
    cage = boxMesh({-5, -5, -5}, {105, 25, 25}, 6);
  }
  std::vector<int> cageVerticesBeyond(double x) const {
    std::vector<int> out;
    for (Eigen::Index v = 0; v < cage.vertices.rows(); ++v)
      if (cage.vertices(v, 0) > x) out.push_back(int(v));
    return out;
  }
};

}  // namespace

TEST(RigidHandles, BodyPartsOwnExactlyTheirTissueWithTheTransitionOnTheBorder) {
  const Bar bar;
  RigidHandle h;
  h.parts = {2};
  h.cageVertices = bar.cageVerticesBeyond(50);
  const HandleInfluence inf = computeHandleInfluence(bar.mesh, bar.cage, {h});
  double borderSum = 0;
  int border = 0;
  for (Eigen::Index v = 0; v < bar.mesh.vertices.rows(); ++v) {
    const double x = bar.mesh.vertices(v, 0), m = inf.membership(v, 0);
    if (x > 50.1) {
      EXPECT_EQ(m, 1.0);
      EXPECT_EQ(inf.weight[v], 1.0);
      EXPECT_EQ(inf.dominantGroup(v), 0);
    } else if (x < 49.9) {
      EXPECT_EQ(m, 0.0);
      EXPECT_EQ(inf.weight[v], 0.0);
      EXPECT_EQ(inf.dominantGroup(v), -1);
    } else {  // on the border: the share of the surrounding volume in part 2
      EXPECT_GE(m, 0.0);
      EXPECT_LE(m, 1.0);
      borderSum += m, ++border;
    }
  }
  ASSERT_EQ(border, 5 * 5);
  EXPECT_NEAR(borderSum / border, 0.5, 0.2);
}

TEST(RigidHandles, CageGroupsReachThroughTheBodyWithAWeightBetweenZeroAndOne) {
  const Bar bar;
  RigidHandle h;
  h.cageVertices = bar.cageVerticesBeyond(60);
  const HandleInfluence inf = computeHandleInfluence(bar.mesh, bar.cage, {h});
  int rigid = 0, none = 0;
  for (Eigen::Index v = 0; v < bar.mesh.vertices.rows(); ++v) {
    const double x = bar.mesh.vertices(v, 0), m = inf.membership(v, 0), w = inf.weight[v];
    EXPECT_GE(m, 0.0);
    EXPECT_LE(m, 1.0);
    EXPECT_EQ(w, handleBlendWeight(m));
    if (x >= 90) {
      EXPECT_EQ(w, 1.0) << x;
    }
    if (x <= 30) {
      EXPECT_EQ(w, 0.0) << x;
    }
    rigid += m == 1.0, none += w == 0.0;
    if (x >= 95) {
      EXPECT_GT(m, 0.9) << x;
    }
  }
  EXPECT_EQ(rigid, inf.rigidVertices());
  EXPECT_GT(none, 0);
}

// Across a joint the blend of a fixed group and a turned one is a partial turn about the joint.
TEST(RigidHandles, BlendedMotionsTurnAboutTheSameJoint) {
  RigidHandle fixed, turned;
  const Eigen::Vector3d joint(10, -20, 30);
  turned.motion = Eigen::Translation3d(joint) *
                  Eigen::AngleAxisd(M_PI / 2, Eigen::Vector3d(0, 1, 1).normalized()) *
                  Eigen::Translation3d(-joint);
  const std::vector<RigidHandle> handles{fixed, turned};
  const Eigen::Vector3d axis = Eigen::Vector3d(0, 1, 1).normalized();
  double previous = -1;
  for (const double t : {0.0, 0.25, 0.5, 0.75, 1.0}) {
    const Eigen::Isometry3d m = blendMotions(Eigen::Vector2d(1 - t, t), handles);
    // A rotation about the same axis through the joint (normalized linear blending keeps the
    // screw; the angle is t * 90 degrees exactly at 0, 1/2 and 1 and grows with t).
    EXPECT_LT((m * joint - joint).norm(), 1e-12) << t;
    const Eigen::AngleAxisd turn(m.linear());
    const double angle = turn.angle() * (turn.axis().dot(axis) < 0 ? -1 : 1);
    if (angle != 0) {
      EXPECT_LT((turn.axis().cwiseAbs() - axis.cwiseAbs()).norm(), 1e-9) << t;
    }
    if (t == 0 || t == 0.5 || t == 1) {
      EXPECT_NEAR(angle, t * M_PI / 2, 1e-12) << t;
    }
    EXPECT_GT(angle, previous);
    previous = angle;
  }
  EXPECT_TRUE(blendMotions(Eigen::Vector2d(0, 0), handles).isApprox(Eigen::Isometry3d::Identity()));
  EXPECT_TRUE(blendMotions(Eigen::Vector2d(0, 3), handles).isApprox(turned.motion, 1e-12));
}

TEST(RigidHandles, DominatedTissueMovesExactlyWhereGreenCoordinatesLag) {
  const Bar bar;
  RigidHandle h;
  h.parts = {2};
  h.cageVertices = bar.cageVerticesBeyond(50);
  h.motion = Eigen::Translation3d(0, 0, 30) * Eigen::AngleAxisd(0.3, Eigen::Vector3d::UnitX());
  const std::vector<RigidHandle> handles{h};
  const Eigen::MatrixX3d cage = moveHandles(bar.cage.vertices, handles);
  for (Eigen::Index v = 0; v < cage.rows(); ++v) {
    const bool moved = bar.cage.vertices(v, 0) > 50;
    const Eigen::Vector3d rest = bar.cage.vertices.row(v), want = moved ? h.motion * rest : rest;
    EXPECT_LT((Eigen::Vector3d(cage.row(v)) - want).norm(), 1e-12);
  }
  const CageDeformation deformation(bar.mesh, bar.cage);
  const HandleInfluence inf = computeHandleInfluence(bar.mesh, bar.cage, handles);
  const Eigen::MatrixX3d green = deformation.deform(cage),
                         ours = deformation.deform(cage, inf, handles);
  double greenWorst = 0;
  for (Eigen::Index v = 0; v < bar.mesh.vertices.rows(); ++v) {
    if (inf.membership(v, 0) < 1) continue;
    const Eigen::Vector3d want = h.motion * Eigen::Vector3d(bar.mesh.vertices.row(v));
    EXPECT_LT((Eigen::Vector3d(ours.row(v)) - want).norm(), 1e-6);
    greenWorst = std::max(greenWorst, (Eigen::Vector3d(green.row(v)) - want).norm());
  }
  EXPECT_GT(greenWorst, 1.0);  // what the influence corrects
  for (Eigen::Index v = 0; v < ours.rows(); ++v) EXPECT_TRUE(ours.row(v).allFinite());
}

TEST(RigidHandles, RefusesBadHandleLists) {
  const Bar bar;
  RigidHandle a, b;
  a.cageVertices = {0, 1};
  b.cageVertices = {1, 2};
  EXPECT_THROW(computeHandleInfluence(bar.mesh, bar.cage, {a, b}), Error);  // vertex 1 twice
  b.cageVertices = {int(bar.cage.vertices.rows())};
  EXPECT_THROW(computeHandleInfluence(bar.mesh, bar.cage, {a, b}), Error);  // out of range
  EXPECT_THROW(moveHandles(bar.cage.vertices, {a, b}), Error);
  const CageDeformation deformation(bar.mesh, bar.cage);
  HandleInfluence wrongSize;
  EXPECT_THROW(deformation.deform(bar.cage.vertices, wrongSize, {a}), Error);
  const HandleInfluence forA = computeHandleInfluence(bar.mesh, bar.cage, {a});
  EXPECT_THROW(deformation.deform(bar.cage.vertices, forA, {a, a}), Error);  // other list
  EXPECT_NO_THROW(computeHandleInfluence(bar.mesh, bar.cage, {}));
}

// Widening the joint: each ring spreads the transition one ring of vertices further on both
// sides, keeps memberships in [0, 1], and leaves the tissue beyond it carried exactly.
TEST(RigidHandles, JointRingsWidenTheTransitionOnly) {
  const Bar bar;  // vertices every 5 mm along x, border at x = 50
  RigidHandle h;
  h.parts = {2};
  h.cageVertices = bar.cageVerticesBeyond(50);
  for (const int rings : {0, 1, 2}) {
    const HandleInfluence inf = computeHandleInfluence(bar.mesh, bar.cage, {h}, 0, rings);
    double lo = 1e9, hi = -1e9;  // x extent of the fractional memberships
    for (Eigen::Index v = 0; v < bar.mesh.vertices.rows(); ++v) {
      const double m = inf.membership(v, 0), x = bar.mesh.vertices(v, 0);
      EXPECT_GE(m, 0.0);
      EXPECT_LE(m, 1.0);
      if (m > 0 && m < 1) lo = std::min(lo, x), hi = std::max(hi, x);
      if (x >= 50 + 5 * (rings + 1)) {
        EXPECT_EQ(m, 1.0) << rings << " " << x;
      }
      if (x <= 50 - 5 * (rings + 1)) {
        EXPECT_EQ(m, 0.0) << rings << " " << x;
      }
    }
    EXPECT_NEAR(lo, 50 - 5 * rings, 1e-9) << rings;
    EXPECT_NEAR(hi, 50 + 5 * rings, 1e-9) << rings;
  }
  EXPECT_THROW(computeHandleInfluence(bar.mesh, bar.cage, {h}, 0, -1), Error);
}

// Whole pieces (TransferMesh::rigid): a bone straddling the parts' border goes with the group
// holding most of it, every vertex of it alone; one inside part 1 goes with part 1's group; where
// two pieces of different groups share vertices, those split evenly.
TEST(RigidHandles, WholePiecesMoveWithTheGroupCarryingMostOfThem) {
  Bar bar;
  auto centreX = [&](Eigen::Index t) {
    double x = 0;
    for (int k = 0; k < 4; ++k) x += bar.mesh.vertices(bar.mesh.tets(t, k), 0) / 4;
    return x;
  };
  bar.mesh.rigid.assign(std::size_t(bar.mesh.tets.rows()), 0);
  for (Eigen::Index t = 0; t < bar.mesh.tets.rows(); ++t) {
    const double x = centreX(t);
    if (x > 40 && x < 75) bar.mesh.rigid[t] = 14;  // mostly in part 2
    if (x > 10 && x < 40) bar.mesh.rigid[t] = 10;  // in part 1, touching the first at x = 40
  }
  RigidHandle limb, body;
  limb.parts = {2}, body.parts = {1};
  const HandleInfluence inf = computeHandleInfluence(bar.mesh, bar.cage, {limb, body});
  int shared = 0;
  for (Eigen::Index t = 0; t < bar.mesh.tets.rows(); ++t) {
    if (!bar.mesh.rigid[t]) continue;
    for (int k = 0; k < 4; ++k) {
      const int v = bar.mesh.tets(t, k);
      const double x = bar.mesh.vertices(v, 0);
      if (std::fabs(x - 40) < 1e-9) {
        EXPECT_DOUBLE_EQ(inf.membership(v, 0), 0.5);
        EXPECT_DOUBLE_EQ(inf.membership(v, 1), 0.5);
        ++shared;
        continue;
      }
      const int group = bar.mesh.rigid[t] == 14 ? 0 : 1;
      EXPECT_EQ(inf.membership(v, group), 1.0) << "vertex at x = " << x;
      EXPECT_EQ(inf.membership(v, 1 - group), 0.0);
      EXPECT_EQ(inf.weight[v], 1.0);
    }
  }
  EXPECT_GT(shared, 0);
  // Without pieces the bone's part-1 end (x in 40..50) would blend towards part 1.
  bar.mesh.rigid.clear();
  const HandleInfluence plain = computeHandleInfluence(bar.mesh, bar.cage, {limb, body});
  for (Eigen::Index v = 0; v < bar.mesh.vertices.rows(); ++v)
    if (bar.mesh.vertices(v, 0) > 40.1 && bar.mesh.vertices(v, 0) < 49.9) {
      EXPECT_EQ(plain.membership(v, 0), 0.0);
    }
}
