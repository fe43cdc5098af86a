#include "LabelVolumeRounding.h"

#include <algorithm>
#include <numeric>

namespace repose::raster {

std::vector<std::size_t> chooseVolumeRounding(std::vector<RoundingCandidate>& candidates,
                                              const std::vector<double>& target,
                                              std::vector<double>& count) {
  std::vector<std::size_t> order(candidates.size());
  std::iota(order.begin(), order.end(), std::size_t(0));
  std::sort(order.begin(), order.end(), [&](std::size_t a, std::size_t b) {
    const RoundingCandidate &x = candidates[a], &y = candidates[b];
    return x.score != y.score ? x.score > y.score : x.voxel < y.voxel;
  });
  auto known = [&](std::int32_t l) { return l >= 0 && std::size_t(l) < target.size(); };
  // Moving one voxel from a to b changes the relative misfit sum by
  // (2(c_b - t_b) + 1) / t_b^2 + (2(t_a - c_a) + 1) / t_a^2; it is taken when that is negative.
  auto gain = [&](std::int32_t a, std::int32_t b) {
    const double ta = std::max(1.0, target[std::size_t(a)]),
                 tb = std::max(1.0, target[std::size_t(b)]);
    return (2 * (count[std::size_t(b)] - target[std::size_t(b)]) + 1) / (tb * tb) +
           (2 * (target[std::size_t(a)] - count[std::size_t(a)]) + 1) / (ta * ta);
  };
  std::vector<std::size_t> taken;
  for (const std::size_t c : order) {
    const RoundingCandidate& r = candidates[c];
    if (!known(r.from) || !known(r.to) || r.from == r.to || !(target[std::size_t(r.to)] > 0))
      continue;
    if (gain(r.from, r.to) >= 0) continue;
    taken.push_back(c);
    count[std::size_t(r.from)] -= 1;
    count[std::size_t(r.to)] += 1;
  }
  return taken;
}

}  // namespace repose::raster
