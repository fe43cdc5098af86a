// A program that runs the CLI's MPI slab pipeline (CLI/mpi/SlabRanksMpi.cpp) on made-up slabs,
// for PoseMpiCommandTest to start under mpirun: every slab's bytes arrive whole and in order on
// rank 0, two pipelines run one after the other, and a failure while making or using a slab ends
// every rank with one message from rank 0 and the failing rank's exit status.
//
//   ReposeSlabRanksProbe ok | make-fails K | use-fails K | make-cancels K
#include "SlabRanksCli.h"

#include "ArgParser.h"

#include "repose/util/Error.h"

#include <cstdint>
#include <iostream>
#include <string>
#include <vector>

namespace {

// Slab s's bytes: a size that varies (0 for every seventh slab, up to 3 MB) and a pattern that
// names the slab.
std::vector<std::uint8_t> slabBytes(std::int64_t s) {
  const std::size_t n = s % 7 == 0 ? 0 : std::size_t(1 + (s * 7919) % 3000000);
  std::vector<std::uint8_t> bytes(n);
  for (std::size_t i = 0; i < n; ++i) bytes[i] = std::uint8_t((std::size_t(s) * 31 + i) % 251);
  return bytes;
}

}  // namespace

int main(int argc, char** argv) {
  const std::string mode = argc > 1 ? argv[1] : "ok";
  const std::int64_t k = argc > 2 ? std::stoll(argv[2]) : -1;
  std::unique_ptr<repose::SlabRanks> ranks;
  try {
    ranks = repose::cli::makeSlabRanks();
    std::int64_t used = 0;
    for (const std::int64_t count : {std::int64_t(23), std::int64_t(5)}) {
      std::int64_t next = 0;
      ranks->pipeline(
          count,
          [&](std::int64_t s, std::vector<std::uint8_t>& bytes) {
            if (s == k && mode == "make-fails")
              throw repose::Error("slab " + std::to_string(s) + " cannot be made");
            if (s == k && mode == "make-cancels") throw repose::Cancelled();
            bytes = slabBytes(s);
          },
          [&](std::int64_t s, std::vector<std::uint8_t>& bytes) {
            if (s != next++) throw repose::Error("slab " + std::to_string(s) + " out of order");
            if (bytes != slabBytes(s))
              throw repose::Error("slab " + std::to_string(s) + " arrived changed");
            if (s == k && mode == "use-fails")
              throw repose::Error("slab " + std::to_string(s) + " cannot be used");
            ++used;
          });
    }
    if (ranks->root()) std::cout << "used " << used << " slabs over " << ranks->size() << "\n";
    return 0;
  } catch (const repose::cli::QuietExit& e) {
    return e.code;
  } catch (const repose::Cancelled&) {
    std::cerr << "probe: cancelled\n";
    return 130;
  } catch (const std::exception& e) {
    std::cerr << "probe: error: " << e.what() << "\n";
    return 1;
  }
}
