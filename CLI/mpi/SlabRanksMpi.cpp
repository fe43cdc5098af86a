// `repose pose --mpi`: a frame's slabs over the ranks of an MPI job (Core's SlabRanks). Ranks
// 1 .. N-1 make slabs in turn and send them to rank 0, which uses them in slab order.
//
// A slab goes as a header (status, size) and its bytes in pieces of at most 1 GiB (MPI counts
// are ints); a maker that fails sends its error as the status and text instead, then stops. A
// maker has at most two slabs on their way (the one rank 0 receives, the next it makes), so its
// memory is two slabs whatever the frame. When anything fails, rank 0 tells every maker to stop,
// takes what they still send (so no send waits for ever), and the ranks agree on the first
// failure as `together` does. Every maker ends its part with an END message; rank 0 returns from
// a pipeline only when each has.
#include "../SlabRanksCli.h"
#include "MpiSession.h"

#include "repose/util/Error.h"

#include <algorithm>
#include <array>
#include <chrono>
#include <exception>
#include <thread>

namespace repose::cli {
namespace {

using mpi::await;

constexpr int kTagSlab = 7711, kTagStop = 7712, kTagEnd = 7713;
constexpr std::int64_t kPiece = std::int64_t(1) << 30;

class MpiSlabRanks final : public SlabRanks {
 public:
  ~MpiSlabRanks() override {
    // Unwinding from an error the ranks did not agree on (one rank's own): the others would
    // wait for this one for ever, so the whole job stops.
    if (std::uncaught_exceptions() > 0 && !agreed_ && size() > 1) MPI_Abort(session_.comm(), 1);
  }

  int rank() const override { return session_.rank(); }
  int size() const override { return session_.size(); }

  void together(const std::function<void()>& step) override {
    agreeing([&] { session_.together(step); });
  }

  void broadcast(std::vector<std::uint8_t>& bytes) override {
    std::int64_t n = static_cast<std::int64_t>(bytes.size());
    MPI_Request r;
    MPI_Ibcast(&n, 1, MPI_INT64_T, 0, comm(), &r);
    await(r);
    bytes.resize(static_cast<std::size_t>(n));
    for (std::int64_t at = 0; at < n; at += kPiece) {
      MPI_Ibcast(bytes.data() + at, static_cast<int>(std::min(kPiece, n - at)), MPI_BYTE, 0, comm(),
                 &r);
      await(r);
    }
  }

  std::int64_t minimum(std::int64_t value) override {
    MPI_Request r;
    MPI_Iallreduce(MPI_IN_PLACE, &value, 1, MPI_INT64_T, MPI_MIN, comm(), &r);
    await(r);
    return value;
  }

  void pipeline(std::int64_t count, const Make& make, const Use& use) override {
    if (size() == 1) {
      together([&] {
        std::vector<std::uint8_t> bytes;
        for (std::int64_t s = 0; s < count; ++s) make(s, bytes), use(s, bytes);
      });
      return;
    }
    Failure failure = root() ? useInOrder(count, use) : makeMine(count, make);
    // Whether rank 0 told the makers to stop, so each takes its STOP before the next pipeline.
    int stopSent = root() ? failure.kind != 0 : 0;
    MPI_Request r;
    MPI_Ibcast(&stopSent, 1, MPI_INT, 0, comm(), &r);
    await(r);
    if (!root()) {
      if (!stopSent && stop_ != MPI_REQUEST_NULL) MPI_Cancel(&stop_);
      await(stop_);  // done at once when it was (a null request)
    }
    // Rank 0 knows the first failure (its own, or the maker's it received first).
    together([&] {
      if (root() && failure.kind) session_.fail(failure.rank, failure.kind, failure.message);
    });
  }

 private:
  struct Failure {
    int kind = 0;  // mpi::failureOf's
    int rank = 0;
    std::string message;
  };
  // A slab on its way to rank 0: its header, bytes (or error text) and sends.
  struct Outgoing {
    std::array<std::int64_t, 2> header{0, 0};  // failure kind, bytes
    std::vector<std::uint8_t> bytes;
    std::vector<MPI_Request> sends;
    void wait() {
      for (MPI_Request& r : sends) await(r);
      sends.clear();
    }
  };

  MPI_Comm comm() const { return session_.comm(); }

  void agreeing(const std::function<void()>& step) {
    try {
      step();
    } catch (...) {
      agreed_ = true;
      throw;
    }
  }

  void send(Outgoing& out) {
    MPI_Request r;
    MPI_Isend(out.header.data(), 2, MPI_INT64_T, 0, kTagSlab, comm(), &r);
    out.sends.push_back(r);
    const std::int64_t n = out.header[1];
    for (std::int64_t at = 0; at < n; at += kPiece) {
      MPI_Isend(out.bytes.data() + at, static_cast<int>(std::min(kPiece, n - at)), MPI_BYTE, 0,
                kTagSlab, comm(), &r);
      out.sends.push_back(r);
    }
  }

