// What the CLI's MPI front ends share (WarpRanksMpi.cpp, SlabRanksMpi.cpp): MPI started for the
// life of an object with a communicator of its own, waits that poll instead of spinning a core,
// and one rule for a step that fails on some rank (WarpRanks::together). Only the main thread
// calls MPI (MPI_THREAD_FUNNELED): the work's threads never do.
#pragma once

#define OMPI_SKIP_MPICXX 1
#define MPICH_SKIP_MPICXX 1
#include <mpi.h>

#include <cstdint>
#include <functional>
#include <string>

namespace repose::cli::mpi {

// Waits for `request`, polling with a short sleep (MPI's own wait spins a core at 100 %, taken
// from the ranks that work).
void await(MPI_Request& request, MPI_Status* status = MPI_STATUS_IGNORE);
std::string errorText(int code);

class Session {
 public:
  Session();
  ~Session();
  Session(const Session&) = delete;
  Session& operator=(const Session&) = delete;
  MPI_Comm comm() const { return comm_; }
  int rank() const { return rank_; }
  int size() const { return size_; }

  // Runs `step` on every rank. When it throws on some rank, every rank throws: rank 0 the first
  // failing rank's error (repose::Error naming the rank, Cancelled when it was interrupted,
  // UsageError), the others QuietExit (ArgParser.h).
  void together(const std::function<void()>& step);
  // Ends every rank as together() does for a failure of `kind` (1 error, 2 interrupted, 3 usage
  // error) with `message`, first seen on rank `first` (every rank calls it with the same values).
  [[noreturn]] void fail(int first, int kind, const std::string& message) const;
  // Rank `root`'s text on every rank.
  std::string broadcastFrom(int root, std::string text);

 private:
  MPI_Comm comm_ = MPI_COMM_NULL;
  int rank_ = 0, size_ = 1;
  bool owns_ = false;
};

// The kind of failure `together` and the slab pipeline agree on (0 none, 1 error, 2
// interrupted, 3 usage error) and its message, of the exception being handled.
int failureOf(std::string& message);

}  // namespace repose::cli::mpi
