#include "LabelVolumeRounding.h"

#include <Eigen/LU>

#include <algorithm>
#include <atomic>
#include <numeric>

namespace repose::raster {

bool RoundingChooser::offer(const RoundingCandidate& r) {
  auto known = [&](std::int32_t l) { return l >= 0 && std::size_t(l) < target_.size(); };
  if (!known(r.from) || !known(r.to) || r.from == r.to || !(target_[std::size_t(r.to)] > 0))
    return false;
  // Moving one voxel from a to b changes the relative misfit sum by
  // (2(c_b - t_b) + 1) / t_b^2 + (2(t_a - c_a) + 1) / t_a^2; it is taken when that is negative.
  const std::size_t a = std::size_t(r.from), b = std::size_t(r.to);
  const double ta = std::max(1.0, target_[a]), tb = std::max(1.0, target_[b]);
  const double gain = (2 * (count_[b] - target_[b]) + 1) / (tb * tb) +
                      (2 * (target_[a] - count_[a]) + 1) / (ta * ta);
  if (gain >= 0) return false;
  count_[a] -= 1;
  count_[b] += 1;
  return true;
}

std::vector<std::size_t> chooseVolumeRounding(std::vector<RoundingCandidate>& candidates,
                                              const std::vector<double>& target,
                                              std::vector<double>& count) {
  std::vector<std::size_t> order(candidates.size());
  std::iota(order.begin(), order.end(), std::size_t(0));
  std::sort(order.begin(), order.end(), [&](std::size_t a, std::size_t b) {
    return roundingOrder(candidates[a], candidates[b]);
  });
  RoundingChooser chooser(target, count);
  std::vector<std::size_t> taken;
  for (const std::size_t c : order)
    if (chooser.offer(candidates[c])) taken.push_back(c);
  return taken;
}

RoundingTargets roundingTargets(const Volume& labels, const TransferMesh& mesh,
                                const Eigen::MatrixX3d& deformed, const Shell& shell,
                                const RasterOptions& options, const VolumeGeometry& output) {
  RoundingTargets t;
  dispatchScalar(labels.scalarType(), [&](auto* tag) {
    using T = std::remove_pointer_t<decltype(tag)>;
    if constexpr (std::is_integral_v<T>) {
      const T* src = labels.data<T>();
      const auto d = labels.dims();
      const std::int64_t nIn = labels.numVoxels();
      std::int64_t maxLabel = 0;
      for (std::int64_t v = 0; v < nIn; ++v) maxLabel = std::max<std::int64_t>(maxLabel, src[v]);
      if (maxLabel > (1 << 24)) {
        t.skipped = "labels beyond 2^24";
        return;
      }
      if (maxLabel <= 0) return;  // no label to round
      t.maxLabel = maxLabel;
      t.soft.assign(std::size_t(maxLabel) + 1, 1);
      t.soft[0] = 0;
      for (std::size_t v = 0; v < shell.boneLabel.size() && v < t.soft.size(); ++v)
        if (shell.boneLabel[v]) t.soft[v] = 0;

      // Volume ratio (deformed over rest) of every tet.
      const Eigen::Index nt = mesh.tets.rows();
      std::vector<double> ratio(std::size_t(nt), 1.0);
      for (Eigen::Index e = 0; e < nt; ++e) {
        Eigen::Matrix3d R, D;
        for (int c = 0; c < 3; ++c) {
          R.col(c) = (mesh.vertices.row(mesh.tets(e, c + 1)) - mesh.vertices.row(mesh.tets(e, 0)))
                         .transpose();
          D.col(c) =
              (deformed.row(mesh.tets(e, c + 1)) - deformed.row(mesh.tets(e, 0))).transpose();
        }
        const double rest = R.determinant();
        ratio[std::size_t(e)] = rest != 0 ? D.determinant() / rest : 0.0;
      }
      // Per label, the sum of the ratios over its rest voxels, in 2^-20 voxels (fixed point, so
      // the threads' sums add up the same on every run).
      constexpr double kUnit = 1 << 20;
      std::vector<std::atomic<std::int64_t>> sums(std::size_t(maxLabel) + 1);
      for (auto& a : sums) a = 0;
      RasterOptions rest;
      rest.threads = options.threads;
      rest.shellMm = options.shellMm;
      rest.outerFaces = options.outerFaces;
      const VolumeGeometry& g = labels.geometry();
      const ScanInput restIn = makeScanInput(mesh, mesh.vertices, g, g);
      Shell restShell = makeShell(mesh, g, g, rest);
      // The posed shell's rule for whose tissue a shell voxel is, on the same input grid: its
      // coverage of the rest mesh is shared, not scanned again.
      restShell.restParts = shell.restParts;
      restShell.tetParts = shell.tetParts;
      restShell.restCovered = shell.restCovered;
      restShell.claimsBackground = shell.claimsBackground;
      const std::int64_t nx = d[0], plane = d[0] * d[1];
      runScan(restIn, restShell, rest, "label volumes at rest", nullptr, 1.0,
              [&](std::int64_t k, std::int64_t j, std::int64_t i0, std::int64_t i1,
                  const Eigen::Vector3d&, const Eigen::Vector3d&, std::int32_t tet) {
                const T* row = src + k * plane + j * nx;
                std::int64_t run = 0;
                T value = row[i0];
                auto flush = [&] {
                  if (run > 0 && t.isSoft(std::int64_t(value)))
                    sums[std::size_t(value)] +=
                        std::llround(double(run) * ratio[std::size_t(tet)] * kUnit);
                };
                for (std::int64_t i = i0; i <= i1; ++i) {
                  if (row[i] != value) flush(), run = 0, value = row[i];
                  ++run;
                }
                flush();
              });
      const double voxelRatio =
          std::fabs(labels.geometry().ijkToRas.block<3, 3>(0, 0).determinant()) /
          std::fabs(output.ijkToRas.block<3, 3>(0, 0).determinant());
      t.target.assign(std::size_t(maxLabel) + 1, 0.0);
      for (std::size_t v = 1; v < t.target.size(); ++v)
        if (t.soft[v]) t.target[v] = std::max(0.0, double(sums[v].load()) / kUnit * voxelRatio);
    }
  });
  return t;
}

}  // namespace repose::raster
