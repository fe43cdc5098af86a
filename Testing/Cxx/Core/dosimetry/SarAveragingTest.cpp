// Peak spatial-average SAR (IEC/IEEE 62704-1 cube rules): known answers on homogeneous blocks,
// and every cell of a random heterogeneous body on an irregular grid against a plain reference
// written here, cell overlap by cell overlap, with bisection for the cube sizes.
#include "repose/dosimetry/SarAveraging.h"
#include "repose/util/Error.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <optional>
#include <random>

using namespace repose;

namespace {

SarCellGrid uniformGrid(std::array<int, 3> dims, double cell) {
  SarCellGrid g;
  g.dims = dims;
  for (int a = 0; a < 3; ++a) {
    for (int c = 0; c <= dims[a]; ++c) g.edges[a].push_back(c * cell);
  }
  return g;
}

std::int64_t at(const SarCellGrid& g, int i, int j, int k) {
  return i + std::int64_t(g.dims[0]) * (j + std::int64_t(g.dims[1]) * k);
}

std::array<int, 3> cellIndex(const SarCellGrid& g, std::int64_t c) {
  return {int(c % g.dims[0]), int(c / g.dims[0] % g.dims[1]), int(c / g.dims[0] / g.dims[1])};
}

// ---- The reference: the rules written out plainly, O(cells) per box. ----
struct Ref {
  const SarCellGrid& g;
  const std::vector<double>& rho;
  const std::vector<double>& sar;
  double target = 0.010;

