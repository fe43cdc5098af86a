// How `repose sweep` spreads its jobs: one process, or the ranks of an MPI job (when `repose` was
// built with MPI and started by mpirun). Jobs are handed out one at a time as ranks ask for them
// (dynamic load balancing: jobs differ in cost), so a rank that drew a long job does not hold up
// the others.
#pragma once

#include <cstdint>
#include <memory>
#include <string>
#include <vector>

namespace repose::cli {

class SweepComm {
 public:
  virtual ~SweepComm() = default;
  virtual int rank() const = 0;
  virtual int size() const = 0;
  virtual bool mpi() const = 0;

  // A phase hands out the indices [0, count) over all ranks, each once: next() gives this rank
  // its next one, or -1 when none is left. Every rank calls begin and end (end waits for all).
  virtual void beginPhase(std::int64_t count) = 0;
  virtual std::int64_t next() = 0;
  virtual void endPhase() = 0;

  // Every rank's text, in rank order, on every rank.
  virtual std::vector<std::string> allGather(const std::string& mine) = 0;
  // Whether any rank passed true (a collective: every rank calls it).
  virtual bool any(bool mine) = 0;
};

// MPI when built with it and started under mpirun (an MPI launcher's environment), else one
// process. MPI is finalized when the object goes.
std::unique_ptr<SweepComm> makeSweepComm();

// The serial one, and (in a build with MPI) the MPI one.
std::unique_ptr<SweepComm> makeSerialSweepComm();
std::unique_ptr<SweepComm> makeMpiSweepComm();
bool launchedByMpi();

}  // namespace repose::cli
