// `repose warp --mpi` and `repose pose --mpi` in a build without MPI (CMake's FindMPI found
// none): a one-line refusal.
#include "SlabRanksCli.h"
#include "WarpRanks.h"

#include "repose/util/Error.h"

#ifndef REPOSE_HAVE_MPI  // else CLI/mpi/WarpRanksMpi.cpp, SlabRanksMpi.cpp
namespace repose::cli {

namespace {
const char* const kNoMpi =
    "--mpi: this repose was built without MPI (install libopenmpi-dev and rebuild)";
}

std::unique_ptr<WarpRanks> makeWarpRanks() {
  throw Error(kNoMpi);
}

std::unique_ptr<SlabRanks> makeSlabRanks() {
  throw Error(kNoMpi);
}

}  // namespace repose::cli
#endif
