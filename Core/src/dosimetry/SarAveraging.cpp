#include "repose/dosimetry/SarAveraging.h"

#include "SarBoxIntegrals.h"

#include "repose/util/Error.h"
#include "repose/util/Parallel.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <optional>
#include <sstream>
#include <string>

namespace repose {
namespace {

using sar::BoxIntegrals;
using sar::BoxSums;

void checkInput(const SarCellGrid& grid, const std::vector<double>& density,
                const std::vector<double>& localSar, const SarAveragingOptions& options) {
  for (int a = 0; a < 3; ++a) {
    if (grid.dims[a] < 1 || grid.edges[a].size() != std::size_t(grid.dims[a]) + 1) {
      throw Error("SAR averaging: axis " + std::string(1, "xyz"[a]) + " has " +
                  std::to_string(grid.dims[a]) + " cells and " +
                  std::to_string(grid.edges[a].size()) + " edges (cells + 1 needed)");
    }
    for (int c = 0; c < grid.dims[a]; ++c) {
      if (!(grid.edges[a][c + 1] > grid.edges[a][c]) || !std::isfinite(grid.edges[a][c + 1])) {
        throw Error("SAR averaging: the edges along " + std::string(1, "xyz"[a]) +
                    " do not increase at cell " + std::to_string(c));
      }
    }
  }
  const std::size_t n = std::size_t(grid.cellCount());
  if (density.size() != n || localSar.size() != n) {
    throw Error("SAR averaging: " + std::to_string(density.size()) + " densities and " +
                std::to_string(localSar.size()) + " SAR values for a grid of " + std::to_string(n) +
                " cells");
  }
  for (std::size_t c = 0; c < n; ++c) {
    if (!(density[c] >= 0) || !std::isfinite(density[c]) || !(localSar[c] >= 0) ||
        !std::isfinite(localSar[c])) {
      throw Error("SAR averaging: cell " + std::to_string(c) +
                  " has a negative or non-finite density or SAR");
    }
  }
  if (!(options.massKg > 0) || !(options.maxBackgroundFraction >= 0) ||
      !(options.massTolerance > 0) || !(options.faceCubeVolumeSlack >= 0)) {
    throw Error("SAR averaging: the mass, tolerances and background fraction must be positive");
  }
}

// The size s in (0, sMax] at which a cube's mass, continuous and non-decreasing in s, meets the
// target; nullopt when even sMax holds less. Regula falsi with the Illinois step on u = s^3 (in
// which a homogeneous cube's mass is linear), bisection when that stalls; solved 100 times more
// tightly than the tolerance asked for.
template <class MassOf>
std::optional<double> solveCubeSize(const MassOf& massOf, double sMax, double guess, double target,
                                    double tolerance) {
  const double want = 0.01 * tolerance * target;
  double uHi = sMax * sMax * sMax, fHi = massOf(sMax) - target;
  if (fHi < -tolerance * target) return std::nullopt;
  if (std::abs(fHi) <= want) return sMax;
  double uLo = 0, fLo = -target;
  double best = sMax, bestErr = std::abs(fHi);
  double u = std::clamp(guess * guess * guess, 1e-6 * uHi, uHi);
  int side = 0;  // which end was kept last, for the Illinois halving
  for (int iteration = 0; iteration < 200; ++iteration) {
    const double s = std::cbrt(u), f = massOf(s) - target;
    if (std::abs(f) < bestErr) best = s, bestErr = std::abs(f);
    if (bestErr <= want) break;
    if (f < 0) {
      uLo = u, fLo = f;
      if (side == -1) fHi *= 0.5;
      side = -1;
    } else {
      uHi = u, fHi = f;
      if (side == 1) fLo *= 0.5;
      side = 1;
    }
    if (uHi - uLo <= 1e-15 * uHi) break;
    u = uLo - fLo * (uHi - uLo) / (fHi - fLo);
    if (!(u > uLo && u < uHi)) u = 0.5 * (uLo + uHi);
    if (iteration % 8 == 7) u = 0.5 * (uLo + uHi);  // guarantees progress on flat stretches
  }
  if (bestErr > tolerance * target) return std::nullopt;  // not reached: treat as no cube
  return best;
}

struct Cube {
  std::array<double, 3> lo, hi;
  BoxSums sums;
};

class Averager {
 public:
  Averager(const BoxIntegrals& box, const std::vector<double>& density,
           const SarAveragingOptions& options)
      : box_(box), grid_(box.grid()), density_(density), options_(options) {}

