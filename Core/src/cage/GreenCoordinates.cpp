// Green coordinates for triangle cages, following the closed-form integrals of Lipman et al.
// 2008 (their Algorithm 1 and GCTriInt), with guards where a point lies in a face's plane or on
// an edge's line so the coordinates stay finite.
#include "repose/cage/GreenCoordinates.h"

#include "repose/cage/TriangleClosestPoint.h"

#include "repose/util/Error.h"
#include "repose/util/Parallel.h"

#include <Eigen/Geometry>
#include <cmath>
#include <limits>

namespace repose {
namespace {

constexpr double kPi = 3.14159265358979323846;

double sign(double x) {
  return x > 0 ? 1.0 : (x < 0 ? -1.0 : 0.0);
}

// Integral over the triangle (p, v1, v2) of the Green function gradient term, eta at origin
// (Lipman et al.'s GCTriInt), for its two angles theta = pi - alpha (alpha at v1) and
// pi - alpha - beta (beta at p), which is the angle at v2. S = sin(theta), C = cos(theta),
// oneMinusC = 1 - C; lambda: the squared distance from p to the edge's line; c = |p|^2.
double gcTriIntTerm(double S, double C, double oneMinusC, double lambda, double c) {
  const double sqrtC = std::sqrt(c), sqrtL = std::sqrt(lambda);
  const double denom = oneMinusC * oneMinusC;
  double logTerm = 0;
  // lambda -> 0 (eta on the edge's line) makes sqrt(lambda)*log(...) -> 0.
  if (sqrtL > 1e-12 && denom > 1e-300) {
    // The paper's 1 - 2cC / (c(1 + C) + lambda + R), R = sqrt(lambda^2 + lambda c S^2), written
    // as one quotient: for a small angle the subtraction would leave no significant digit.
    const double R = std::sqrt(lambda * lambda + lambda * c * S * S);
    const double arg =
        2 * sqrtL * S * S / denom * (c * oneMinusC + lambda + R) / (c * (1 + C) + lambda + R);
    if (arg > 0) logTerm = sqrtL * std::log(arg);
  }
  const double atanTerm =
      sqrtC > 0 ? 2 * sqrtC * std::atan(sqrtC * C / std::sqrt(lambda + S * S * c)) : 0;
  return -sign(S) / 2 * (atanTerm + logTerm);
}

// Above this |cos| an angle's sine taken as sqrt(1 - cos^2), or 1 - cos by subtraction, keeps too
// few digits (at 1e-7 mm from an edge's line only about 8, which the log and atan terms
// amplify): the angles are then taken from unit vectors instead.
constexpr double kNearlyFlat = 1 - 1e-6;

double gcTriInt(const Eigen::Vector3d& p, const Eigen::Vector3d& v1, const Eigen::Vector3d& v2) {
  const Eigen::Vector3d d = v2 - v1, r = p - v1, a = v1 - p, b = v2 - p;
  const double nd = d.norm(), nr = r.norm(), nb = b.norm();
  const double c = p.squaredNorm();
  if (nd > 0 && nr > 0 && nb > 0) {
    // Most sub-triangles: the angle-sum identities, one inverse trigonometric call (beta).
    const double cosA = std::clamp(d.dot(r) / (nd * nr), -1.0, 1.0);
    const double cosB = std::clamp(a.dot(b) / (nr * nb), -1.0, 1.0);
    const double sinA = std::sqrt(std::max(0.0, 1 - cosA * cosA));
    const double sinB = std::sqrt(std::max(0.0, 1 - cosB * cosB));
    const double C2 = -(cosA * cosB - sinA * sinB);
    if (std::fabs(cosA) < kNearlyFlat && std::fabs(cosB) < kNearlyFlat &&
        std::fabs(C2) < kNearlyFlat) {
      const double lambda = r.squaredNorm() * sinA * sinA;
      const double I1 = gcTriIntTerm(sinA, -cosA, 1 + cosA, lambda, c);
      const double I2 = gcTriIntTerm(sinA * cosB + cosA * sinB, C2, 1 - C2, lambda, c);
      return -1 / (4 * kPi) * std::fabs(I1 - I2 - std::sqrt(c) * std::atan2(sinB, cosB));
    }
  }
  // A nearly flat sub-triangle (p close to the edge's line): every sine, cosine and 1 - cos from
  // the unit vectors of its angle (|u x w|, u . w, |u -+ w|^2 / 2), beta from atan2.
  const auto unit = [](const Eigen::Vector3d& x) {
    const double n = x.norm();
    return n > 0 ? Eigen::Vector3d(x / n) : Eigen::Vector3d::Zero();
  };
  const Eigen::Vector3d e1 = unit(d), q1 = unit(r);    // alpha's sides, at v1
  const Eigen::Vector3d e2 = unit(-d), q2 = unit(-b);  // the angle at v2
  const double beta = std::atan2(a.cross(b).norm(), a.dot(b));
  const double lambda = nd > 0 ? d.cross(r).squaredNorm() / (nd * nd) : 0.0;
  const double I1 =
      gcTriIntTerm(e1.cross(q1).norm(), -e1.dot(q1), (e1 + q1).squaredNorm() / 2, lambda, c);
  const double I2 =
      gcTriIntTerm(e2.cross(q2).norm(), e2.dot(q2), (e2 - q2).squaredNorm() / 2, lambda, c);
  return -1 / (4 * kPi) * std::fabs(I1 - I2 - std::sqrt(c) * beta);
}

}  // namespace

Eigen::MatrixX3d faceNormals(const Eigen::MatrixX3d& vertices, const Eigen::MatrixX3i& faces) {
  Eigen::MatrixX3d n(faces.rows(), 3);
  for (Eigen::Index f = 0; f < faces.rows(); ++f) {
    const Eigen::Vector3d a = vertices.row(faces(f, 0)), b = vertices.row(faces(f, 1)),
                          c = vertices.row(faces(f, 2));
    const Eigen::Vector3d cross = (b - a).cross(c - a);
    const double len = cross.norm();
    n.row(f) = len > 0 ? Eigen::Vector3d(cross / len) : Eigen::Vector3d::Zero();
  }
  return n;
}

GreenCoordinates computeGreenCoordinates(const TriangleMesh& cage, const Eigen::MatrixX3d& points,
                                         int threads) {
  const Eigen::Index nv = cage.vertices.rows(), nf = cage.faces.rows();
  if (nv < 4 || nf < 4)
    throw Error("Green coordinates need a closed cage (at least a tetrahedron)");
  const Eigen::MatrixX3d normals = faceNormals(cage.vertices, cage.faces);
  // The closed forms divide tiny by tiny for points within ~1e-6 of a face's plane. Such points
  // are evaluated a little inside instead, which bounds the error by that offset.
  const double size =
      (cage.vertices.colwise().maxCoeff() - cage.vertices.colwise().minCoeff()).norm();
  const double nearSurface = 1e-5 * size;
  GreenCoordinates gc;
  gc.phi.setZero(points.rows(), nv);
  gc.psi.setZero(points.rows(), nf);
  parallelFor(
      points.rows(), threads,
      [&](std::int64_t begin, std::int64_t end) {
        for (std::int64_t r = begin; r < end; ++r) {
          Eigen::Vector3d eta = points.row(r);
          // Near an edge or a corner one push leaves the point close to the other faces: repeat.
          for (int push = 0; push < 8; ++push) {
            double closest = std::numeric_limits<double>::max();
            Eigen::Index closestFace = -1;
            for (Eigen::Index f = 0; f < nf; ++f) {
              // The distance to a triangle is at least the distance to its plane: most faces stop
              // here.
              const double plane = std::fabs(
                  normals.row(f).dot(eta - cage.vertices.row(cage.faces(f, 0)).transpose()));
              if (plane >= std::min(closest, nearSurface)) continue;
              const double d = pointTriangleDistance(eta, cage.vertices.row(cage.faces(f, 0)),
                                                     cage.vertices.row(cage.faces(f, 1)),
                                                     cage.vertices.row(cage.faces(f, 2)));
              if (d < closest) closest = d, closestFace = f;
            }
            if (closest >= nearSurface) break;
            eta -= 2 * nearSurface * normals.row(closestFace).transpose();
          }
          for (Eigen::Index f = 0; f < nf; ++f) {
            const Eigen::Vector3d n = normals.row(f);
            Eigen::Vector3d v[3];
            for (int l = 0; l < 3; ++l)
              v[l] = cage.vertices.row(cage.faces(f, l)).transpose() - eta;
            const Eigen::Vector3d p = v[0].dot(n) * n;
            double s[3], I[3], II[3];
            Eigen::Vector3d N[3];
            for (int l = 0; l < 3; ++l) {
              const Eigen::Vector3d& a = v[l];
              const Eigen::Vector3d& b = v[(l + 1) % 3];
              // The sub-triangle (p, a, b) of eta's projection p: when p lies on the edge's
              // line (eta right above a cage edge, or above its extension: common where the
              // cage's triangles are long and thin) it has no area and adds nothing, but its
              // closed form divides rounding noise by rounding noise (sin(alpha) ~ 0 in
              // gcTriInt) and, with a sign picked from that noise, threw points tens of
              // millimetres off. Below 1e-10 of the edge's length from the line it is skipped.
              const double twiceArea = (a - p).cross(b - p).dot(n);
              const bool onLine = std::fabs(twiceArea) <= 1e-10 * (b - a).squaredNorm();
              s[l] = onLine ? 0.0 : sign(twiceArea);
              I[l] = onLine ? 0.0 : gcTriInt(p, a, b);
              II[l] = gcTriInt(Eigen::Vector3d::Zero(), b, a);
              const Eigen::Vector3d q = b.cross(a);
              const double qn = q.norm();
              N[l] = qn > 0 ? Eigen::Vector3d(q / qn) : Eigen::Vector3d::Zero();
            }
            const double Itotal = -std::fabs(s[0] * I[0] + s[1] * I[1] + s[2] * I[2]);
            gc.psi(r, f) = -Itotal;
            const Eigen::Vector3d w = n * Itotal + N[0] * II[0] + N[1] * II[1] + N[2] * II[2];
            if (w.norm() > 1e-12) {
              for (int l = 0; l < 3; ++l) {
                const Eigen::Vector3d& Nn = N[(l + 1) % 3];
                const double d = Nn.dot(v[l]);
                if (std::fabs(d) > 1e-300) gc.phi(r, cage.faces(f, l)) += Nn.dot(w) / d;
              }
            }
          }
        }
      },
      16);
  return gc;
}

Eigen::VectorXd greenFaceStretch(const TriangleMesh& rest, const Eigen::MatrixX3d& deformed) {
  Eigen::VectorXd s(rest.faces.rows());
  for (Eigen::Index f = 0; f < rest.faces.rows(); ++f) {
    const auto& F = rest.faces;
    const Eigen::Vector3d u = rest.vertices.row(F(f, 1)) - rest.vertices.row(F(f, 0));
    const Eigen::Vector3d v = rest.vertices.row(F(f, 2)) - rest.vertices.row(F(f, 0));
    const Eigen::Vector3d u2 = deformed.row(F(f, 1)) - deformed.row(F(f, 0));
    const Eigen::Vector3d v2 = deformed.row(F(f, 2)) - deformed.row(F(f, 0));
    const double area = 0.5 * u.cross(v).norm();
    const double num = u2.squaredNorm() * v.squaredNorm() - 2 * u2.dot(v2) * u.dot(v) +
                       v2.squaredNorm() * u.squaredNorm();
    s[f] = area > 0 ? std::sqrt(std::max(0.0, num)) / (std::sqrt(8.0) * area) : 1.0;
  }
  return s;
}

Eigen::MatrixX3d applyGreenCoordinates(const GreenCoordinates& gc, const TriangleMesh& rest,
                                       const Eigen::MatrixX3d& deformed) {
  const Eigen::MatrixX3d normals = faceNormals(deformed, rest.faces);
  const Eigen::VectorXd stretch = greenFaceStretch(rest, deformed);
  return gc.phi * deformed + gc.psi * (stretch.asDiagonal() * normals);
}

}  // namespace repose
