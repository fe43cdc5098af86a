#include "repose/phantom/PhantomPoses.h"

#include <Eigen/Geometry>
#include <cmath>

namespace repose {

std::vector<RigidHandle> phantomElbowFlexionHandles(const Phantom& phantom,
                                                    const TriangleMesh& cage, double degrees) {
  const Eigen::Vector3d elbow = phantom.joint("elbow_left").ras,
                        shoulder = phantom.joint("shoulder_left").ras;
  RigidHandle handle, rest;
  handle.parts = {kPartForearmLeft, kPartHandLeft};
  for (int part = kPartHead; part <= kPartFootRight; ++part)
    if (part != kPartForearmLeft && part != kPartHandLeft) rest.parts.push_back(part);
  // A positive turn about +x takes -z (the hanging forearm) to +y (anterior, RAS).
  handle.motion = Eigen::Translation3d(elbow) *
                  Eigen::AngleAxisd(degrees * M_PI / 180, Eigen::Vector3d::UnitX()) *
                  Eigen::Translation3d(-elbow);
  for (Eigen::Index v = 0; v < cage.vertices.rows(); ++v) {
    const Eigen::Vector3d p = cage.vertices.row(v);
    // The left arm hangs at -x; 25 mm past the shoulder's x keeps the hip and thigh out.
    (p.z() < elbow.z() && p.x() < shoulder.x() + 25 ? handle : rest).cageVertices.push_back(int(v));
  }
  return {handle, rest};
}

Eigen::MatrixX3d phantomElbowFlexion(const Phantom& phantom, const TriangleMesh& cage,
                                     double degrees) {
  return moveHandles(cage.vertices, phantomElbowFlexionHandles(phantom, cage, degrees));
}

}  // namespace repose