  double overlap(int a, int c, double lo, double hi) const {
    return std::max(0.0, std::min(hi, g.edges[a][c + 1]) - std::max(lo, g.edges[a][c]));
  }
  // mass, power, air volume in [lo, hi]
  std::array<double, 3> box(const std::array<double, 3>& lo,
                            const std::array<double, 3>& hi) const {
    std::array<double, 3> s{0, 0, 0};
    for (int k = 0; k < g.dims[2]; ++k)
      for (int j = 0; j < g.dims[1]; ++j)
        for (int i = 0; i < g.dims[0]; ++i) {
          const double v = overlap(0, i, lo[0], hi[0]) * overlap(1, j, lo[1], hi[1]) *
                           overlap(2, k, lo[2], hi[2]);
          if (v == 0) continue;
          const std::int64_t c = at(g, i, j, k);
          s[0] += rho[c] * v;
          s[1] += rho[c] * v * sar[c];
          if (rho[c] > 0) s[2] += v;
        }
    // Air: the box less its tissue, beyond the grid too.
    s[2] = (hi[0] - lo[0]) * (hi[1] - lo[1]) * (hi[2] - lo[2]) - s[2];
    return s;
  }
  // Smallest size in (0, sMax] whose box holds the target (bisection), or nullopt.
  template <class Place>
  std::optional<double> size(double sMax, const Place& place) const {
    std::array<double, 3> lo, hi;
    place(sMax, lo, hi);
    if (box(lo, hi)[0] < target) return std::nullopt;
    double a = 0, b = sMax;
    for (int it = 0; it < 60; ++it) {
      const double m = 0.5 * (a + b);
      place(m, lo, hi);
      (box(lo, hi)[0] < target ? a : b) = m;
    }
    return b;
  }
  double centre(int a, int c) const { return 0.5 * (g.edges[a][c] + g.edges[a][c + 1]); }
  double extent() const {
    double e = 0;
    for (int a = 0; a < 3; ++a) e = std::max(e, g.edges[a].back() - g.edges[a].front());
    return e;
  }
  // A face touches tissue: some tissue cell overlapping the cube lies in its outermost layer.
  bool facesTouch(const std::array<double, 3>& lo, const std::array<double, 3>& hi) const {
    for (int a = 0; a < 3; ++a)
      for (int side = 0; side < 2; ++side) {
        bool touch = false;
        for (int k = 0; k < g.dims[2]; ++k)
          for (int j = 0; j < g.dims[1]; ++j)
            for (int i = 0; i < g.dims[0]; ++i) {
              const std::array<int, 3> c{i, j, k};
              bool in = true;
              for (int b = 0; b < 3; ++b) in = in && overlap(b, c[b], lo[b], hi[b]) > 0;
              if (!in || rho[at(g, i, j, k)] == 0) continue;
              const double x = side == 0 ? lo[a] : hi[a];
              if (g.edges[a][c[a]] <= x && x <= g.edges[a][c[a] + 1] &&
                  overlap(a, c[a], lo[a], hi[a]) > 0)
                touch = true;
            }
        if (!touch) return false;
      }
    return true;
  }
};

// The reference's whole result: kind and averaged SAR per cell.
std::pair<std::vector<SarCubeKind>, std::vector<double>> reference(const Ref& r) {
  const SarCellGrid& g = r.g;
  const std::int64_t n = g.cellCount();
  std::vector<SarCubeKind> kind(n, SarCubeKind::Background);
  std::vector<double> avg(n, 0.0), half(n, 0.0);
  for (std::int64_t c = 0; c < n; ++c) {
    const std::array<int, 3> v = cellIndex(g, c);
    if (r.rho[c] == 0) continue;
    kind[c] = SarCubeKind::None;
    const std::array<double, 3> ctr{r.centre(0, v[0]), r.centre(1, v[1]), r.centre(2, v[2])};
    const double hMax = r.extent();  // a cube of this half-edge holds the whole grid
    auto place = [&](double h, std::array<double, 3>& lo, std::array<double, 3>& hi) {
      for (int a = 0; a < 3; ++a) lo[a] = ctr[a] - h, hi[a] = ctr[a] + h;
    };
    const auto h = r.size(hMax, place);
    if (!h) continue;
    std::array<double, 3> lo, hi;
    place(*h, lo, hi);
    const auto s = r.box(lo, hi);
    if (s[2] > 0.1 * std::pow(2 * *h, 3) || !r.facesTouch(lo, hi)) continue;
    kind[c] = SarCubeKind::Centred;
    avg[c] = s[1] / s[0];
    half[c] = *h;
  }
  for (std::int64_t c = 0; c < n; ++c) {
    if (kind[c] != SarCubeKind::None) continue;
    const std::array<int, 3> v = cellIndex(g, c);
    double best = -1;
    for (std::int64_t u = 0; u < n; ++u) {
      if (kind[u] != SarCubeKind::Centred) continue;
      const std::array<int, 3> cu{int(u % g.dims[0]), int(u / g.dims[0] % g.dims[1]),
                                  int(u / g.dims[0] / g.dims[1])};
      bool inside = true;
      for (int a = 0; a < 3; ++a) {
        const double eps = 1e-9 * (g.edges[a][v[a] + 1] - g.edges[a][v[a]]);
        inside = inside && r.centre(a, cu[a]) - half[u] <= g.edges[a][v[a]] + eps &&
                 g.edges[a][v[a] + 1] <= r.centre(a, cu[a]) + half[u] + eps;
      }
      if (inside) best = std::max(best, avg[u]);
    }
    if (best >= 0) {
      kind[c] = SarCubeKind::Covered;
      avg[c] = best;
    }
  }
  for (std::int64_t c = 0; c < n; ++c) {
    if (kind[c] != SarCubeKind::None) continue;
    const std::array<int, 3> v = cellIndex(g, c);
    std::vector<std::pair<double, double>> cubes;  // (volume, mean)
    for (int axis = 0; axis < 3; ++axis)
      for (int side : {-1, 1}) {
        const double face = side > 0 ? g.edges[axis][v[axis]] : g.edges[axis][v[axis] + 1];
        const double lMax = 2 * r.extent();
        auto place = [&](double l, std::array<double, 3>& lo, std::array<double, 3>& hi) {
          for (int a = 0; a < 3; ++a) {
            lo[a] = r.centre(a, v[a]) - l / 2, hi[a] = r.centre(a, v[a]) + l / 2;
          }
          lo[axis] = side > 0 ? face : face - l;
          hi[axis] = side > 0 ? face + l : face;
        };
        const auto l = r.size(lMax, place);
        if (!l) continue;
        std::array<double, 3> lo, hi;
        place(*l, lo, hi);
        const auto s = r.box(lo, hi);
        cubes.push_back({std::pow(*l, 3), s[1] / s[0]});
      }
    if (cubes.empty()) continue;
    double vMin = 1e300, best = 0;
    for (const auto& q : cubes) vMin = std::min(vMin, q.first);
    for (const auto& q : cubes)
      if (q.first <= 1.05 * vMin) best = std::max(best, q.second);
    kind[c] = SarCubeKind::FaceCube;
    avg[c] = best;
  }
  return {kind, avg};
}

}  // namespace