  // Step 1: the valid cube centred on cell (i, j, k), if there is one.
  std::optional<Cube> centredCube(const std::array<int, 3>& cell) const {
    std::array<double, 3> centre;
    for (int a = 0; a < 3; ++a) centre[a] = box_.centre(a, cell[a]);
    Cube cube;
    auto place = [&](double h) {
      for (int a = 0; a < 3; ++a) cube.lo[a] = centre[a] - h, cube.hi[a] = centre[a] + h;
    };
    auto massOf = [&](double edge) {
      place(0.5 * edge);
      return box_.sums(cube.lo, cube.hi).mass;
    };
    const std::optional<double> edge = solveCubeSize(massOf, largestEdge(), homogeneousEdge(cell),
                                                     options_.massKg, options_.massTolerance);
    if (!edge) return std::nullopt;
    place(0.5 * *edge);
    cube.sums = box_.sums(cube.lo, cube.hi);
    const double volume = *edge * *edge * *edge;
    if (cube.sums.background > options_.maxBackgroundFraction * volume) return std::nullopt;
    if (!facesTouchTissue(cube)) return std::nullopt;
    return cube;
  }

  // Step 3: the face cubes of cell (i, j, k): its mean and volume, the largest mean of those
  // within the slack of the smallest volume.
  std::optional<std::pair<double, double>> faceCube(const std::array<int, 3>& cell) const {
    double bestVolume = std::numeric_limits<double>::infinity();
    std::array<std::pair<double, double>, 6> found;  // (volume, mean)
    int count = 0;
    for (int axis = 0; axis < 3; ++axis) {
      for (int side : {-1, 1}) {
        std::optional<Cube> cube = faceCubeToward(cell, axis, side);
        if (!cube) continue;
        const double edge = cube->hi[0] - cube->lo[0];
        found[count++] = {edge * edge * edge, cube->sums.power / cube->sums.mass};
        bestVolume = std::min(bestVolume, found[count - 1].first);
      }
    }
    if (count == 0) return std::nullopt;
    double mean = 0;
    for (int t = 0; t < count; ++t) {
      if (found[t].first <= (1 + options_.faceCubeVolumeSlack) * bestVolume) {
        mean = std::max(mean, found[t].second);
      }
    }
    return std::make_pair(mean, std::cbrt(bestVolume));
  }

 private:
  // A cube of this edge placed at any cell holds the whole grid: no cube needs to be larger.
  double largestEdge() const {
    double extent = 0;
    for (int a = 0; a < 3; ++a) extent = std::max(extent, box_.upper(a) - box_.lower(a));
    return 2 * extent;
  }

  // A first guess: the edge of a cube of the target mass at the cell's own density.
  double homogeneousEdge(const std::array<int, 3>& cell) const {
    const std::int64_t c =
        cell[0] + std::int64_t(grid_.dims[0]) * (cell[1] + std::int64_t(grid_.dims[1]) * cell[2]);
    return std::cbrt(options_.massKg / std::max(density_[c], 1.0));
  }

  // The cube's outermost layer of cells on each face holds tissue (a face beyond the grid has
  // none).
  bool facesTouchTissue(const Cube& cube) const {
    std::array<int, 3> first, last;
    for (int a = 0; a < 3; ++a) {
      if (cube.lo[a] < box_.lower(a) || cube.hi[a] > box_.upper(a)) return false;
      first[a] = box_.cellAbove(a, cube.lo[a]);
      last[a] = box_.cellBelow(a, cube.hi[a]);
    }
    for (int a = 0; a < 3; ++a) {
      for (int layer : {first[a], last[a]}) {
        std::array<int, 3> f = first, l = last;
        f[a] = l[a] = layer;
        if (box_.tissueCells(f, l) == 0) return false;
      }
    }
    return true;
  }

