// The point of a triangle closest to a point, as barycentric weights (Ericson, Real-Time
// Collision Detection, 5.1.5): shared by the Green coordinates (distance to the cage) and the
// handle influence (which cage vertices a surface point is nearest).
#pragma once

#include <Eigen/Core>

namespace repose {

// Weights (wa, wb, wc), summing to 1, of the point of triangle (a, b, c) closest to p.
inline Eigen::Vector3d closestPointWeights(const Eigen::Vector3d& p, const Eigen::Vector3d& a,
                                           const Eigen::Vector3d& b, const Eigen::Vector3d& c) {
  const Eigen::Vector3d ab = b - a, ac = c - a, ap = p - a;
  const double d1 = ab.dot(ap), d2 = ac.dot(ap);
  if (d1 <= 0 && d2 <= 0) return {1, 0, 0};
  const Eigen::Vector3d bp = p - b;
  const double d3 = ab.dot(bp), d4 = ac.dot(bp);
  if (d3 >= 0 && d4 <= d3) return {0, 1, 0};
  const double vc = d1 * d4 - d3 * d2;
  if (vc <= 0 && d1 >= 0 && d3 <= 0) {
    const double t = d1 / (d1 - d3);
    return {1 - t, t, 0};
  }
  const Eigen::Vector3d cp = p - c;
  const double d5 = ab.dot(cp), d6 = ac.dot(cp);
  if (d6 >= 0 && d5 <= d6) return {0, 0, 1};
  const double vb = d5 * d2 - d1 * d6;
  if (vb <= 0 && d2 >= 0 && d6 <= 0) {
    const double t = d2 / (d2 - d6);
    return {1 - t, 0, t};
  }
  const double va = d3 * d6 - d5 * d4;
  if (va <= 0 && (d4 - d3) >= 0 && (d5 - d6) >= 0) {
    const double t = (d4 - d3) / ((d4 - d3) + (d5 - d6));
    return {0, 1 - t, t};
  }
  const double denom = 1 / (va + vb + vc);
  return {1 - (vb + vc) * denom, vb * denom, vc * denom};
}

inline double pointTriangleDistance(const Eigen::Vector3d& p, const Eigen::Vector3d& a,
                                    const Eigen::Vector3d& b, const Eigen::Vector3d& c) {
  const Eigen::Vector3d w = closestPointWeights(p, a, b, c);
  return (p - (w.x() * a + w.y() * b + w.z() * c)).norm();
}

}  // namespace repose
