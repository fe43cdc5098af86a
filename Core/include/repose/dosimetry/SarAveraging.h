// Peak spatial-average SAR: the local SAR of a voxel model averaged over cubes of a given mass
// (10 g, 1 g) by the rules of IEC/IEEE 62704-1 for FDTD grids, as openEMS's sar_calculation reads
// them (its IEEE_62704 method, fixed upstream in 2025; Debian 12's build aborts on body models).
//
// 1. Centred cubes. Each tissue cell is the centre of an axis-aligned cube, grown until it holds
//    the mass (cells cut by the cube count in the fraction of their volume inside it, so the mass
//    is continuous in the cube's size and is met to a relative 1e-6). The cube is valid when at
//    most maxBackgroundFraction of its volume is background (cells without density, and all
//    beyond the grid: the air round the body), and each of its six faces touches tissue (its
//    outermost layer of cells holds a tissue cell: a cube is not padded by a face lying wholly in
//    air). A valid cube's mean, power over mass, is its centre's averaged SAR.
// 2. Covered cells. A tissue cell that is no valid centre but lies wholly inside valid cubes takes
//    the largest of their means.
// 3. Face cubes. Any other tissue cell (at thin or pointed parts of the surface) is placed at the
//    centre of one face of a cube, which extends from that cell's outer face into the body, in
//    each of the six directions, with no background limit. The smallest such cube is taken, and
//    of those within faceCubeVolumeSlack of its volume the largest mean.
// The peak spatial-average SAR is the largest averaged SAR of any tissue cell.
#pragma once

#include "repose/util/Progress.h"

#include <array>
#include <cstdint>
#include <vector>

namespace repose {

// A rectilinear grid of cells, x fastest: index = i + nx * (j + ny * k). edges[a] holds the
// nx+1 (ny+1, nz+1) cell boundaries along axis a, increasing, in metres.
struct SarCellGrid {
  std::array<int, 3> dims{0, 0, 0};
  std::array<std::vector<double>, 3> edges;
  std::int64_t cellCount() const { return std::int64_t(dims[0]) * dims[1] * dims[2]; }
};

struct SarAveragingOptions {
  double massKg = 0.010;
  double maxBackgroundFraction = 0.10;  // of a centred cube's volume (IEC/IEEE 62704-1: 10 %)
  double massTolerance = 1e-6;          // relative (IEC/IEEE 62704-1)
  double faceCubeVolumeSlack = 0.05;    // face cubes within 5 % of the smallest's volume compete
  int threads = 0;                      // 0: all cores
  ProgressFn progress;
};

// How a tissue cell got its averaged SAR.
enum class SarCubeKind : std::uint8_t {
  Background = 0,  // no density: averaged SAR 0
  Centred = 1,     // the centre of a valid cube
  Covered = 2,     // inside valid cubes: the largest of their means
  FaceCube = 3,    // at the centre of a face cube's face
  None = 4,        // the whole grid holds less than the mass: averaged SAR 0
};

struct SarAveraged {
  std::vector<double> sar;        // W/kg per cell, averaged
  std::vector<SarCubeKind> kind;  // per cell
  std::vector<double> cubeEdge;   // m: the edge of the cell's own cube (Centred, FaceCube)
  std::array<std::int64_t, 5> count{0, 0, 0, 0, 0};  // cells per SarCubeKind
  double peak = 0;                                   // W/kg, the largest averaged SAR
  std::int64_t peakCell = -1;                        // its cell (-1 without tissue)
};

// density: kg/m^3 per cell (0 = background); localSar: W/kg per cell. Throws repose::Error on
// arrays of the wrong size, edges that do not increase, or a negative density or SAR.
SarAveraged averageSarIec62704(const SarCellGrid& grid, const std::vector<double>& density,
                               const std::vector<double>& localSar,
                               const SarAveragingOptions& options = {});

}  // namespace repose
