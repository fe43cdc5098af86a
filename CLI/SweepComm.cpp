#include "SweepComm.h"

#include <cstdlib>

namespace repose::cli {
namespace {

class SerialSweepComm final : public SweepComm {
 public:
  int rank() const override { return 0; }
  int size() const override { return 1; }
  bool mpi() const override { return false; }
  void beginPhase(std::int64_t count) override { count_ = count, next_ = 0; }
  std::int64_t next() override { return next_ < count_ ? next_++ : -1; }
  void endPhase() override {}
  std::vector<std::string> allGather(const std::string& mine) override { return {mine}; }
  bool any(bool mine) override { return mine; }

 private:
  std::int64_t count_ = 0, next_ = 0;
};

}  // namespace

std::unique_ptr<SweepComm> makeSerialSweepComm() {
  return std::make_unique<SerialSweepComm>();
}

bool launchedByMpi() {
  // Open MPI's mpirun, and the PMI/PMIx launchers of other MPIs and of Slurm's srun.
  for (const char* name : {"OMPI_COMM_WORLD_SIZE", "PMIX_RANK", "PMI_RANK", "PMI_SIZE"})
    if (std::getenv(name)) return true;
  return false;
}

std::unique_ptr<SweepComm> makeSweepComm() {
#ifdef REPOSE_HAVE_MPI
  if (launchedByMpi()) return makeMpiSweepComm();
#endif
  return makeSerialSweepComm();
}

}  // namespace repose::cli
