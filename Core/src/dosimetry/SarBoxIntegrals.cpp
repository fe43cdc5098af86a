#include "SarBoxIntegrals.h"

#include "repose/util/Parallel.h"

#include <algorithm>

namespace repose::sar {
namespace {

// The cumulative sum at x along one axis, as weights on two nodes: inside a cell it is linear.
struct AxisTerms {
  std::array<int, 4> node{};
  std::array<double, 4> weight{};
  int count = 0;

  void add(int n, double w) {
    if (w == 0) return;
    for (int t = 0; t < count; ++t) {
      if (node[t] == n) {
        weight[t] += w;
        return;
      }
    }
    node[count] = n;
    weight[count] = w;
    ++count;
  }
};

}  // namespace

BoxIntegrals::BoxIntegrals(const SarCellGrid& grid, const std::vector<double>& density,
                           const std::vector<double>& localSar, int threads)
    : grid_(grid), dims_(grid.dims) {
  const int nx = dims_[0], ny = dims_[1], nz = dims_[2];
  prefix_.assign(std::size_t(nx + 1) * (ny + 1) * (nz + 1), BoxSums{});
  tissue_.assign(prefix_.size(), 0);
  // Cell values into node (i+1, j+1, k+1); then running sums along x, y and z in turn.
  parallelFor(
      nz, threads,
      [&](std::int64_t k0, std::int64_t k1) {
        for (std::int64_t k = k0; k < k1; ++k) {
          const double dz = grid.edges[2][k + 1] - grid.edges[2][k];
          for (int j = 0; j < ny; ++j) {
            const double dyz = dz * (grid.edges[1][j + 1] - grid.edges[1][j]);
            for (int i = 0; i < nx; ++i) {
              const std::int64_t c = i + std::int64_t(nx) * (j + std::int64_t(ny) * k);
              const double volume = dyz * (grid.edges[0][i + 1] - grid.edges[0][i]);
              BoxSums& s = prefix_[node(i + 1, j + 1, int(k) + 1)];
              s.mass = density[c] * volume;
              s.power = localSar[c] * s.mass;
              s.background = density[c] > 0 ? volume : 0.0;  // tissue volume, see sums()
              tissue_[node(i + 1, j + 1, int(k) + 1)] = density[c] > 0 ? 1 : 0;
            }
          }
        }
      },
      1);
  auto accumulate = [](BoxSums& to, const BoxSums& from) {
    to.mass += from.mass;
    to.power += from.power;
    to.background += from.background;
  };
  parallelFor(
      nz + 1, threads,
      [&](std::int64_t k0, std::int64_t k1) {
        for (std::int64_t k = k0; k < k1; ++k) {
          for (int j = 0; j <= ny; ++j) {
            for (int i = 1; i <= nx; ++i) {
              accumulate(prefix_[node(i, j, int(k))], prefix_[node(i - 1, j, int(k))]);
              tissue_[node(i, j, int(k))] += tissue_[node(i - 1, j, int(k))];
            }
          }
          for (int j = 1; j <= ny; ++j) {
            for (int i = 0; i <= nx; ++i) {
              accumulate(prefix_[node(i, j, int(k))], prefix_[node(i, j - 1, int(k))]);
              tissue_[node(i, j, int(k))] += tissue_[node(i, j - 1, int(k))];
            }
          }
        }
      },
      1);
  for (int k = 1; k <= nz; ++k) {
    parallelFor(
        std::int64_t(nx + 1) * (ny + 1), threads,
        [&](std::int64_t a, std::int64_t b) {
          const std::int64_t slab = std::int64_t(nx + 1) * (ny + 1);
          for (std::int64_t p = a; p < b; ++p) {
            accumulate(prefix_[p + slab * k], prefix_[p + slab * (k - 1)]);
            tissue_[p + slab * k] += tissue_[p + slab * (k - 1)];
          }
        },
        4096);
  }
}

int BoxIntegrals::cellAbove(int axis, double x) const {
  const std::vector<double>& e = grid_.edges[axis];
  const int c = int(std::upper_bound(e.begin(), e.end(), x) - e.begin()) - 1;
  return std::clamp(c, 0, dims_[axis] - 1);
}

int BoxIntegrals::cellBelow(int axis, double x) const {
  const std::vector<double>& e = grid_.edges[axis];
  const int c = int(std::lower_bound(e.begin(), e.end(), x) - e.begin()) - 1;
  return std::clamp(c, 0, dims_[axis] - 1);
}

BoxSums BoxIntegrals::sums(const std::array<double, 3>& lo, const std::array<double, 3>& hi) const {
  std::array<AxisTerms, 3> terms;
  double boxVolume = 1;
  for (int a = 0; a < 3; ++a) {
    const std::vector<double>& e = grid_.edges[a];
    boxVolume *= hi[a] - lo[a];
    const double inLo = std::clamp(lo[a], e.front(), e.back());
    const double inHi = std::clamp(hi[a], e.front(), e.back());
    for (const auto& [x, sign] : {std::pair<double, double>{inHi, 1.0}, {inLo, -1.0}}) {
      const int c = cellAbove(a, x);
      const double t = std::clamp((x - e[c]) / (e[c + 1] - e[c]), 0.0, 1.0);
      terms[a].add(c, sign * (1 - t));
      terms[a].add(c + 1, sign * t);
    }
  }
  BoxSums s;
  for (int tk = 0; tk < terms[2].count; ++tk) {
    for (int tj = 0; tj < terms[1].count; ++tj) {
      const double wjk = terms[2].weight[tk] * terms[1].weight[tj];
      for (int ti = 0; ti < terms[0].count; ++ti) {
        const double w = wjk * terms[0].weight[ti];
        const BoxSums& p = prefix_[node(terms[0].node[ti], terms[1].node[tj], terms[2].node[tk])];
        s.mass += w * p.mass;
        s.power += w * p.power;
        s.background += w * p.background;
      }
    }
  }
  s.background = std::max(0.0, boxVolume - s.background);  // the box less its tissue
  return s;
}

std::int64_t BoxIntegrals::tissueCells(const std::array<int, 3>& first,
                                       const std::array<int, 3>& last) const {
  const int i0 = first[0], j0 = first[1], k0 = first[2];
  const int i1 = last[0] + 1, j1 = last[1] + 1, k1 = last[2] + 1;
  return tissue_[node(i1, j1, k1)] - tissue_[node(i0, j1, k1)] - tissue_[node(i1, j0, k1)] -
         tissue_[node(i1, j1, k0)] + tissue_[node(i0, j0, k1)] + tissue_[node(i0, j1, k0)] +
         tissue_[node(i1, j0, k0)] - tissue_[node(i0, j0, k0)];
}

}  // namespace repose::sar
