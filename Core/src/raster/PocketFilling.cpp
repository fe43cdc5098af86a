#include "repose/raster/PocketFilling.h"

#include "repose/util/Error.h"
#include "repose/volume/LabelStatistics.h"

#include <Eigen/LU>

#include <array>
#include <cmath>
#include <map>

namespace repose {
namespace {

// Fills the voxels listed in `fill` (flags per voxel) layer by layer with the most common
// non-zero label among their 6 neighbours not waiting to be filled.
template <class T>
void fillFromWalls(T* v, const std::array<std::int64_t, 3>& d, std::vector<char> fill,
                   const std::vector<std::int64_t>& voxels) {
  std::vector<std::int64_t> pending = voxels;
  while (!pending.empty()) {
    std::vector<std::pair<std::int64_t, T>> layer;
    std::vector<std::int64_t> rest;
    for (const std::int64_t c : pending) {
      const std::int64_t i = c % d[0], j = (c / d[0]) % d[1], k = c / (d[0] * d[1]);
      std::map<T, int> votes;
      auto vote = [&](bool inside, std::int64_t q) {
        if (inside && !fill[q] && v[q] != 0) ++votes[v[q]];
      };
      vote(i > 0, c - 1), vote(i + 1 < d[0], c + 1);
      vote(j > 0, c - d[0]), vote(j + 1 < d[1], c + d[0]);
      vote(k > 0, c - d[0] * d[1]), vote(k + 1 < d[2], c + d[0] * d[1]);
      if (votes.empty()) {
        rest.push_back(c);
        continue;
      }
      T best = votes.begin()->first;
      int most = 0;
      for (const auto& [label, n] : votes)
        if (n > most) most = n, best = label;  // ties to the smaller label: map order
      layer.emplace_back(c, best);
    }
    if (layer.empty()) break;  // a pocket with no labelled wall (cannot happen when enclosed)
    for (const auto& [c, label] : layer) v[c] = label, fill[c] = 0;
    pending.swap(rest);
  }
}

}  // namespace

PocketReport fillPosePockets(Volume& posed, const Volume& rest, const std::vector<float>& field,
                             Volume* posedParts) {
  if (!isIntegerType(posed.scalarType()) || !isIntegerType(rest.scalarType()))
    throw Error("pockets are filled in label maps, not in float volumes");
  const auto d = posed.dims(), rd = rest.dims();
  const std::int64_t n = posed.numVoxels();
  if (field.size() != std::size_t(3 * n))
    throw Error("the displacement field does not match the posed grid");
  if (posedParts && posedParts->dims() != d) throw Error("the posed parts map is on another grid");
  PocketReport report;
  const std::vector<char> restOutside = outsideBackground(rest);
  const std::vector<char> outside = outsideBackground(posed);
  auto restIsBackground = [&](std::int64_t q) {
    bool zero = false;
    dispatchScalar(rest.scalarType(), [&](auto* tag) {
      using T = std::remove_pointer_t<decltype(tag)>;
      zero = rest.data<T>()[q] == 0;
    });
    return zero;
  };
  std::vector<char> fill(n, 0);
  std::vector<std::int64_t> voxels;
  dispatchScalar(posed.scalarType(), [&](auto* tag) {
    using T = std::remove_pointer_t<decltype(tag)>;
    if constexpr (std::is_integral_v<T>) {
      const T* v = posed.data<T>();
      const Eigen::Matrix4d toRestIjk = rest.geometry().ijkToRas.inverse();
      for (std::int64_t k = 0; k < d[2]; ++k)
        for (std::int64_t j = 0; j < d[1]; ++j)
          for (std::int64_t i = 0; i < d[0]; ++i) {
            const std::int64_t c = posed.index(i, j, k);
            if (v[c] != 0 || outside[c]) continue;
            const Eigen::Vector3d ras =
                posed.geometry().voxelToRas(i, j, k) +
                Eigen::Vector3d(field[3 * c], field[3 * c + 1], field[3 * c + 2]);
            const Eigen::Vector4d r = toRestIjk * Eigen::Vector4d(ras.x(), ras.y(), ras.z(), 1);
            const double ri = std::floor(r.x() + 0.5), rj = std::floor(r.y() + 0.5),
                         rk = std::floor(r.z() + 0.5);
            const bool onGrid =
                ri >= 0 && rj >= 0 && rk >= 0 && ri < rd[0] && rj < rd[1] && rk < rd[2];
            // Off the rest grid: no tet covered it (the field points far outside) or it came
            // from the rest grid's own outside; either way not a cavity of the body.
            const std::int64_t q =
                onGrid ? rest.index(std::int64_t(ri), std::int64_t(rj), std::int64_t(rk)) : -1;
            // From rest background enclosed by the body: a cavity the body has. From its
            // outside, from tissue (the rasterizer put background there, so not) or from no
            // rest position at all: a pocket the pose made.
            const bool fromCavity = q >= 0 && !restOutside[q] && restIsBackground(q);
            if (fromCavity) {
              ++report.keptCavities;
            } else {
              fill[c] = 1;
              voxels.push_back(c);
            }
          }
      fillFromWalls(posed.data<T>(), d, fill, voxels);
    }
  });
  report.filled = std::int64_t(voxels.size());
  if (posedParts)
    dispatchScalar(posedParts->scalarType(), [&](auto* tag) {
      using T = std::remove_pointer_t<decltype(tag)>;
      if constexpr (std::is_integral_v<T>) fillFromWalls(posedParts->data<T>(), d, fill, voxels);
    });
  return report;
}

}  // namespace repose
