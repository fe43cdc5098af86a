// Analytic shapes the phantom is built from: elliptic round cones (tapered capsules) for the body
// segments and bones, ellipsoids and ellipsoid shells for organs, and boxes for culling.
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>

#include <algorithm>
#include <cmath>
#include <cstdint>

namespace repose::phantom {

struct Box {
  Eigen::Vector3d lo = Eigen::Vector3d::Constant(1e300);
  Eigen::Vector3d hi = Eigen::Vector3d::Constant(-1e300);

  void extend(const Box& b) {
    lo = lo.cwiseMin(b.lo);
    hi = hi.cwiseMax(b.hi);
  }
  Box expanded(double m) const { return {(lo.array() - m).matrix(), (hi.array() + m).matrix()}; }
  bool containsZ(double z) const { return z >= lo.z() && z <= hi.z(); }
  bool containsY(double y) const { return y >= lo.y() && y <= hi.y(); }
  bool containsX(double x) const { return x >= lo.x() && x <= hi.x(); }
  bool contains(const Eigen::Vector3d& p) const {
    return containsX(p.x()) && containsY(p.y()) && containsZ(p.z());
  }
};

// Polynomial smooth minimum: equals min(a, b) once |a - b| >= k, and keeps the 1-Lipschitz
// property of its arguments, so creases between segments get a fillet of about k/4.
inline double smoothMin(double a, double b, double k) {
  const double h = std::max(k - std::fabs(a - b), 0.0) / k;
  return std::min(a, b) - h * h * k * 0.25;
}

// A tapered capsule (the convex hull of two spheres) whose cross-section is squashed into an
// ellipse: semi-axes r*s1 along e1 and r*s2 along e2 (s1, s2 <= 1), r along the axis. Bodies are
// rarely round, and one primitive type for limbs, torso, head, hands, feet and bones keeps the
// evaluation loop simple.
struct RoundCone {
  Eigen::Vector3d a = Eigen::Vector3d::Zero(), u = Eigen::Vector3d::UnitZ();
  Eigen::Vector3d e1 = Eigen::Vector3d::UnitX(), e2 = Eigen::Vector3d::UnitY();
  double len = 1, r1 = 1, r2 = 1, s1 = 1, s2 = 1;
  double sinT = 0, cosT = 1;  // slope of the side line (Quilez's round cone)

  // `across` says where e1 points (projected perpendicular to the axis); e2 completes the frame.
  static RoundCone make(const Eigen::Vector3d& from, const Eigen::Vector3d& to, double rFrom,
                        double rTo, const Eigen::Vector3d& across = Eigen::Vector3d::UnitX(),
                        double s1 = 1, double s2 = 1) {
    RoundCone c;
    c.a = from;
    c.len = (to - from).norm();
    c.u = (to - from) / c.len;
    Eigen::Vector3d e = across - across.dot(c.u) * c.u;
    if (e.norm() < 1e-9) e = c.u.unitOrthogonal();
    c.e1 = e.normalized();
    c.e2 = c.u.cross(c.e1);
    c.r1 = rFrom;
    c.r2 = rTo;
    c.s1 = s1;
    c.s2 = s2;
    c.sinT = (rFrom - rTo) / c.len;  // caller keeps |r1 - r2| < len
    c.cosT = std::sqrt(1 - c.sinT * c.sinT);
    return c;
  }

  // Distance to the surface in the squashed frame (exact for a round cross-section); its sign
  // is exact, its magnitude is the first-order distance (value / gradient norm) so tissue
  // layers keep their thickness around the ellipse.
  double distance(const Eigen::Vector3d& p) const {
    const Eigen::Vector3d d = p - a;
    const double t = d.dot(u);
    const double x1 = d.dot(e1) / s1, x2 = d.dot(e2) / s2;
    const double rho = std::sqrt(x1 * x1 + x2 * x2);
    double dist, gr, gt;
    const double k = -sinT * rho + cosT * t;
    if (k < 0) {
      const double n = std::sqrt(rho * rho + t * t);
      dist = n - r1;
      gr = n > 0 ? rho / n : 1;
      gt = n > 0 ? t / n : 0;
    } else if (k > cosT * len) {
      const double tt = t - len, n = std::sqrt(rho * rho + tt * tt);
      dist = n - r2;
      gr = n > 0 ? rho / n : 1;
      gt = n > 0 ? tt / n : 0;
    } else {
      dist = cosT * rho + sinT * t - r1;
      gr = cosT;
      gt = sinT;
    }
    if (s1 == 1 && s2 == 1) return dist;
    double c1 = 1, c2 = 0;
    if (rho > 1e-9) c1 = x1 / rho, c2 = x2 / rho;
    const double gx = c1 / s1, gy = c2 / s2;
    return dist / std::sqrt(gr * gr * (gx * gx + gy * gy) + gt * gt);
  }
  bool inside(const Eigen::Vector3d& p) const { return distance(p) < 0; }

  Box bounds() const {
    Box b;
    for (int end = 0; end < 2; ++end) {
      const Eigen::Vector3d c = end ? Eigen::Vector3d(a + len * u) : a;
      const double r = end ? r2 : r1;
      for (int w = 0; w < 3; ++w) {
        const double half =
            r * std::sqrt(std::pow(s1 * e1[w], 2) + std::pow(s2 * e2[w], 2) + std::pow(u[w], 2));
        b.lo[w] = std::min(b.lo[w], c[w] - half);
        b.hi[w] = std::max(b.hi[w], c[w] + half);
      }
    }
    return b;
  }
};

// Axis-aligned ellipsoid; organs are placed, not posed, so no rotation is needed.
struct Ellipsoid {
  Eigen::Vector3d c = Eigen::Vector3d::Zero(), r = Eigen::Vector3d::Ones();
  double level(const Eigen::Vector3d& p) const {
    return ((p - c).array() / r.array()).square().sum();
  }
  bool inside(const Eigen::Vector3d& p) const { return level(p) < 1; }
  Box bounds() const { return {c - r, c + r}; }
};

}  // namespace repose::phantom
