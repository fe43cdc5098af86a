// ARAP local/global iterations. The global step solves L_ff x_f = b_f - L_fh x_h with a CHOLMOD
// factorization of L_ff made in setHandles; the local step fits one rotation per vertex.
#include "repose/cage/ArapDeformer.h"

#include "repose/numerics/SparseCholesky.h"
#include "repose/util/Error.h"

#include <Eigen/Geometry>
#include <Eigen/SVD>
#include <algorithm>
#include <cmath>
#include <map>
#include <set>

namespace repose {

struct ArapDeformer::Impl {
  Eigen::MatrixX3d rest;
  // Symmetric edge list with cotangent weights: neighbours[i] = (j, w_ij).
  std::vector<std::vector<std::pair<int, double>>> neighbours;
  std::vector<int> handles;
  std::vector<int> freeIndex;  // vertex -> row in the free system, or -1 for a handle
  std::vector<int> freeVertices;
  Eigen::SparseMatrix<double> Lfh;  // free x handle coupling (negated weights)
  SparseCholesky llt;

  std::vector<Eigen::Matrix3d> rotations(const Eigen::MatrixX3d& p) const {
    std::vector<Eigen::Matrix3d> R(rest.rows());
    for (Eigen::Index i = 0; i < rest.rows(); ++i) {
      Eigen::Matrix3d S = Eigen::Matrix3d::Zero();
      for (const auto& [j, w] : neighbours[i])
        S += w * (rest.row(i) - rest.row(j)).transpose() * (p.row(i) - p.row(j));
      Eigen::JacobiSVD<Eigen::Matrix3d> svd(S, Eigen::ComputeFullU | Eigen::ComputeFullV);
      Eigen::Matrix3d Ri = svd.matrixV() * svd.matrixU().transpose();
      if (Ri.determinant() < 0) {  // a reflection: flip the axis of the smallest singular value
        Eigen::Matrix3d V = svd.matrixV();
        V.col(2) *= -1;
        Ri = V * svd.matrixU().transpose();
      }
      R[i] = Ri;
    }
    return R;
  }

