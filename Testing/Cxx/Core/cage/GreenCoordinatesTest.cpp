// Green coordinates properties over several cages: identity reproduction, exactness under
// similarities, finiteness near faces, edges and vertices; winding numbers inside/outside.
#include "TestMeshes.h"

#include "repose/cage/GreenCoordinates.h"
#include "repose/cage/WindingNumber.h"

#include <gtest/gtest.h>

#include <random>

using namespace repose;
using namespace repose::test;

namespace {

struct NamedCage {
  const char* name;
  TriangleMesh mesh;
};

std::vector<NamedCage> cages() {
  return {{"cube", boxMesh({-50, -50, -50}, {50, 50, 50}, 2)},
          {"thin_bar", boxMesh({0, 0, 0}, {400, 20, 20}, 3)},
          {"sphere", sphereMesh({10, -20, 30}, 120, 2)}};
}

// Random points strictly inside (winding number ~ 1), well away from the surface.
Eigen::MatrixX3d interiorPoints(const TriangleMesh& cage, int count, unsigned seed) {
  const Eigen::Vector3d lo = cage.vertices.colwise().minCoeff(),
                        hi = cage.vertices.colwise().maxCoeff();
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> u(0.05, 0.95);
  Eigen::MatrixX3d candidates(count * 4, 3);
  for (Eigen::Index r = 0; r < candidates.rows(); ++r)
    for (int c = 0; c < 3; ++c) candidates(r, c) = lo[c] + u(rng) * (hi[c] - lo[c]);
  const Eigen::VectorXd w = windingNumbers(cage, candidates);
  Eigen::MatrixX3d out(count, 3);
  int n = 0;
  for (Eigen::Index r = 0; r < candidates.rows() && n < count; ++r)
    if (w[r] > 0.999) out.row(n++) = candidates.row(r);
  return out.topRows(n);
}

double cageSize(const TriangleMesh& cage) {
  return (cage.vertices.colwise().maxCoeff() - cage.vertices.colwise().minCoeff()).norm();
}

}  // namespace

TEST(GreenCoordinates, UndeformedCageReproducesEveryInteriorPoint) {
  for (const auto& [name, cage] : cages()) {
    const Eigen::MatrixX3d points = interiorPoints(cage, 200, 1);
    ASSERT_GT(points.rows(), 100) << name;
    const GreenCoordinates gc = computeGreenCoordinates(cage, points);
    const Eigen::MatrixX3d out = applyGreenCoordinates(gc, cage, cage.vertices);
    EXPECT_LT((out - points).rowwise().norm().maxCoeff(), 1e-6 * cageSize(cage)) << name;
    // Partition of unity of phi holds inside the cage.
    EXPECT_LT((gc.phi.rowwise().sum().array() - 1).abs().maxCoeff(), 1e-6) << name;
  }
}

TEST(GreenCoordinates, SimilarityOfTheCageIsReproducedExactly) {
  std::mt19937 rng(5);
  for (const auto& [name, cage] : cages()) {
    const Eigen::MatrixX3d points = interiorPoints(cage, 150, 2);
    const GreenCoordinates gc = computeGreenCoordinates(cage, points);
    for (int trial = 0; trial < 3; ++trial) {
      const Eigen::Matrix3d R = Eigen::Quaterniond::UnitRandom().toRotationMatrix();
      const double scale = std::uniform_real_distribution<double>(0.3, 3.0)(rng);
      const Eigen::RowVector3d t(37.5, -12, 250);
      const Eigen::MatrixX3d deformed = (scale * cage.vertices * R.transpose()).rowwise() + t;
      const Eigen::MatrixX3d expected = (scale * points * R.transpose()).rowwise() + t;
      const Eigen::MatrixX3d out = applyGreenCoordinates(gc, cage, deformed);
      EXPECT_LT((out - expected).rowwise().norm().maxCoeff(), 1e-5 * scale * cageSize(cage))
          << name << " scale " << scale;
    }
  }
}

TEST(GreenCoordinates, StretchIsTheScaleOfASimilarity) {
  const TriangleMesh cage = sphereMesh({0, 0, 0}, 10, 1);
  const Eigen::Matrix3d R =
      Eigen::AngleAxisd(0.7, Eigen::Vector3d(1, 1, 0).normalized()).toRotationMatrix();
  const Eigen::VectorXd s = greenFaceStretch(cage, 2.5 * cage.vertices * R.transpose());
  EXPECT_LT((s.array() - 2.5).abs().maxCoeff(), 1e-12);
}

TEST(GreenCoordinates, FiniteAndAccurateNearFacesEdgesAndVertices) {
  const TriangleMesh cage = boxMesh({-1, -1, -1}, {1, 1, 1}, 1);
  const double size = std::sqrt(12.0);
  for (double gap : {1e-3, 1e-5, 1e-6, 1e-7, 1e-9, 1e-12, 0.0}) {
    Eigen::MatrixX3d points(4, 3);
    points << 0.3, 0.2, 1 - gap,    // under a face
        0.4, 0.4, 1 - gap,          // under a face's diagonal edge
        0, 1 - gap, 1 - gap,        // next to a cube edge
        1 - gap, 1 - gap, 1 - gap;  // next to a corner
    const GreenCoordinates gc = computeGreenCoordinates(cage, points);
    ASSERT_TRUE(gc.phi.allFinite()) << gap;
    ASSERT_TRUE(gc.psi.allFinite()) << gap;
    const Eigen::MatrixX3d out = applyGreenCoordinates(gc, cage, cage.vertices);
    // Points this close are evaluated up to ~1e-5 of the cage size inside: that bounds the error.
    EXPECT_LT((out - points).rowwise().norm().maxCoeff(), 1e-4 * size) << "gap " << gap;
  }
}

TEST(WindingNumber, OneInsideZeroOutsideForEveryCage) {
  for (const auto& [name, cage] : cages()) {
    const Eigen::Vector3d lo = cage.vertices.colwise().minCoeff(),
                          hi = cage.vertices.colwise().maxCoeff();
    Eigen::MatrixX3d pts(3, 3);
    pts.row(0) = (lo + hi) / 2;
    pts.row(1) = hi + (hi - lo);
    pts.row(2) = lo - Eigen::Vector3d(1e-3, 0, 0);
    const Eigen::VectorXd w = windingNumbers(cage, pts);
    EXPECT_NEAR(w[0], 1, 1e-9) << name;
    EXPECT_NEAR(w[1], 0, 1e-9) << name;
    EXPECT_NEAR(w[2], 0, 1e-6) << name;
  }
}

TEST(WindingNumber, FlippedOrientationGivesMinusOne) {
  TriangleMesh cage = boxMesh({-1, -1, -1}, {1, 1, 1}, 2);
  cage.faces.col(1).swap(cage.faces.col(2));
  EXPECT_NEAR(windingNumbers(cage, Eigen::RowVector3d(0.1, 0.2, 0.3))[0], -1, 1e-9);
}
