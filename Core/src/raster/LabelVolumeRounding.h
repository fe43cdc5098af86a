// Volume-preserving rounding of a posed label map (RasterOptions::preserveLabelVolumes).
//
// Nearest-neighbour sampling decides each output voxel by the one rest voxel its centre maps to.
// For a structure one or two voxels across, turned onto a grid of other spacing (an arm's vessel
// raised from 4.8 mm slices into the 1.8 mm plane), that decision alone moves the label's voxel
// count by several percent either way, whatever the deformation does (docs/QUALITY.md, the
// resampling floor). The deformation itself gives each label a volume: the sum over its rest
// voxels of det B_t of the tet carrying them. This step relabels voxels on the borders between
// soft labels so each label's count comes to that volume, choosing first the voxels whose rest
// position lies most in the label they go to (its trilinear weight there against the sampled
// label's).
//
// In three steps, so a frame too large for memory is rounded as one that fits (issue 56): the
// targets from the rest map (roundingTargets, once); each slab's counts and candidates, sorted
// (slabRoundingCandidates, a slab and the slices beside it); and the greedy choice over the
// candidates of every slab in one order (RoundingChooser), which a merge of the slabs' sorted
// runs gives exactly as one sort of them all.
#pragma once

#include "RasterScan.h"

#include <cstdint>
#include <string>
#include <vector>

namespace repose::raster {

struct RoundingCandidate {
  std::int64_t voxel = 0;  // output voxel index
  std::int32_t from = 0;   // its sampled label
  std::int32_t to = 0;     // the neighbouring label it may take
  float score = 0;         // trilinear weight of `to` minus that of `from` at its rest position
};

// The order candidates are offered in: best score first, ties by voxel index (a total order, as
// each voxel has one candidate).
inline bool roundingOrder(const RoundingCandidate& x, const RoundingCandidate& y) {
  return x.score != y.score ? x.score > y.score : x.voxel < y.voxel;
}

// The greedy step: a candidate is taken when it lowers the sum over labels of
// ((target - count) / target)^2, the relative misfit, so a vessel's few voxels weigh as much as
// a muscle's many. `count` (the sampled counts per label value) is updated as candidates are
// taken; offer them in roundingOrder.
class RoundingChooser {
 public:
  RoundingChooser(const std::vector<double>& target, std::vector<double>& count)
      : target_(target), count_(count) {}
  bool offer(const RoundingCandidate& c);

