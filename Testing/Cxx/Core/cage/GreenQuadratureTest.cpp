// Green coordinates against their integrals (issue 29, item 4). The reference integrates the
// definitions of Lipman et al. (2008), which the seed uses, by quadrature written here:
//   phi_i(eta) = sum over the faces at v_i of  int Gamma_i(xi) dG/dn(xi, eta) dsigma,
//   psi_j(eta) = - int_{t_j} G(xi, eta) dsigma,      G(xi, eta) = -1 / (4 pi |xi - eta|),
// Gamma_i the hat function of v_i on the face, n the face's outward unit normal. Each face is
// split recursively until a piece is smaller than a tenth of its distance to eta, and each piece
// integrated with Dunavant's 7-point degree-5 rule. The reference first proves itself (it
// reproduces eta: sum phi_i v_i + sum psi_j n_j = eta, Green's identity for the linear function)
// and then the production coordinates (closed forms, src/cage/GreenCoordinates.cpp) must agree
// with it: at the middle, under a dent of a non-convex cage, near a face, an edge and a vertex.
#include "repose/cage/GreenCoordinates.h"
#include "repose/cage/TriangleMesh.h"

#include <gtest/gtest.h>

#include <Eigen/Geometry>

#include <array>
#include <cmath>

using namespace repose;

namespace {

// A 100 mm cube whose top face is dented: its centre vertex pushed 30 mm down into the cube
// (the cage is not convex there). Faces outward.
TriangleMesh dentedCube() {
  TriangleMesh c;
  c.vertices.resize(9, 3);
  c.vertices << 0, 0, 0, 100, 0, 0, 100, 100, 0, 0, 100, 0,  // bottom
      0, 0, 100, 100, 0, 100, 100, 100, 100, 0, 100, 100,    // top corners
      50, 50, 70;                                            // the dent
  c.faces.resize(14, 3);
  c.faces << 0, 2, 1, 0, 3, 2,             // bottom (normal -z)
      0, 1, 5, 0, 5, 4,                    // y = 0
      1, 2, 6, 1, 6, 5,                    // x = 100
      2, 3, 7, 2, 7, 6,                    // y = 100
      3, 0, 4, 3, 4, 7,                    // x = 0
      4, 5, 8, 5, 6, 8, 6, 7, 8, 7, 4, 8;  // the dented top
  return c;
}

struct QuadratureRule {
  double a, b, c, w;
};
constexpr double kA1 = 0.059715871789770, kB1 = 0.470142064105115, kW1 = 0.132394152788506;
constexpr double kA2 = 0.797426985353087, kB2 = 0.101286507323456, kW2 = 0.125939180544827;
constexpr QuadratureRule kDunavant5[7] = {{1.0 / 3, 1.0 / 3, 1.0 / 3, 0.225},
                                          {kA1, kB1, kB1, kW1},
                                          {kB1, kA1, kB1, kW1},
                                          {kB1, kB1, kA1, kW1},
                                          {kA2, kB2, kB2, kW2},
                                          {kB2, kA2, kB2, kW2},
                                          {kB2, kB2, kA2, kW2}};

struct Reference {
  Eigen::RowVectorXd phi, psi;
};

// One face's contribution, on the piece whose corners have face-barycentric coordinates L0..L2.
void integratePiece(const std::array<Eigen::Vector3d, 3>& corner, const Eigen::Vector3d& normal,
                    const Eigen::Vector3d& eta, const std::array<Eigen::Vector3d, 3>& L, int depth,
                    Eigen::Vector3d& phiFace, double& psiFace) {
  auto at = [&](const Eigen::Vector3d& l) {
    return Eigen::Vector3d(l[0] * corner[0] + l[1] * corner[1] + l[2] * corner[2]);
  };
  const Eigen::Vector3d p0 = at(L[0]), p1 = at(L[1]), p2 = at(L[2]);
  const double h = std::max({(p1 - p0).norm(), (p2 - p1).norm(), (p0 - p2).norm()});
  const double d = ((p0 + p1 + p2) / 3 - eta).norm() - h;
  if (depth < 18 && h > 0.1 * std::max(d, 0.0)) {
    const Eigen::Vector3d m01 = (L[0] + L[1]) / 2, m12 = (L[1] + L[2]) / 2, m20 = (L[2] + L[0]) / 2;
    for (const auto& piece : {std::array<Eigen::Vector3d, 3>{L[0], m01, m20},
                              std::array<Eigen::Vector3d, 3>{m01, L[1], m12},
                              std::array<Eigen::Vector3d, 3>{m20, m12, L[2]},
                              std::array<Eigen::Vector3d, 3>{m01, m12, m20}})
      integratePiece(corner, normal, eta, piece, depth + 1, phiFace, psiFace);
    return;
  }
  const double area = (p1 - p0).cross(p2 - p0).norm() / 2;
  for (const QuadratureRule& q : kDunavant5) {
    const Eigen::Vector3d l = q.a * L[0] + q.b * L[1] + q.c * L[2];
    const Eigen::Vector3d xi = at(l);
    const double r = (xi - eta).norm();
    const double w = q.w * area;
    psiFace += w / (4 * M_PI * r);                                     // -G
    phiFace += w * l * normal.dot(xi - eta) / (4 * M_PI * r * r * r);  // Gamma * dG/dn
  }
}

Reference integrate(const TriangleMesh& cage, const Eigen::Vector3d& eta) {
  Reference ref;
  ref.phi = Eigen::RowVectorXd::Zero(cage.vertices.rows());
  ref.psi = Eigen::RowVectorXd::Zero(cage.faces.rows());
  for (Eigen::Index f = 0; f < cage.faces.rows(); ++f) {
    std::array<Eigen::Vector3d, 3> corner;
    for (int k = 0; k < 3; ++k) corner[std::size_t(k)] = cage.vertices.row(cage.faces(f, k));
    const Eigen::Vector3d normal =
        (corner[1] - corner[0]).cross(corner[2] - corner[0]).normalized();
    Eigen::Vector3d phiFace = Eigen::Vector3d::Zero();
    double psiFace = 0;
    integratePiece(corner, normal, eta,
                   {Eigen::Vector3d::UnitX(), Eigen::Vector3d::UnitY(), Eigen::Vector3d::UnitZ()},
                   0, phiFace, psiFace);
    for (int k = 0; k < 3; ++k) ref.phi[cage.faces(f, k)] += phiFace[k];
    ref.psi[f] = psiFace;
  }
  return ref;
}

}  // namespace

