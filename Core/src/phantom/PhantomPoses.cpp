#include "repose/phantom/PhantomPoses.h"

#include <Eigen/Geometry>
#include <cmath>

namespace repose {

Eigen::MatrixX3d phantomElbowFlexion(const Phantom& phantom, const TriangleMesh& cage,
                                     double degrees) {
  const Eigen::Vector3d elbow = phantom.joint("elbow_left").ras,
                        shoulder = phantom.joint("shoulder_left").ras;
  // A positive turn about +x takes -z (the hanging forearm) to +y (anterior, RAS).
  const Eigen::Matrix3d R =
      Eigen::AngleAxisd(degrees * M_PI / 180, Eigen::Vector3d::UnitX()).toRotationMatrix();
  Eigen::MatrixX3d out = cage.vertices;
  for (Eigen::Index v = 0; v < out.rows(); ++v) {
    const Eigen::Vector3d p = cage.vertices.row(v);
    // The left arm hangs at -x; 25 mm past the shoulder's x keeps the hip and thigh out.
    if (p.z() < elbow.z() && p.x() < shoulder.x() + 25)
      out.row(v) = (R * (p - elbow) + elbow).transpose();
  }
  return out;
}

}  // namespace repose