  // The cube whose face along `axis` on the side opposite `side` is the cell's outer face, the
  // cell at its centre, extending by its edge in direction `side`.
  std::optional<Cube> faceCubeToward(const std::array<int, 3>& cell, int axis, int side) const {
    const std::vector<double>& e = grid_.edges[axis];
    const double face = side > 0 ? e[cell[axis]] : e[cell[axis] + 1];
    std::array<double, 3> centre;
    for (int a = 0; a < 3; ++a) centre[a] = box_.centre(a, cell[a]);
    Cube cube;
    auto place = [&](double edge) {
      for (int a = 0; a < 3; ++a) {
        if (a == axis) {
          cube.lo[a] = side > 0 ? face : face - edge;
          cube.hi[a] = side > 0 ? face + edge : face;
        } else {
          cube.lo[a] = centre[a] - 0.5 * edge, cube.hi[a] = centre[a] + 0.5 * edge;
        }
      }
    };
    auto massOf = [&](double edge) {
      place(edge);
      return box_.sums(cube.lo, cube.hi).mass;
    };
    const std::optional<double> edge = solveCubeSize(massOf, largestEdge(), homogeneousEdge(cell),
                                                     options_.massKg, options_.massTolerance);
    if (!edge) return std::nullopt;
    place(*edge);
    cube.sums = box_.sums(cube.lo, cube.hi);
    return cube;
  }