TEST(SarAveraging, UniformSarInAHomogeneousBlockIsUniformAndTheCubesHoldTenGrams) {
  const SarCellGrid g = uniformGrid({16, 16, 16}, 0.004);  // 4 mm cells
  std::vector<double> rho(g.cellCount(), 0.0), sar(g.cellCount(), 0.0);
  for (int k = 3; k < 13; ++k)
    for (int j = 3; j < 13; ++j)
      for (int i = 3; i < 13; ++i) rho[at(g, i, j, k)] = 1050, sar[at(g, i, j, k)] = 2.5;
  const SarAveraged r = averageSarIec62704(g, rho, sar);
  EXPECT_EQ(r.count[0], g.cellCount() - 1000);
  EXPECT_EQ(r.count[1] + r.count[2] + r.count[3], 1000);
  EXPECT_EQ(r.count[4], 0);
  EXPECT_GT(r.count[1], 0);
  EXPECT_GT(r.count[3], 0);  // the block's corners and edges need face cubes
  const double edge = std::cbrt(0.010 / 1050);
  for (std::int64_t c = 0; c < g.cellCount(); ++c) {
    if (rho[c] == 0) {
      EXPECT_EQ(r.sar[c], 0.0);
      continue;
    }
    EXPECT_NEAR(r.sar[c], 2.5, 1e-12);
    const int i = int(c % 16), j = int(c / 16 % 16), k = int(c / 256);
    if (std::min({i, j, k}) >= 6 && std::max({i, j, k}) <= 9) {
      // Cubes wholly in tissue: 10 g of 1050 kg/m3.
      EXPECT_EQ(r.kind[c], SarCubeKind::Centred);
      EXPECT_NEAR(r.cubeEdge[c] / edge, 1.0, 1e-6) << c;
    }
  }
  EXPECT_NEAR(r.peak, 2.5, 1e-12);
}

TEST(SarAveraging, ACentredCubeAveragesALinearFieldToItsCentreValue) {
  // Symmetric cubes over a cell-constant linear field give the centre cell's value exactly.
  const SarCellGrid g = uniformGrid({20, 20, 20}, 0.003);
  std::vector<double> rho(g.cellCount(), 1000.0), sar(g.cellCount());
  for (int k = 0; k < 20; ++k)
    for (int j = 0; j < 20; ++j)
      for (int i = 0; i < 20; ++i) sar[at(g, i, j, k)] = 1.0 + 0.10 * i - 0.03 * j + 0.07 * k;
  const SarAveraged r = averageSarIec62704(g, rho, sar);
  int centred = 0;
  for (std::int64_t c = 0; c < g.cellCount(); ++c) {
    if (r.kind[c] != SarCubeKind::Centred) continue;
    ++centred;
    EXPECT_NEAR(r.sar[c], sar[c], 1e-9 * sar[c]) << c;
  }
  // A 21.5 mm cube needs 3.6 cells either side: the grid's 4-cell rim has no centred cubes,
  // and there is no background, so its cells are covered or get face cubes.
  EXPECT_EQ(centred, 12 * 12 * 12);
  EXPECT_EQ(r.count[0], 0);
  EXPECT_EQ(r.count[4], 0);
}

TEST(SarAveraging, ASurfaceCellTakesTheCubeBehindItsFaceOnAFlatBody) {
  // Tissue below z = 30 mm in a 60 mm box of 5 mm cells; SAR falls with depth. The top layer's
  // centred cubes are half air, so the top cells are neither centres nor covered: each is the
  // centre of the face of a 21.5 mm cube reaching down into the body, the smallest of its six.
  const SarCellGrid g = uniformGrid({12, 12, 12}, 0.005);
  std::vector<double> rho(g.cellCount(), 0.0), sar(g.cellCount(), 0.0);
  auto sarAtLayer = [](int k) { return 10.0 - 1.5 * (5 - k); };  // k = 5 is the top layer
  for (int k = 0; k < 6; ++k)
    for (int j = 0; j < 12; ++j)
      for (int i = 0; i < 12; ++i) rho[at(g, i, j, k)] = 1000, sar[at(g, i, j, k)] = sarAtLayer(k);
  const SarAveraged r = averageSarIec62704(g, rho, sar);
  const double edge = std::cbrt(0.010 / 1000);  // 21.54 mm: 4.31 layers
  // The face cube of a top cell: layers 5, 4, 3, 2 whole and 0.31 of layer 1.
  const double part = edge / 0.005 - 4;
  const double expected =
      (sarAtLayer(5) + sarAtLayer(4) + sarAtLayer(3) + sarAtLayer(2) + part * sarAtLayer(1)) /
      (4 + part);
  const std::int64_t top = at(g, 6, 6, 5);
  EXPECT_EQ(r.kind[top], SarCubeKind::FaceCube);
  EXPECT_NEAR(r.sar[top], expected, 1e-6 * expected);
  EXPECT_NEAR(r.cubeEdge[top] / edge, 1.0, 1e-6);
  // The layer below is inside the valid cubes of the layers under it, and takes their largest.
  EXPECT_EQ(r.kind[at(g, 6, 6, 4)], SarCubeKind::Covered);
  EXPECT_EQ(r.kind[at(g, 6, 6, 2)], SarCubeKind::Centred);
  // Every top cell away from the block's sides alike; at the sides, where the block's corner
  // is exposed, the face cubes reach less deep and their means are larger: the peak is there.
  for (int j = 3; j < 9; ++j)
    for (int i = 3; i < 9; ++i) EXPECT_NEAR(r.sar[at(g, i, j, 5)], expected, 1e-6 * expected);
  EXPECT_GT(r.peak, expected);
  const std::int64_t p = r.peakCell;
  EXPECT_EQ(p / 144, 5);
  EXPECT_TRUE(p % 12 == 0 || p % 12 == 11 || p / 12 % 12 == 0 || p / 12 % 12 == 11);
  EXPECT_EQ(r.count[4], 0);
}

