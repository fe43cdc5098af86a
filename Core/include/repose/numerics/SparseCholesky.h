// A sparse symmetric positive definite factorization kept for repeated solves (CHOLMOD's
// supernodal LLT through Eigen). Shared by Core's solvers (cage, mesh); no header of Core's
// public interface includes it, so those show only Eigen's dense types.
#pragma once

#include <Eigen/Core>
#include <Eigen/SparseCore>
#include <memory>
#include <string>

namespace repose {

class SparseCholesky {
 public:
  SparseCholesky();
  ~SparseCholesky();
  SparseCholesky(SparseCholesky&&) noexcept;
  SparseCholesky& operator=(SparseCholesky&&) noexcept;

  // Factorizes A (symmetric positive definite; only the lower triangle is read). Throws
  // repose::Error naming `what` when A is not positive definite (e.g. an unconstrained part).
  void factorize(const Eigen::SparseMatrix<double>& A, const std::string& what);
  bool factorized() const;
  // Solves A X = B for all columns of B at once (one back-substitution per column).
  Eigen::MatrixXd solve(const Eigen::MatrixXd& B) const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace repose
