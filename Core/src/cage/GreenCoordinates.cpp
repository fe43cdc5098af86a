// Green coordinates for triangle cages, following the closed-form integrals of Lipman et al.
// 2008 (their Algorithm 1 and GCTriInt), with guards where a point lies in a face's plane or on
// an edge's line so the coordinates stay finite.
#include "repose/cage/GreenCoordinates.h"

#include "TriangleClosestPoint.h"

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

// Cosine of the angle between a and b (1 when either is zero, i.e. the angle is taken as 0).
double cosAngle(const Eigen::Vector3d& a, const Eigen::Vector3d& b) {
  const double d = a.norm() * b.norm();
  return d > 0 ? std::clamp(a.dot(b) / d, -1.0, 1.0) : 1.0;
}

// Integral over the triangle (p, v1, v2) of the Green function gradient term, eta at origin.
// The sines and cosines of theta = pi - alpha and pi - alpha - beta come from dot products and
// the angle-sum identities: only beta itself needs an inverse trigonometric call.
double gcTriInt(const Eigen::Vector3d& p, const Eigen::Vector3d& v1, const Eigen::Vector3d& v2) {
  const double cosA = cosAngle(v2 - v1, p - v1), sinA = std::sqrt(std::max(0.0, 1 - cosA * cosA));
  const double cosB = cosAngle(v1 - p, v2 - p), sinB = std::sqrt(std::max(0.0, 1 - cosB * cosB));
  const double beta = std::atan2(sinB, cosB);
  const double lambda = (p - v1).squaredNorm() * sinA * sinA;
  const double c = p.squaredNorm();
  const double sqrtC = std::sqrt(c), sqrtL = std::sqrt(lambda);
  auto integral = [&](double S, double C) {
    const double denom = (1 - C) * (1 - C);
    double logTerm = 0;
    // lambda -> 0 (eta on the edge's line) makes sqrt(lambda)*log(...) -> 0.
    if (sqrtL > 1e-12 && denom > 1e-300) {
      const double arg =
          2 * sqrtL * S * S / denom *
          (1 -
           2 * c * C / (c * (1 + C) + lambda + std::sqrt(lambda * lambda + lambda * c * S * S)));
      if (arg > 0) logTerm = sqrtL * std::log(arg);
    }
    const double atanTerm =
        sqrtC > 0 ? 2 * sqrtC * std::atan(sqrtC * C / std::sqrt(lambda + S * S * c)) : 0;
    return -sign(S) / 2 * (atanTerm + logTerm);
  };
  // theta1 = pi - alpha; theta2 = pi - (alpha + beta).
  const double I1 = integral(sinA, -cosA);
  const double I2 = integral(sinA * cosB + cosA * sinB, -(cosA * cosB - sinA * sinB));
  return -1 / (4 * kPi) * std::fabs(I1 - I2 - sqrtC * beta);
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
              s[l] = sign((a - p).cross(b - p).dot(n));
              I[l] = gcTriInt(p, a, b);
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