  double energy(const Eigen::MatrixX3d& p, const std::vector<Eigen::Matrix3d>& R) const {
    double e = 0;
    for (Eigen::Index i = 0; i < rest.rows(); ++i)
      for (const auto& [j, w] : neighbours[i])
        e +=
            w * ((p.row(i) - p.row(j)).transpose() - R[i] * (rest.row(i) - rest.row(j)).transpose())
                    .squaredNorm();
    return e;
  }
};

ArapDeformer::ArapDeformer(const TriangleMesh& rest) : impl_(std::make_unique<Impl>()) {
  const Eigen::Index nv = rest.vertices.rows();
  if (nv < 4 || rest.faces.rows() < 4)
    throw Error("ARAP needs a closed cage with at least 4 vertices");
  if (rest.faces.minCoeff() < 0 || rest.faces.maxCoeff() >= nv)
    throw Error("ARAP cage has a face index out of range");
  impl_->rest = rest.vertices;
  // Cotangent weight of edge (i,j): half the sum of the cotangents of the opposite angles.
  std::map<std::pair<int, int>, double> weights;
  for (Eigen::Index f = 0; f < rest.faces.rows(); ++f)
    for (int c = 0; c < 3; ++c) {
      const int i = rest.faces(f, (c + 1) % 3), j = rest.faces(f, (c + 2) % 3),
                k = rest.faces(f, c);
      const Eigen::Vector3d a = rest.vertices.row(i) - rest.vertices.row(k);
      const Eigen::Vector3d b = rest.vertices.row(j) - rest.vertices.row(k);
      const double cross = a.cross(b).norm();
      const double cot = cross > 0 ? a.dot(b) / cross : 0;
      weights[std::minmax(i, j)] += 0.5 * cot;
    }
  double mean = 0;
  for (const auto& [edge, w] : weights) mean += std::fabs(w);
  mean /= std::max<std::size_t>(1, weights.size());
  // Obtuse triangles give negative cotangent weights, which can make the system indefinite.
  const double floor = 1e-3 * mean;
  impl_->neighbours.assign(nv, {});
  for (const auto& [edge, w] : weights) {
    const double wc = std::max(w, floor);
    impl_->neighbours[edge.first].emplace_back(edge.second, wc);
    impl_->neighbours[edge.second].emplace_back(edge.first, wc);
  }
}

ArapDeformer::~ArapDeformer() = default;
ArapDeformer::ArapDeformer(ArapDeformer&&) noexcept = default;
ArapDeformer& ArapDeformer::operator=(ArapDeformer&&) noexcept = default;

void ArapDeformer::setHandles(const std::vector<int>& handleVertices) {
  const int nv = static_cast<int>(impl_->rest.rows());
  if (handleVertices.empty()) throw Error("ARAP needs at least one handle vertex");
  std::set<int> unique;
  for (int h : handleVertices) {
    if (h < 0 || h >= nv)
      throw Error("handle vertex " + std::to_string(h) + " is not a cage vertex (0.." +
                  std::to_string(nv - 1) + ")");
    if (!unique.insert(h).second)
      throw Error("handle vertex " + std::to_string(h) + " given twice");
  }
  impl_->handles = handleVertices;
  impl_->freeIndex.assign(nv, -1);
  impl_->freeVertices.clear();
  for (int v = 0; v < nv; ++v)
    if (!unique.count(v)) {
      impl_->freeIndex[v] = static_cast<int>(impl_->freeVertices.size());
      impl_->freeVertices.push_back(v);
    }
  std::vector<int> handleIndex(nv, -1);
  for (std::size_t h = 0; h < handleVertices.size(); ++h)
    handleIndex[handleVertices[h]] = static_cast<int>(h);
  const int nf = static_cast<int>(impl_->freeVertices.size());
  std::vector<Eigen::Triplet<double>> ff, fh;
  for (int r = 0; r < nf; ++r) {
    const int i = impl_->freeVertices[r];
    double diagonal = 0;
    for (const auto& [j, w] : impl_->neighbours[i]) {
      diagonal += w;
      if (impl_->freeIndex[j] >= 0)
        ff.emplace_back(r, impl_->freeIndex[j], -w);
      else
        fh.emplace_back(r, handleIndex[j], -w);
    }
    ff.emplace_back(r, r, diagonal);
  }
  Eigen::SparseMatrix<double> Lff(nf, nf);
  Lff.setFromTriplets(ff.begin(), ff.end());
  impl_->Lfh.resize(nf, static_cast<Eigen::Index>(handleVertices.size()));
  impl_->Lfh.setFromTriplets(fh.begin(), fh.end());
  if (nf > 0) impl_->llt.factorize(Lff, "ARAP cage system");
}

const std::vector<int>& ArapDeformer::handles() const {
  return impl_->handles;
}

ArapResult ArapDeformer::solve(const Eigen::MatrixX3d& handleTargets,
                               const Eigen::MatrixX3d* initial, const ArapOptions& options) const {
  const Impl& m = *impl_;
  if (m.handles.empty()) throw Error("ARAP: setHandles must be called before solve");
  if (handleTargets.rows() != static_cast<Eigen::Index>(m.handles.size()))
    throw Error("ARAP: " + std::to_string(handleTargets.rows()) + " targets for " +
                std::to_string(m.handles.size()) + " handles");
  if (!handleTargets.allFinite()) throw Error("ARAP: handle targets are not finite");
  ArapResult result;
  result.positions = initial ? *initial : m.rest;
  if (result.positions.rows() != m.rest.rows())
    throw Error("ARAP: initial positions have the wrong size");
  for (std::size_t h = 0; h < m.handles.size(); ++h)
    result.positions.row(m.handles[h]) = handleTargets.row(h);
  if (m.freeVertices.empty()) return result;

  const Eigen::MatrixXd handleTerm = m.Lfh * handleTargets;
  double previous = m.energy(result.positions, m.rotations(result.positions));
  for (int it = 0; it < options.maxIterations; ++it) {
    const std::vector<Eigen::Matrix3d> R = m.rotations(result.positions);
    Eigen::MatrixXd b(m.freeVertices.size(), 3);
    for (std::size_t r = 0; r < m.freeVertices.size(); ++r) {
      const int i = m.freeVertices[r];
      Eigen::Vector3d bi = Eigen::Vector3d::Zero();
      for (const auto& [j, w] : m.neighbours[i])
        bi += 0.5 * w * (R[i] + R[j]) * (m.rest.row(i) - m.rest.row(j)).transpose();
      b.row(r) = bi.transpose();
    }
    const Eigen::MatrixXd x = m.llt.solve(b - handleTerm);
    for (std::size_t r = 0; r < m.freeVertices.size(); ++r)
      result.positions.row(m.freeVertices[r]) = x.row(r);
    const double e = m.energy(result.positions, m.rotations(result.positions));
    result.energies.push_back(e);
    result.iterations = it + 1;
    if (previous - e <= options.tolerance * std::max(previous, 1e-300)) break;
    previous = e;
  }
  return result;
}

double ArapDeformer::energy(const Eigen::MatrixX3d& deformed) const {
  return impl_->energy(deformed, impl_->rotations(deformed));
}

}  // namespace repose
