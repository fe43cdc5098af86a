// `repose warp --mpi` in a build without MPI (CMake's FindMPI found none): a one-line refusal.
#include "WarpRanks.h"

#include "repose/util/Error.h"

#ifndef REPOSE_HAVE_MPI  // else CLI/mpi/WarpRanksMpi.cpp
namespace repose::cli {

std::unique_ptr<WarpRanks> makeWarpRanks() {
  throw Error("--mpi: this repose was built without MPI (install libopenmpi-dev and rebuild)");
}

}  // namespace repose::cli
#endif
