// parallelFor: split [0, n) into contiguous chunks run on std::threads. Core's only threading
// primitive, so thread counts are chosen in one place (0 = all cores).
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
  std::vector<std::thread> pool;
  for (std::int64_t w = 0; w < workers; ++w) {
    const std::int64_t begin = n * w / workers, end = n * (w + 1) / workers;
    pool.emplace_back([&, begin, end] {
      try {
        body(begin, end);
      } catch (...) {
        std::lock_guard<std::mutex> lock(errorMutex);
        if (!error) error = std::current_exception();
      }
    });
  }
  for (auto& t : pool) t.join();
  if (error) std::rethrow_exception(error);
}

}  // namespace repose