  const BoxIntegrals& box_;
  const SarCellGrid& grid_;
  const std::vector<double>& density_;
  const SarAveragingOptions& options_;
};

std::array<int, 3> cellOf(const SarCellGrid& grid, std::int64_t c) {
  const std::int64_t nxy = std::int64_t(grid.dims[0]) * grid.dims[1];
  return {int(c % grid.dims[0]), int((c % nxy) / grid.dims[0]), int(c / nxy)};
}

// Runs body over [0, n) in blocks, with a progress point between blocks (on this thread).
template <class Body>
void inBlocks(std::int64_t n, const SarAveragingOptions& options, double from, double to,
              const std::string& stage, Body&& body) {
  const std::int64_t block = std::max<std::int64_t>(4096, n / 50);
  for (std::int64_t b = 0; b < n; b += block) {
    reportProgress(options.progress, from + (to - from) * double(b) / double(n), stage);
    const std::int64_t end = std::min(n, b + block);
    parallelFor(
        end - b, options.threads, [&](std::int64_t i0, std::int64_t i1) { body(b + i0, b + i1); },
        16);
  }
}

}  // namespace

SarAveraged averageSarIec62704(const SarCellGrid& grid, const std::vector<double>& density,
                               const std::vector<double>& localSar,
                               const SarAveragingOptions& options) {
  checkInput(grid, density, localSar, options);
  const std::int64_t n = grid.cellCount();
  reportProgress(options.progress, 0.0, "SAR averaging: sums");
  const BoxIntegrals box(grid, density, localSar, options.threads);
  const Averager averager(box, density, options);

  SarAveraged out;
  out.sar.assign(std::size_t(n), 0.0);
  out.kind.assign(std::size_t(n), SarCubeKind::Background);
  out.cubeEdge.assign(std::size_t(n), 0.0);
  std::vector<std::int64_t> tissue;
  for (std::int64_t c = 0; c < n; ++c) {
    if (density[std::size_t(c)] > 0) tissue.push_back(c);
  }

  // 1. Centred cubes.
  double largestHalf = 0;
  inBlocks(std::int64_t(tissue.size()), options, 0.05, 0.75, "SAR averaging: centred cubes",
           [&](std::int64_t t0, std::int64_t t1) {
             for (std::int64_t t = t0; t < t1; ++t) {
               const std::int64_t c = tissue[std::size_t(t)];
               const std::optional<Cube> cube = averager.centredCube(cellOf(grid, c));
               out.kind[std::size_t(c)] = cube ? SarCubeKind::Centred : SarCubeKind::None;
               if (!cube) continue;
               out.sar[std::size_t(c)] = cube->sums.power / cube->sums.mass;
               out.cubeEdge[std::size_t(c)] = cube->hi[0] - cube->lo[0];
             }
           });
  for (std::int64_t c : tissue) largestHalf = std::max(largestHalf, 0.5 * out.cubeEdge[c]);

  // 2. Cells wholly inside valid cubes: search the centres within reach of the largest cube.
  std::vector<std::int64_t> rest;
  for (std::int64_t c : tissue) {
    if (out.kind[std::size_t(c)] == SarCubeKind::None) rest.push_back(c);
  }
  std::vector<double> covered(rest.size(), -1.0);
  inBlocks(std::int64_t(rest.size()), options, 0.75, 0.85, "SAR averaging: covered cells",
           [&](std::int64_t r0, std::int64_t r1) {
             for (std::int64_t r = r0; r < r1; ++r) {
               const std::array<int, 3> v = cellOf(grid, rest[std::size_t(r)]);
               std::array<double, 3> lo, hi;
               std::array<int, 3> first, last;
               for (int a = 0; a < 3; ++a) {
                 lo[a] = grid.edges[a][v[a]], hi[a] = grid.edges[a][v[a] + 1];
                 first[a] = box.cellAbove(a, hi[a] - largestHalf);
                 last[a] = box.cellBelow(a, lo[a] + largestHalf);
               }
               double best = -1;
               for (int k = first[2]; k <= last[2]; ++k) {
                 for (int j = first[1]; j <= last[1]; ++j) {
                   for (int i = first[0]; i <= last[0]; ++i) {
                     const std::int64_t u =
                         i + std::int64_t(grid.dims[0]) * (j + std::int64_t(grid.dims[1]) * k);
                     if (out.kind[std::size_t(u)] != SarCubeKind::Centred) continue;
                     const double h = 0.5 * out.cubeEdge[std::size_t(u)];
                     const std::array<int, 3> cu{i, j, k};
                     bool inside = true;
                     for (int a = 0; a < 3 && inside; ++a) {
                       const double centre = box.centre(a, cu[a]);
                       // A cell on the cube's face counts as inside, to rounding.
                       const double slack = 1e-9 * (hi[a] - lo[a]);
                       inside = centre - h <= lo[a] + slack && hi[a] <= centre + h + slack;
                     }
                     if (inside) best = std::max(best, out.sar[std::size_t(u)]);
                   }
                 }
               }
               covered[std::size_t(r)] = best;
             }
           });
  std::vector<std::int64_t> unused;
  for (std::size_t r = 0; r < rest.size(); ++r) {
    if (covered[r] >= 0) {
      out.kind[std::size_t(rest[r])] = SarCubeKind::Covered;
      out.sar[std::size_t(rest[r])] = covered[r];
    } else {
      unused.push_back(rest[r]);
    }
  }

  // 3. Face cubes for the rest.
  inBlocks(std::int64_t(unused.size()), options, 0.85, 1.0, "SAR averaging: face cubes",
           [&](std::int64_t u0, std::int64_t u1) {
             for (std::int64_t t = u0; t < u1; ++t) {
               const std::int64_t c = unused[std::size_t(t)];
               const auto found = averager.faceCube(cellOf(grid, c));
               if (!found) continue;  // stays None, averaged SAR 0
               out.kind[std::size_t(c)] = SarCubeKind::FaceCube;
               out.sar[std::size_t(c)] = found->first;
               out.cubeEdge[std::size_t(c)] = found->second;
             }
           });

  for (std::int64_t c = 0; c < n; ++c) {
    ++out.count[std::size_t(out.kind[std::size_t(c)])];
    if (out.kind[std::size_t(c)] != SarCubeKind::Background &&
        (out.peakCell < 0 || out.sar[std::size_t(c)] > out.peak)) {
      out.peak = out.sar[std::size_t(c)];
      out.peakCell = c;
    }
  }
  reportProgress(options.progress, 1.0, "SAR averaging: done");
  return out;
}

}  // namespace repose
