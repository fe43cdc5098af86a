// The sweep's jobs over MPI ranks. Rank 0 works like the others; during a phase a coordinator
// thread on rank 0 answers the other ranks' requests for their next index from the same counter
// rank 0's own jobs draw from. Only that thread calls MPI on rank 0 while a phase runs, and only
// the main thread between phases (MPI_THREAD_SERIALIZED). It polls with a short sleep rather than
// blocking in MPI_Recv, which spins a core at 100 % in Open MPI and would slow rank 0's jobs.
// Built only where CMake's FindMPI finds MPI (CLI/CMakeLists.txt).
#include "../SweepComm.h"

#include "repose/util/Error.h"

// The C API only: without these, Open MPI's mpi.h pulls in its deprecated C++ bindings, which
// live in another library (libmpi_cxx).
#define OMPI_SKIP_MPICXX 1
#define MPICH_SKIP_MPICXX 1
#include <mpi.h>

#include <atomic>
#include <chrono>
#include <exception>
#include <thread>

namespace repose::cli {
namespace {

constexpr int kTagAsk = 7701, kTagGive = 7702;

class MpiSweepComm final : public SweepComm {
 public:
  MpiSweepComm() {
    int initialized = 0;
    MPI_Initialized(&initialized);
    if (!initialized) {
      int provided = MPI_THREAD_SINGLE;
      MPI_Init_thread(nullptr, nullptr, MPI_THREAD_SERIALIZED, &provided);
      owns_ = true;
      if (provided < MPI_THREAD_SERIALIZED) {
        MPI_Finalize();
        throw Error(
            "MPI: the library does not give MPI_THREAD_SERIALIZED, which the sweep's "
            "coordinator thread needs");
      }
    }
    MPI_Comm_dup(MPI_COMM_WORLD, &comm_);
    MPI_Comm_rank(comm_, &rank_);
    MPI_Comm_size(comm_, &size_);
  }

  ~MpiSweepComm() override {
    // Unwinding from an error outside a job (those are caught per job): the other ranks would
    // wait for this one in a collective for ever, so the whole run stops.
    if (std::uncaught_exceptions() > 0 && size_ > 1) MPI_Abort(comm_, 1);
    if (coordinator_.joinable()) coordinator_.join();
    MPI_Comm_free(&comm_);
    if (owns_) MPI_Finalize();
  }

  int rank() const override { return rank_; }
  int size() const override { return size_; }
  bool mpi() const override { return true; }

  void beginPhase(std::int64_t count) override {
    count_ = count;
    next_ = 0;
    MPI_Barrier(comm_);
    if (rank_ == 0 && size_ > 1) coordinator_ = std::thread([this] { coordinate(); });
  }

  std::int64_t next() override {
    if (rank_ == 0) {
      const std::int64_t i = next_.fetch_add(1);
      return i < count_ ? i : -1;
    }
    std::int64_t i = -1;
    MPI_Send(nullptr, 0, MPI_BYTE, 0, kTagAsk, comm_);
    MPI_Recv(&i, 1, MPI_INT64_T, 0, kTagGive, comm_, MPI_STATUS_IGNORE);
    return i;
  }

  void endPhase() override {
    if (coordinator_.joinable()) coordinator_.join();
    MPI_Barrier(comm_);
  }

  std::vector<std::string> allGather(const std::string& mine) override {
    const int length = static_cast<int>(mine.size());
    std::vector<int> lengths(static_cast<std::size_t>(size_)), offsets(lengths.size());
    MPI_Allgather(&length, 1, MPI_INT, lengths.data(), 1, MPI_INT, comm_);
    int total = 0;
    for (int r = 0; r < size_; ++r)
      offsets[std::size_t(r)] = total, total += lengths[std::size_t(r)];
    std::string all(std::size_t(total), '\0');
    MPI_Allgatherv(mine.data(), length, MPI_CHAR, all.data(), lengths.data(), offsets.data(),
                   MPI_CHAR, comm_);
    std::vector<std::string> out;
    for (int r = 0; r < size_; ++r)
      out.push_back(
          all.substr(std::size_t(offsets[std::size_t(r)]), std::size_t(lengths[std::size_t(r)])));
    return out;
  }

  bool any(bool mine) override {
    int in = mine ? 1 : 0, out = 0;
    MPI_Allreduce(&in, &out, 1, MPI_INT, MPI_MAX, comm_);
    return out != 0;
  }

 private:
  // Rank 0, during a phase: one index per request until every other rank has been told -1.
  void coordinate() {
    int waiting = size_ - 1;
    while (waiting > 0) {
      MPI_Request request;
      MPI_Status status;
      MPI_Irecv(nullptr, 0, MPI_BYTE, MPI_ANY_SOURCE, kTagAsk, comm_, &request);
      for (int done = 0;;) {
        MPI_Test(&request, &done, &status);
        if (done) break;
        std::this_thread::sleep_for(std::chrono::microseconds(500));
      }
      std::int64_t i = next_.fetch_add(1);
      if (i >= count_) {
        i = -1;
        --waiting;
      }
      MPI_Send(&i, 1, MPI_INT64_T, status.MPI_SOURCE, kTagGive, comm_);
    }
  }

  MPI_Comm comm_ = MPI_COMM_NULL;
  int rank_ = 0, size_ = 1;
  bool owns_ = false;
  std::int64_t count_ = 0;
  std::atomic<std::int64_t> next_{0};
  std::thread coordinator_;
};

}  // namespace

std::unique_ptr<SweepComm> makeMpiSweepComm() {
  return std::make_unique<MpiSweepComm>();
}

}  // namespace repose::cli
