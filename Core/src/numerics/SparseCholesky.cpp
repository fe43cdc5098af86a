// CHOLMOD through Eigen's CholmodSupport; the cholmod_common lives inside the Eigen solver, so
// one SparseCholesky owns exactly one CHOLMOD context (RAII, no global state).
#include "repose/numerics/SparseCholesky.h"

#include "repose/util/Error.h"

#include <Eigen/CholmodSupport>

namespace repose {

struct SparseCholesky::Impl {
  Eigen::CholmodSupernodalLLT<Eigen::SparseMatrix<double>, Eigen::Lower> llt;
  bool ok = false;
};

SparseCholesky::SparseCholesky() : impl_(std::make_unique<Impl>()) {}
SparseCholesky::~SparseCholesky() = default;
SparseCholesky::SparseCholesky(SparseCholesky&&) noexcept = default;
SparseCholesky& SparseCholesky::operator=(SparseCholesky&&) noexcept = default;

void SparseCholesky::factorize(const Eigen::SparseMatrix<double>& A, const std::string& what) {
  impl_->ok = false;
  if (A.rows() != A.cols() || A.rows() == 0) throw Error(what + ": empty or non-square system");
  impl_->llt.compute(A);
  if (impl_->llt.info() != Eigen::Success)
    throw Error(what + ": the system is singular (a part of the mesh has no constraint)");
  impl_->ok = true;
}

bool SparseCholesky::factorized() const {
  return impl_->ok;
}

Eigen::MatrixXd SparseCholesky::solve(const Eigen::MatrixXd& B) const {
  if (!impl_->ok) throw Error("SparseCholesky::solve called before a successful factorize");
  Eigen::MatrixXd X = impl_->llt.solve(B);
  if (!X.allFinite()) throw Error("sparse solve produced non-finite values");
  return X;
}

}  // namespace repose
