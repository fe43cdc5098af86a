#include "repose/pose/EncasedTissue.h"

#include <algorithm>
#include <cmath>
#include <cstdint>

namespace repose {

std::vector<int> labelsEncasedInBone(const Volume& organs, const std::vector<int>& rigidLabels,
                                     const EncasedTissueOptions& options) {
  const auto& d = organs.dims();
  if (organs.numVoxels() == 0 || rigidLabels.empty()) return {};
  // The long axis: the voxel axis nearest S; the slices across it are scanned.
  const Eigen::Matrix3d dir = organs.geometry().directions();
  int along = 0;
  for (int a = 1; a < 3; ++a)
    if (std::fabs(dir(2, a)) > std::fabs(dir(2, along))) along = a;
  const int u = along == 0 ? 1 : 0, v = along == 2 ? 1 : 2;
  const Eigen::Vector3d spacing = organs.geometry().spacing();
  const std::int64_t reachU = std::max<std::int64_t>(1, std::llround(options.reachMm / spacing[u]));
  const std::int64_t reachV = std::max<std::int64_t>(1, std::llround(options.reachMm / spacing[v]));
  std::vector<char> rigid(65536, 0);
  for (const int l : rigidLabels)
    if (l > 0 && l <= 65535) rigid[std::size_t(l)] = 1;

  const std::int64_t nu = d[std::size_t(u)], nv = d[std::size_t(v)];
  const std::int64_t step[3] = {1, d[0], d[0] * d[1]};
  std::vector<std::int32_t> label(std::size_t(nu * nv));
  std::vector<std::uint8_t> sides(std::size_t(nu * nv));
  // Per label value (a vector: this runs per voxel of G).
  std::vector<std::int64_t> total(65536, 0), encased(65536, 0);
  // Along one line of the slice (n cells, `at(c)` its c-th), counts for each soft cell whether
  // bone lies within `reach` cells before it and, in the second sweep, after it.
  auto sweep = [&](std::int64_t n, std::int64_t reach, auto at) {
    std::int64_t last = -reach - 1;
    for (std::int64_t c = 0; c < n; ++c) {
      const std::int32_t l = label[std::size_t(at(c))];
      if (l > 0 && rigid[std::size_t(l)])
        last = c;
      else if (l > 0 && c - last <= reach)
        ++sides[std::size_t(at(c))];
    }
    last = n + reach;
    for (std::int64_t c = n - 1; c >= 0; --c) {
      const std::int32_t l = label[std::size_t(at(c))];
      if (l > 0 && rigid[std::size_t(l)])
        last = c;
      else if (l > 0 && last - c <= reach)
        ++sides[std::size_t(at(c))];
    }
  };
  for (std::int64_t s = 0; s < d[std::size_t(along)]; ++s) {
    for (std::int64_t b = 0; b < nv; ++b)
      for (std::int64_t a = 0; a < nu; ++a) {
        const double value = organs.valueAsDouble(s * step[along] + b * step[v] + a * step[u]);
        label[std::size_t(a + nu * b)] =
            value > 0 && value <= 65535 ? std::int32_t(std::lround(value)) : 0;
      }
    std::fill(sides.begin(), sides.end(), std::uint8_t(0));
    for (std::int64_t b = 0; b < nv; ++b)
      sweep(nu, reachU, [&](std::int64_t c) { return c + nu * b; });
    for (std::int64_t a = 0; a < nu; ++a)
      sweep(nv, reachV, [&](std::int64_t c) { return a + nu * c; });
    for (std::size_t c = 0; c < label.size(); ++c) {
      const std::int32_t l = label[c];
      if (l <= 0 || rigid[std::size_t(l)]) continue;
      ++total[std::size_t(l)];
      if (sides[c] >= options.sides) ++encased[std::size_t(l)];
    }
  }
  std::vector<int> out;
  for (std::size_t l = 1; l < total.size(); ++l)
    if (total[l] > 0 && double(encased[l]) >= options.share * double(total[l]))
      out.push_back(int(l));
  return out;
}

void softenEncasedNearOtherParts(const Volume& organs, const Volume& parts,
                                 const std::vector<int>& encased, double bandMm,
                                 std::uint16_t* piece) {
  if (encased.empty()) return;
  std::vector<char> isEncased(65536, 0);
  for (const int l : encased)
    if (l > 0 && l <= 65535) isEncased[std::size_t(l)] = 1;
  const auto& d = parts.dims();
  const Eigen::Vector3d spacing = parts.geometry().spacing();
  const std::int64_t step[3] = {1, d[0], d[0] * d[1]};
  std::vector<std::int64_t> soften;
  for (std::int64_t k = 0; k < d[2]; ++k)
    for (std::int64_t j = 0; j < d[1]; ++j)
      for (std::int64_t i = 0; i < d[0]; ++i) {
        const std::int64_t at = parts.index(i, j, k);
        const double label = organs.valueAsDouble(at);
        if (piece[at] == 0 || !(label > 0 && label <= 65535) ||
            !isEncased[std::size_t(std::lround(label))])
          continue;
        const double own = parts.valueAsDouble(at);
        const std::int64_t ijk[3] = {i, j, k};
        bool near = false;
        for (int a = 0; a < 3 && !near; ++a) {
          const std::int64_t reach = std::llround(bandMm / spacing[a]);
          for (const int sign : {-1, 1})
            for (std::int64_t s = 1; s <= reach && !near; ++s) {
              const std::int64_t n = ijk[a] + sign * s;
              if (n < 0 || n >= d[std::size_t(a)]) break;
              const double other = parts.valueAsDouble(at + sign * s * step[a]);
              near = other > 0 && other != own;
            }
        }
        if (near) soften.push_back(at);
      }
  for (const std::int64_t at : soften) piece[at] = 0;
}

}  // namespace repose
