// `repose warp --mpi`: the ranks of an MPI job share one output grid. Rank 0 reads the cage and
// computes the deformation, which every rank receives; each rank then rasterizes its share of the
// grid's slabs (slab s goes to rank s mod N, so the body's costly middle is spread evenly) and
// all ranks write them into one NIfTI file with MPI-IO collective writes, round by round. A
// .nii.gz is written as the serial writer's independent gzip pieces (repose/io/GzipPieces.h):
// the file is byte for byte the serial out-of-core one, whatever the number of ranks.
//
// Errors are agreed on: a step that fails on any rank fails on every rank (so none waits for
// ever in a collective), the failing rank's message is printed once, by rank 0, and rank 0's
// temporary output is removed.
#pragma once

#include "ArgParser.h"

#include "repose/io/NiftiIO.h"
#include "repose/raster/Rasterizer.h"
#include "repose/util/Progress.h"

#include <Eigen/Core>

#include <cstdint>
#include <functional>
#include <memory>
#include <string>

namespace repose::cli {

class WarpRanks {
 public:
  virtual ~WarpRanks() = default;
  virtual int rank() const = 0;
  virtual int size() const = 0;
  virtual std::int64_t slabs() const = 0;  // how many slabs writeLabels cut the grid into

  // Runs `step` on every rank. When it throws on some rank, every rank throws: rank 0 the first
  // failing rank's error (repose::Error, or Cancelled when it was interrupted), the others
  // QuietExit (ArgParser.h).
  virtual void together(const std::function<void()>& step) = 0;
  // Rank 0's matrix on every rank (the others' argument is replaced).
  virtual void broadcast(Eigen::MatrixX3d& matrix) = 0;
  // Rank 0's text on every rank.
  virtual std::string broadcast(const std::string& text) = 0;

  // Rasterizes every slab of `grid` with `slabs` (on this rank's share) and writes the NIfTI
  // `path` (.nii or .nii.gz; a path every rank can open: rank 0's temporary output) holding at
  // most `slabBytes` of output per rank at a time. Returns on rank 0 the counts of all ranks
  // (labelVoxels summed); `progress` is called on rank 0.
  virtual RasterReport writeLabels(LabelSlabRasterizer& slabs, const VolumeGeometry& grid,
                                   const NiftiLayout& input, const std::string& path,
                                   std::size_t slabBytes, const ProgressFn& progress) = 0;
};

// The ranks of the MPI job this process belongs to (one rank when it was not started by an MPI
// launcher). Throws repose::Error when `repose` was built without MPI. MPI is finalized when the
// object goes.
std::unique_ptr<WarpRanks> makeWarpRanks();

}  // namespace repose::cli