TEST(SarAveraging, EveryCellOfARandomBodyOnAnIrregularGridMatchesThePlainReference) {
  std::mt19937 rng(62704);
  std::uniform_real_distribution<double> width(0.003, 0.006), u01(0, 1);
  SarCellGrid g;
  g.dims = {17, 15, 14};
  for (int a = 0; a < 3; ++a) {
    g.edges[a].push_back(-0.02);
    for (int c = 0; c < g.dims[a]; ++c) g.edges[a].push_back(g.edges[a].back() + width(rng));
  }
  std::vector<double> rho(g.cellCount(), 0.0), sar(g.cellCount(), 0.0);
  int tissue = 0;
  for (int k = 0; k < g.dims[2]; ++k)
    for (int j = 0; j < g.dims[1]; ++j)
      for (int i = 0; i < g.dims[0]; ++i) {
        // An ellipsoid with an air cavity and a few air cells scattered in it.
        const double x = (i - 8.0) / 7.0, y = (j - 7.0) / 6.2, z = (k - 6.5) / 5.6;
        const double r2 = x * x + y * y + z * z;
        const bool cavity = (i - 9) * (i - 9) + (j - 6) * (j - 6) + (k - 7) * (k - 7) <= 2;
        if (r2 > 1 || cavity || u01(rng) < 0.05) continue;
        rho[at(g, i, j, k)] = 900 + 1000 * u01(rng);
        sar[at(g, i, j, k)] = 0.2 + 3.0 * u01(rng);
        ++tissue;
      }
  const SarAveraged got = averageSarIec62704(g, rho, sar);
  const Ref ref{g, rho, sar};
  const auto [kind, avg] = reference(ref);
  std::array<int, 5> count{0, 0, 0, 0, 0};
  for (std::int64_t c = 0; c < g.cellCount(); ++c) {
    ++count[int(kind[c])];
    ASSERT_EQ(int(got.kind[c]), int(kind[c])) << "cell " << c;
    EXPECT_NEAR(got.sar[c], avg[c], 1e-6 * std::max(avg[c], 1e-3)) << "cell " << c;
  }
  // The body exercises every rule.
  EXPECT_GT(count[1], 20);
  EXPECT_GT(count[2], 5);
  EXPECT_GT(count[3], 5);
  EXPECT_EQ(got.count[1] + got.count[2] + got.count[3] + got.count[4], tissue);
  const double peak = *std::max_element(avg.begin(), avg.end());
  EXPECT_NEAR(got.peak, peak, 1e-9 * peak);
}

TEST(SarAveraging, TooLittleMassForACubeLeavesCellsWithoutOne) {
  const SarCellGrid g = uniformGrid({4, 4, 4}, 0.002);  // 8 mm box: 0.5 g of water at most
  std::vector<double> rho(g.cellCount(), 1000.0), sar(g.cellCount(), 1.0);
  const SarAveraged r = averageSarIec62704(g, rho, sar);
  EXPECT_EQ(r.count[4], g.cellCount());
  EXPECT_EQ(r.peak, 0.0);
  SarAveragingOptions gram;
  gram.massKg = 0.0001;  // 0.1 g fits
  EXPECT_EQ(averageSarIec62704(g, rho, sar, gram).count[4], 0);
}

TEST(SarAveraging, BadInputIsRefusedInOneLine) {
  SarCellGrid g = uniformGrid({3, 3, 3}, 0.01);
  std::vector<double> rho(27, 1000.0), sar(27, 1.0);
  EXPECT_THROW(averageSarIec62704(g, std::vector<double>(26, 1.0), sar), Error);
  std::vector<double> negative = sar;
  negative[5] = -1;
  EXPECT_THROW(averageSarIec62704(g, rho, negative), Error);
  g.edges[1][2] = g.edges[1][1];
  try {
    averageSarIec62704(g, rho, sar);
    FAIL() << "flat cell accepted";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("do not increase"), std::string::npos);
    EXPECT_EQ(std::string(e.what()).find('\n'), std::string::npos);
  }
}

TEST(SarAveraging, ProgressCanCancel) {
  const SarCellGrid g = uniformGrid({10, 10, 10}, 0.004);
  std::vector<double> rho(1000, 1000.0), sar(1000, 1.0);
  SarAveragingOptions o;
  int calls = 0;
  o.progress = [&](double, const std::string&) { return ++calls < 2; };
  EXPECT_THROW(averageSarIec62704(g, rho, sar, o), Cancelled);
}