  // Rank 0: the header and bytes of `from`'s next slab.
  std::array<std::int64_t, 2> receive(int from, std::vector<std::uint8_t>& bytes) {
    std::array<std::int64_t, 2> header{};
    MPI_Request r;
    MPI_Irecv(header.data(), 2, MPI_INT64_T, from, kTagSlab, comm(), &r);
    await(r);
    // Grown without a copy of the last slab (it is overwritten): never two slabs at once.
    if (bytes.capacity() < std::size_t(header[1])) std::vector<std::uint8_t>().swap(bytes);
    bytes.resize(static_cast<std::size_t>(header[1]));
    for (std::int64_t at = 0; at < header[1]; at += kPiece) {
      MPI_Irecv(bytes.data() + at, static_cast<int>(std::min(kPiece, header[1] - at)), MPI_BYTE,
                from, kTagSlab, comm(), &r);
      await(r);
    }
    return header;
  }

  // A maker: its slabs, made and sent in order, until they are done, one fails or rank 0 says
  // stop; then END.
  Failure makeMine(std::int64_t count, const Make& make) {
    MPI_Irecv(&stopValue_, 1, MPI_INT, 0, kTagStop, comm(), &stop_);
    bool stopSeen = false;
    auto stopped = [&] {
      int done = 0;
      if (!stopSeen) MPI_Test(&stop_, &done, MPI_STATUS_IGNORE);  // stop_ is null once done
      return stopSeen = stopSeen || done != 0;
    };
    Failure failure;
    std::array<Outgoing, 2> outgoing;
    int which = 0;
    for (std::int64_t s = rank() - 1; s < count && !failure.kind; s += size() - 1) {
      Outgoing& out = outgoing[std::size_t(which)];
      which ^= 1;
      out.wait();
      if (stopped()) break;
      try {
        make(s, out.bytes);
        out.header = {0, static_cast<std::int64_t>(out.bytes.size())};
      } catch (...) {
        failure.kind = mpi::failureOf(failure.message);
        failure.rank = rank();
        out.bytes.assign(failure.message.begin(), failure.message.end());
        out.header = {failure.kind, static_cast<std::int64_t>(out.bytes.size())};
      }
      send(out);
    }
    for (Outgoing& out : outgoing) out.wait();
    int end = 0;
    MPI_Request r;
    MPI_Isend(&end, 1, MPI_INT, 0, kTagEnd, comm(), &r);
    await(r);
    return failure;
  }

  // Rank 0: every slab received from its maker and used, in order, until one fails; then STOP
  // to every maker and whatever they still send taken until each says END.
  Failure useInOrder(std::int64_t count, const Use& use) {
    Failure failure;
    std::vector<std::uint8_t> bytes;
    for (std::int64_t s = 0; s < count && !failure.kind; ++s) {
      const int from = makerOf(s);
      const std::array<std::int64_t, 2> header = receive(from, bytes);
      if (header[0] != 0) {
        failure = {int(header[0]), from, std::string(bytes.begin(), bytes.end())};
        break;
      }
      try {
        use(s, bytes);
      } catch (...) {
        failure.kind = mpi::failureOf(failure.message);
        failure.rank = 0;
      }
    }
    std::vector<MPI_Request> stops;
    int stop = 1;
    if (failure.kind)
      for (int r = 1; r < size(); ++r) {
        stops.emplace_back();
        MPI_Isend(&stop, 1, MPI_INT, r, kTagStop, comm(), &stops.back());
      }
    for (int ends = 0; ends < size() - 1;) {
      MPI_Status status;
      int waiting = 0;
      MPI_Iprobe(MPI_ANY_SOURCE, MPI_ANY_TAG, comm(), &waiting, &status);
      if (!waiting) {
        std::this_thread::sleep_for(std::chrono::microseconds(200));
        continue;
      }
      if (status.MPI_TAG == kTagEnd) {
        int end = 0;
        MPI_Request r;
        MPI_Irecv(&end, 1, MPI_INT, status.MPI_SOURCE, kTagEnd, comm(), &r);
        await(r);
        ++ends;
      } else {
        receive(status.MPI_SOURCE, bytes);  // a slab made before the maker saw STOP: dropped
      }
    }
    for (MPI_Request& r : stops) await(r);
    return failure;
  }

  mpi::Session session_;
  MPI_Request stop_ = MPI_REQUEST_NULL;  // a maker's receive of rank 0's STOP, into stopValue_
  int stopValue_ = 0;
  bool agreed_ = false;
};

}  // namespace

std::unique_ptr<SlabRanks> makeSlabRanks() {
  return std::make_unique<MpiSlabRanks>();
}

}  // namespace repose::cli