 private:
  const std::vector<double>& target_;
  std::vector<double>& count_;
};

// Chooses, from `candidates`, the relabellings that bring the counts towards `target` (per label
// value, in output voxels; `count` the sampled counts, updated), offered in roundingOrder.
// Returns the indices into `candidates` taken, in the order taken.
std::vector<std::size_t> chooseVolumeRounding(std::vector<RoundingCandidate>& candidates,
                                              const std::vector<double>& target,
                                              std::vector<double>& count);

// Per soft label (non-zero, not negative, not a piece's: Shell::boneLabel) the volume the
// deformation gives it, in output voxels: a scan of the rest mesh on the input's grid summing
// each tet's volume ratio over the voxels it carries. `skipped` says why the map is not rounded
// (labels beyond 2^24); no soft label leaves `soft` empty.
struct RoundingTargets {
  std::int64_t maxLabel = 0;
  std::vector<char> soft;      // per label value up to maxLabel
  std::vector<double> target;  // per label value
  std::string skipped;
  bool active() const { return skipped.empty() && maxLabel > 0; }
  bool isSoft(std::int64_t v) const { return v > 0 && v <= maxLabel && soft[std::size_t(v)]; }
};
RoundingTargets roundingTargets(const Volume& labels, const TransferMesh& mesh,
                                const Eigen::MatrixX3d& deformed, const Shell& shell,
                                const RasterOptions& options, const VolumeGeometry& output);

// One slab's share: slices [k0, k1) of the sampled labels (`slab`, as the label scan wrote them)
// with the slices k0 - 1 and k1 beside it (`below`, `above`; null at the grid's faces). Adds the
// slab's soft-label counts to `count` and appends its candidates, sorted in roundingOrder, to
// `out`: each voxel on a border between two soft labels (6-neighbours) that was sampled where its
// rest position is, with the soft label of most trilinear weight among the other labels of the 8
// rest voxels around that position. The border voxels are scanned again as the label scan did,
// so each keeps the rest position of the write that decided it; `sourceOf(i, j, k, p, tet)` is
// the rest voxel the scan sampled, `src` the rest map's layer 0 on grid `d`.
template <class T, class Source>
void slabRoundingCandidates(const ScanInput& in, const Shell& shell, const RasterOptions& options,
                            const VolumeGeometry& output, const RoundingTargets& t, const T* src,
                            const std::array<std::int64_t, 3>& d, const Source& sourceOf,
                            std::int64_t k0, std::int64_t k1, const T* below, const T* slab,
                            const T* above, std::vector<double>& count,
                            std::vector<RoundingCandidate>& out) {
  const std::int64_t nx = output.dims[0], ny = output.dims[1], plane = nx * ny;
  const std::int64_t n = plane * (k1 - k0);
  for (std::int64_t v = 0; v < n; ++v)
    if (t.isSoft(std::int64_t(slab[v]))) count[std::size_t(slab[v])] += 1;

  // The slab's voxels on a border between two soft labels, one bit each.
  const std::int64_t words = (n + 63) / 64;
  std::vector<std::uint64_t> border(std::size_t(words), 0);
  parallelFor(words, options.threads, [&](std::int64_t w0, std::int64_t w1) {
    for (std::int64_t w = w0; w < w1; ++w)
      for (std::int64_t v = 64 * w; v < std::min(n, 64 * (w + 1)); ++v) {
        const T a = slab[v];
        if (!t.isSoft(std::int64_t(a))) continue;
        const std::int64_t i = v % nx, j = (v / nx) % ny, k = v / plane;
        auto other = [&](T b) { return b != a && t.isSoft(std::int64_t(b)); };
        const bool down = k > 0 ? other(slab[v - plane]) : below && other(below[v % plane]);
        const bool up = k + 1 < k1 - k0 ? other(slab[v + plane]) : above && other(above[v % plane]);
        if ((i > 0 && other(slab[v - 1])) || (i + 1 < nx && other(slab[v + 1])) ||
            (j > 0 && other(slab[v - nx])) || (j + 1 < ny && other(slab[v + nx])) || down || up)
          border[std::size_t(w)] |= std::uint64_t(1) << (v - 64 * w);
      }
  });
  std::vector<std::int64_t> rank(std::size_t(words) + 1, 0);
  for (std::int64_t w = 0; w < words; ++w)
    rank[std::size_t(w) + 1] = rank[std::size_t(w)] + __builtin_popcountll(border[std::size_t(w)]);
  std::vector<RoundingCandidate> candidates(std::size_t(rank.back()),
                                            RoundingCandidate{0, -1, -1, 0});
  RasterOptions again = options;
  again.progress = {};
  runScan(
      in, shell, again, "label borders", nullptr, frameSign(output),
      [&](std::int64_t k, std::int64_t j, std::int64_t i0, std::int64_t i1, Eigen::Vector3d p,
          const Eigen::Vector3d& step, std::int32_t tet) {
        for (std::int64_t i = i0; i <= i1; ++i, p += step) {
          const std::int64_t v = (k - k0) * plane + j * nx + i;
          const std::uint64_t word = border[std::size_t(v / 64)];
          if (!(word >> (v % 64) & 1)) continue;
          RoundingCandidate& c = candidates[std::size_t(
              rank[std::size_t(v / 64)] +
              __builtin_popcountll(word & ((std::uint64_t(1) << (v % 64)) - 1)))];
          c.voxel = k * plane + j * nx + i;
          c.to = -1;
          const std::int64_t at = sourceOf(i, j, k, p, tet);
          // Only a voxel sampled where its rest position is (not redirected off a piece).
          if (at < 0 || at != nearestVoxel(p, d)) {
            c.from = -1;
            continue;
          }
          c.from = std::int32_t(src[at]);
          std::array<std::int32_t, 8> value;
          std::array<double, 8> weight;
          int m8 = 0;
          const double fx = std::floor(p.x()), fy = std::floor(p.y()), fz = std::floor(p.z());
          const double tx = p.x() - fx, ty = p.y() - fy, tz = p.z() - fz;
          for (int corner = 0; corner < 8; ++corner) {
            const std::int64_t x = std::int64_t(fx) + (corner & 1),
                               y = std::int64_t(fy) + (corner >> 1 & 1),
                               z = std::int64_t(fz) + (corner >> 2 & 1);
            const double w = ((corner & 1) ? tx : 1 - tx) * ((corner >> 1 & 1) ? ty : 1 - ty) *
                             ((corner >> 2 & 1) ? tz : 1 - tz);
            const std::int32_t l = x < 0 || y < 0 || z < 0 || x >= d[0] || y >= d[1] || z >= d[2]
                                       ? 0
                                       : std::int32_t(src[x + d[0] * (y + d[1] * z)]);
            int m = 0;
            while (m < m8 && value[std::size_t(m)] != l) ++m;
            if (m == m8) value[std::size_t(m8)] = l, weight[std::size_t(m8++)] = 0;
            weight[std::size_t(m)] += w;
          }
          double own = 0, best = -1;
          for (int m = 0; m < m8; ++m)
            if (value[std::size_t(m)] == c.from)
              own = weight[std::size_t(m)];
            else if (t.isSoft(value[std::size_t(m)]) && weight[std::size_t(m)] > best)
              best = weight[std::size_t(m)], c.to = value[std::size_t(m)];
          c.score = float(best - own);
        }
      },
      k0, k1);
  const std::size_t first = out.size();
  for (const RoundingCandidate& c : candidates)
    if (c.to >= 0 && c.from >= 0 && std::int64_t(slab[c.voxel - k0 * plane]) == c.from &&
        t.isSoft(c.from))
      out.push_back(c);
  std::sort(out.begin() + std::ptrdiff_t(first), out.end(), roundingOrder);
}

}  // namespace repose::raster
