// Motion-adaptive refinement on a 90-degree elbow flexion of the phantom: the mesh refines where
// the arm bends, the maximum error falls, and the mesh returned matches the field returned.
#include "repose/cage/CageBuilder.h"
#include "repose/mesh/Refinement.h"
#include "repose/phantom/Phantom.h"

#include <gtest/gtest.h>

#include <Eigen/Geometry>

using namespace repose;

namespace {

// The left forearm and hand turned 90 degrees forward about the elbow (cage vertices only).
Eigen::MatrixX3d elbowFlexion(const Phantom& phantom, const TriangleMesh& cage) {
  const Eigen::Vector3d elbow = phantom.joint("elbow_left").ras,
                        shoulder = phantom.joint("shoulder_left").ras;
  const Eigen::Matrix3d R =
      Eigen::AngleAxisd(-M_PI / 2, Eigen::Vector3d::UnitX()).toRotationMatrix();
  Eigen::MatrixX3d out = cage.vertices;
  for (Eigen::Index v = 0; v < out.rows(); ++v) {
    const Eigen::Vector3d p = cage.vertices.row(v);
    if (p.z() < elbow.z() && p.x() < shoulder.x() + 25)
      out.row(v) = (R * (p - elbow) + elbow).transpose();
  }
  return out;
}

}  // namespace

TEST(Refinement, RefinesWhereTheElbowBendsAndLowersTheMaximumError) {
  PhantomOptions po;
  po.voxelMm = 4;
  const Phantom phantom(po);
  const Volume parts = phantom.makeVolumes().second;
  const TriangleMesh cage = buildCage(parts, {}).mesh;
  RefinementOptions o;
  o.initialSizeMm = 45;
  o.maxIterations = 3;
  o.uniformity = 0;  // run every iteration
  const RefinementResult r = refineTransferMesh(parts, cage, elbowFlexion(phantom, cage), o);
  ASSERT_EQ(r.steps.size(), 3u);
  EXPECT_GT(r.steps.back().vertices, r.steps.front().vertices);
  EXPECT_LT(r.steps.back().maxTetError, r.steps.front().maxTetError);
  // The field shrank near the elbow, not at the feet.
  const Eigen::Vector3d elbow = phantom.joint("elbow_left").ras,
                        ankle = phantom.joint("ankle_right").ras;
  EXPECT_LT(r.sizing.at(elbow), r.sizing.at(ankle));
  EXPECT_EQ(r.mesh.vertices.rows(), r.steps.back().vertices);
}
