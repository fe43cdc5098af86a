// parallelFor: split [0, n) into contiguous chunks, the first run by the caller and the others on
// std::threads of their own. Core's only threading primitive, so thread counts are chosen in one
// place (0 = all cores).
#pragma once

#include <algorithm>
#include <cstdint>
#include <exception>
#include <mutex>
#include <thread>
#include <vector>

namespace repose {

inline int resolveThreads(int threads) {
  if (threads > 0) return threads;
  return std::max(1u, std::thread::hardware_concurrency());
}

// Calls body(begin, end) on disjoint ranges covering [0, n); rethrows the first exception.
template <class Body>
void parallelFor(std::int64_t n, int threads, Body&& body, std::int64_t minChunk = 64) {
  const std::int64_t workers =
      std::max<std::int64_t>(1, std::min<std::int64_t>(resolveThreads(threads), n / minChunk));
  if (workers <= 1) {
    if (n > 0) body(std::int64_t(0), n);
    return;
  }
  std::exception_ptr error;
  std::mutex errorMutex;
  auto run = [&](std::int64_t w) {
    try {
      body(n * w / workers, n * (w + 1) / workers);
    } catch (...) {
      std::lock_guard<std::mutex> lock(errorMutex);
      if (!error) error = std::current_exception();
    }
  };
  // The caller runs the first chunk itself: a live slice calls this twice in a few milliseconds,
  // and each thread started is tens of microseconds of it.
  std::vector<std::thread> pool;
  pool.reserve(static_cast<std::size_t>(workers - 1));
  for (std::int64_t w = 1; w < workers; ++w) pool.emplace_back(run, w);
  run(0);
  for (auto& t : pool) t.join();
  if (error) std::rethrow_exception(error);
}

}  // namespace repose
