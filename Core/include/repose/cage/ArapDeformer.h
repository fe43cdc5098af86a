// As-rigid-as-possible deformation of a cage (Sorkine & Alexa 2007): handle vertices are placed,
// every other vertex follows by alternating local rotations (SVD) and a global Laplacian solve.
#pragma once

#include "repose/cage/TriangleMesh.h"

#include <memory>
#include <vector>

namespace repose {

struct ArapOptions {
  int maxIterations = 100;
  double tolerance = 1e-8;  // stop when the energy decreases by less than this fraction
};

struct ArapResult {
  Eigen::MatrixX3d positions;  // #V by 3, handles exactly at their targets
  int iterations = 0;
  std::vector<double> energies;  // ARAP energy after each iteration (non-increasing)
};

// Keeps the factorization of the free-vertex Laplacian until the handle set changes, so each
// drag of the handles costs only back-substitutions.
class ArapDeformer {
 public:
  // rest: a closed, connected triangle mesh (mm). Cotangent weights, clamped to stay positive.
  explicit ArapDeformer(const TriangleMesh& rest);
  ~ArapDeformer();
  ArapDeformer(ArapDeformer&&) noexcept;
  ArapDeformer& operator=(ArapDeformer&&) noexcept;

  // Which vertices are constrained. Throws repose::Error for an empty set, a duplicate or an
  // index out of range. Factorizes (CHOLMOD) once per call.
  void setHandles(const std::vector<int>& handleVertices);
  const std::vector<int>& handles() const;

  // handleTargets: #handles by 3, in setHandles order. initial: #V by 3 start (rest if null).
  ArapResult solve(const Eigen::MatrixX3d& handleTargets, const Eigen::MatrixX3d* initial = nullptr,
                   const ArapOptions& options = {}) const;
  // Energy sum_i sum_j w_ij |(p'_i - p'_j) - R_i (p_i - p_j)|^2 with the best rotations R_i.
  double energy(const Eigen::MatrixX3d& deformed) const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace repose