TEST(GreenQuadrature, ClosedFormsEqualTheIntegralsInsideANonConvexCage) {
  const TriangleMesh cage = dentedCube();
  const Eigen::MatrixX3d normals = faceNormals(cage.vertices, cage.faces);
  struct Where {
    const char* name;
    Eigen::Vector3d eta;
  };
  const Where points[] = {{"middle", {50, 50, 40}},
                          {"under the dent", {50, 50, 66}},
                          {"beside the dent, above its tip", {20, 30, 85}},
                          {"0.5 mm from the bottom face", {37, 61, 0.5}},
                          {"0.5 mm from an edge", {0.5, 0.5, 43}},
                          {"1 mm from a corner", {99, 99, 1}},
                          {"0.5 mm below a dented face", {35, 50, 78.5}}};
  for (const Where& w : points) {
    const Reference ref = integrate(cage, w.eta);
    // The reference reproduces the point and the constant (sum phi = 1): it integrates what it
    // says it does.
    const Eigen::Vector3d reproduced =
        (ref.phi * cage.vertices).transpose() + (ref.psi * normals).transpose();
    ASSERT_LT((reproduced - w.eta).norm(), 1e-8) << w.name << ": the quadrature itself";
    ASSERT_NEAR(ref.phi.sum(), 1, 1e-8) << w.name;
    const GreenCoordinates gc = computeGreenCoordinates(cage, w.eta.transpose(), 1);
    EXPECT_LT((gc.phi.row(0) - ref.phi).cwiseAbs().maxCoeff(), 1e-9) << w.name << ": phi";
    EXPECT_LT((gc.psi.row(0) - ref.psi).cwiseAbs().maxCoeff(), 1e-8) << w.name << ": psi (mm)";
  }
}
