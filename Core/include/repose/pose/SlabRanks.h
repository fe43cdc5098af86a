// The processes that share the slabs of one frame made out of core (issue 56: `repose pose
// --mpi`). A frame's two passes over its slabs split in two kinds of work: making a slab's voxels
// (the rasterizer's scans, the costliest part, independent from slab to slab) and the steps that
// go in slab order (the rounding's candidates, the pockets' background trace, the report's
// counts, the files' gzip streams). Rank 0 runs the second for every slab, in order, with the
// same code as one process; the other ranks make the slabs and send them to it. So the files and
// the report are the one-process frame's, byte for byte, whatever the number of ranks.
//
// Core knows no MPI: the front end passes an implementation (the CLI's, over MPI) or none (one
// process: oneSlabRank()).
#pragma once

#include <cstdint>
#include <functional>
#include <memory>
#include <vector>

namespace repose {

class SlabRanks {
 public:
  using Make = std::function<void(std::int64_t slab, std::vector<std::uint8_t>& bytes)>;
  using Use = std::function<void(std::int64_t slab, std::vector<std::uint8_t>& bytes)>;

  virtual ~SlabRanks() = default;
  virtual int rank() const = 0;
  virtual int size() const = 0;
  bool root() const { return rank() == 0; }

  // Runs `step` on every rank. When it throws on some rank, it throws on every rank: on rank 0
  // the first failing rank's error (repose::Error naming the rank, or Cancelled), on the others
  // an exception of the front end's that ends the process quietly.
  virtual void together(const std::function<void()>& step) = 0;
  // Rank 0's bytes on every rank (the others' are replaced).
  virtual void broadcast(std::vector<std::uint8_t>& bytes) = 0;
  // The smallest of every rank's `value`, on every rank.
  virtual std::int64_t minimum(std::int64_t value) = 0;
  // For slabs 0 .. count-1: make(s, bytes) on the rank that makes slab s (makerOf), then use(s,
  // bytes) on rank 0, slab after slab in order. Fails as together() does when make or use throws
  // anywhere; the others' slabs are then dropped.
  virtual void pipeline(std::int64_t count, const Make& make, const Use& use) = 0;
  // The rank that makes slab s: rank 0 alone, else ranks 1 .. size-1 in turn (rank 0 has the
  // ordered steps of every slab to run).
  int makerOf(std::int64_t slab) const {
    return size() == 1 ? 0 : 1 + int(slab % std::int64_t(size() - 1));
  }
};

// One process: every step runs here, in order.
std::unique_ptr<SlabRanks> oneSlabRank();

}  // namespace repose
