// Exact sums over axis-aligned boxes of a rectilinear cell grid, for SAR averaging: the mass,
// absorbed power and background volume inside any box with real-valued bounds, each cell counted
// in the fraction of its volume inside the box, and all beyond the grid counted as background
// (the air round a body model); and the number of tissue cells in a block of whole cells.
//
// Why exact: with a per-cell constant density, the mass below a point, M(x, y, z), is trilinear
// inside every cell, so a box's mass is the 8-corner difference of M with each corner
// interpolated from the node prefix sums: 4 nodes with weights per axis, 64 terms in all. The
// mass is then continuous in the box's size and a cube can be sized to any tolerance.
#pragma once

#include "repose/dosimetry/SarAveraging.h"

#include <array>
#include <cstdint>
#include <vector>

namespace repose::sar {

struct BoxSums {
  double mass = 0;        // kg
  double power = 0;       // W
  double background = 0;  // m^3 of cells without density, and of the box beyond the grid
};

class BoxIntegrals {
 public:
  // density kg/m^3 and localSar W/kg per cell (sizes checked by the caller).
  BoxIntegrals(const SarCellGrid& grid, const std::vector<double>& density,
               const std::vector<double>& localSar, int threads);

  const SarCellGrid& grid() const { return grid_; }
  double lower(int axis) const { return grid_.edges[axis].front(); }
  double upper(int axis) const { return grid_.edges[axis].back(); }
  double centre(int axis, int cell) const {
    return 0.5 * (grid_.edges[axis][cell] + grid_.edges[axis][cell + 1]);
  }

  // Sums over the box [lo, hi] (lo < hi on every axis; it may reach beyond the grid).
  BoxSums sums(const std::array<double, 3>& lo, const std::array<double, 3>& hi) const;

  // The cell holding x from above (x on an edge: the cell starting there), and from below (x on
  // an edge: the cell ending there); both clamped to the grid.
  int cellAbove(int axis, double x) const;
  int cellBelow(int axis, double x) const;

  // Tissue cells in the block of cells [first, last] (inclusive) per axis.
  std::int64_t tissueCells(const std::array<int, 3>& first, const std::array<int, 3>& last) const;

 private:
  std::int64_t node(int i, int j, int k) const {
    return i + std::int64_t(dims_[0] + 1) * (j + std::int64_t(dims_[1] + 1) * k);
  }

  const SarCellGrid& grid_;
  std::array<int, 3> dims_;
  // Per node: sums over the cells below it on all axes (`background` holding tissue volume).
  std::vector<BoxSums> prefix_;
  std::vector<std::int64_t> tissue_;  // per node: tissue cells below it
};

}  // namespace repose::sar
