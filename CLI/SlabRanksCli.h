// `repose pose --mpi`: the ranks of an MPI job share each frame's slabs (Core's SlabRanks: the
// other ranks make the slabs, rank 0 runs the ordered steps and writes the files).
#pragma once

#include "repose/pose/SlabRanks.h"

#include <memory>

namespace repose::cli {

// The ranks of the MPI job this process belongs to (one rank when no MPI launcher started it).
// Throws repose::Error when `repose` was built without MPI. A rank that leaves on an error the
// ranks did not agree on (together, pipeline) ends the whole job, rather than leave the others
// waiting for it. MPI is finalized when the object goes.
std::unique_ptr<SlabRanks> makeSlabRanks();

}  // namespace repose::cli
