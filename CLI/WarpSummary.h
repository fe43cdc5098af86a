// What `repose warp` prints (its per-label volumes, counts and memory, as text or --json), shared
// by the run in one process (CommandWarp.cpp) and the one over MPI ranks (WarpOverRanks.cpp).
#pragma once

#include "ArgParser.h"

#include "repose/io/SliceCache.h"
#include "repose/raster/Rasterizer.h"
#include "repose/volume/Volume.h"

#include <map>
#include <string>
#include <utility>

namespace repose::cli {

struct WarpSummary {
  std::string input, out;
  LabelTable labels;
  VolumeGeometry grid;
  bool outOfCore = false;
  double budget = 0, usedBefore = 0, inCoreNeed = 0;
  RasterReport report;
  int unreachable = 0;  // transfer-mesh vertices left at rest
  std::map<std::pair<int, int>, std::pair<double, double>> volumes;  // (layer, value) -> mm3
  double seconds = 0;
  int ranks = 1;
  std::int64_t slabs = 0;  // --mpi: the output's slabs, spread over the ranks
  // --mpi, on rank 0: setup (MPI, reading, the deformation and its broadcast, the slab
  // rasterizer), slabs (rasterized and written by all ranks), input_volumes (G counted).
  std::map<std::string, double> stageSeconds;
};

void printWarpSummary(const WarpSummary& summary, bool json);

// Voxels per non-zero label of a file read through a slice cache, as mm3.
std::map<int, double> streamedLabelVolumes(SliceCache& cache);

// `repose warp --mpi` (p parsed): every rank of the MPI job runs it.
int runWarpOverRanks(const ArgParser& p);

}  // namespace repose::cli
