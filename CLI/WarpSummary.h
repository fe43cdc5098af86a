// What `repose warp` prints (its per-label volumes, counts and memory, as text or --json), shared
// by the run in one process (CommandWarp.cpp) and the one over MPI ranks (WarpOverRanks.cpp).
#pragma once

#include "ArgParser.h"

#include "repose/io/SliceCache.h"
#include "repose/mesh/RigiditySolver.h"
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
  // The mesh's Green coordinates: read from their file, or computed (and why), and the seconds
  // from reading the mesh to the deformed vertices.
  bool coordinatesRead = false;
  std::string coordinatesNote;
  double deformationSeconds = 0;
};

// --coordinates, else the file beside --mesh (tm.vtu -> tm.green), which `repose mesh` and scene
// folders write.
std::string warpCoordinatesFile(const ArgParser& p);
// The deformation's coordinate source into the summary; a file that was there but not used (for
// another mesh or cage, damaged) is said on stderr.
void noteWarpCoordinates(const CageDeformation& deformation, const std::string& coordinatesFile,
                         WarpSummary& summary);

void printWarpSummary(const WarpSummary& summary, bool json);

// Voxels per non-zero label of a file read through a slice cache, as mm3.
std::map<int, double> streamedLabelVolumes(SliceCache& cache);

// `repose warp --mpi` (p parsed): every rank of the MPI job runs it.
int runWarpOverRanks(const ArgParser& p);

}  // namespace repose::cli
