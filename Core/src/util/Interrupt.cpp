#include "repose/util/Interrupt.h"

#include "repose/util/Error.h"

#include <atomic>

namespace repose {

namespace {
// Lock-free, so touching it from a signal handler is safe.
std::atomic<int> gSignal{0};
static_assert(std::atomic<int>::is_always_lock_free);
}  // namespace

void requestInterrupt(int signal) noexcept {
  int none = 0;
  gSignal.compare_exchange_strong(none, signal == 0 ? -1 : signal);
}

int interruptSignal() noexcept {
  return gSignal.load(std::memory_order_relaxed);
}

void throwIfInterrupted() {
  if (interruptSignal() != 0) throw Cancelled();
}

}  // namespace repose
