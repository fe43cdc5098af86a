// Separable exact EDT: one 1D lower-envelope pass per axis, each line independent (parallel).
// Anisotropy enters as the sample spacing of each pass, so distances are true millimetres.
#include "repose/volume/DistanceTransform.h"

#include "repose/util/Parallel.h"

#include <limits>

namespace repose {
namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();

// In place 1D transform of f (squared distances, may be inf) with sample spacing h:
// d(q) = min_p (h (q - p))^2 + f(p).
void transformLine(std::vector<double>& f, double h, std::vector<double>& d, std::vector<int>& v,
                   std::vector<double>& z) {
  const int n = static_cast<int>(f.size());
  const double h2 = h * h;
  int k = -1;
  for (int q = 0; q < n; ++q) {
    if (f[q] == kInf) continue;
    // Parabola q's intersection with the last kept one; pop while it hides them.
    while (k >= 0) {
      const int p = v[k];
      const double s = ((f[q] + h2 * q * q) - (f[p] + h2 * p * p)) / (2 * h2 * (q - p));
      if (s <= z[k]) {
        --k;
        continue;
      }
      z[k + 1] = s;
      break;
    }
    ++k;
    v[k] = q;
    if (k == 0) z[0] = -kInf;
    z[k + 1] = kInf;
  }
  if (k < 0) {
    std::fill(d.begin(), d.begin() + n, kInf);
  } else {
    int j = 0;
    for (int q = 0; q < n; ++q) {
      while (z[j + 1] < q) ++j;
      const double dq = h * (q - v[j]);
      d[q] = dq * dq + f[v[j]];
    }
  }
  std::copy(d.begin(), d.begin() + n, f.begin());
}

}  // namespace

namespace {

// The three passes over a grid stored as `Store` between them (each line in doubles).
template <class Store>
std::vector<Store> transformGrid(const std::vector<std::uint8_t>& mask,
                                 const std::array<std::int64_t, 3>& dims,
                                 const Eigen::Vector3d& spacing, int threads) {
  const std::int64_t nx = dims[0], ny = dims[1], nz = dims[2];
  std::vector<Store> g(mask.size());
  for (std::size_t i = 0; i < mask.size(); ++i) g[i] = mask[i] ? Store(0) : Store(kInf);
  const std::int64_t stride[3] = {1, nx, nx * ny};
  const std::int64_t length[3] = {nx, ny, nz};
  for (int axis = 0; axis < 3; ++axis) {
    // Lines along `axis`, indexed by the other two coordinates.
    const int a = (axis + 1) % 3, b = (axis + 2) % 3;
    const std::int64_t lines = length[a] * length[b];
    parallelFor(
        lines, threads,
        [&](std::int64_t begin, std::int64_t end) {
          const std::size_t n = static_cast<std::size_t>(length[axis]);
          std::vector<double> f(n), d(n), z(n + 1);
          std::vector<int> v(n);
          for (std::int64_t line = begin; line < end; ++line) {
            const std::int64_t ia = line % length[a], ib = line / length[a];
            const std::int64_t base = ia * stride[a] + ib * stride[b];
            for (std::size_t q = 0; q < n; ++q) f[q] = g[base + q * stride[axis]];
            transformLine(f, spacing[axis], d, v, z);
            for (std::size_t q = 0; q < n; ++q) g[base + q * stride[axis]] = Store(f[q]);
          }
        },
        16);
  }
  return g;
}

}  // namespace

std::vector<float> squaredDistanceToMask(const std::vector<std::uint8_t>& mask,
                                         const std::array<std::int64_t, 3>& dims,
                                         const Eigen::Vector3d& spacing, int threads) {
  const std::vector<double> g = transformGrid<double>(mask, dims, spacing, threads);
  return std::vector<float>(g.begin(), g.end());
}

std::vector<float> squaredDistanceToMaskLean(const std::vector<std::uint8_t>& mask,
                                             const std::array<std::int64_t, 3>& dims,
                                             const Eigen::Vector3d& spacing, int threads) {
  return transformGrid<float>(mask, dims, spacing, threads);
}

}  // namespace repose
