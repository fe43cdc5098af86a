// parallelFor: the chunks cover [0, n) once each, in as many workers as asked (no more than
// n / minChunk), the first on the calling thread; an exception from any chunk, the caller's
// included, comes back after every worker has finished.
#include "repose/util/Parallel.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <mutex>
#include <set>
#include <stdexcept>
#include <string>
#include <thread>
#include <utility>
#include <vector>

using namespace repose;

namespace {

struct Chunk {
  std::int64_t begin, end;
  std::thread::id thread;
};

std::vector<Chunk> chunksOf(std::int64_t n, int threads, std::int64_t minChunk) {
  std::mutex m;
  std::vector<Chunk> chunks;
  parallelFor(
      n, threads,
      [&](std::int64_t b, std::int64_t e) {
        std::lock_guard<std::mutex> lock(m);
        chunks.push_back({b, e, std::this_thread::get_id()});
      },
      minChunk);
  std::sort(chunks.begin(), chunks.end(),
            [](const Chunk& a, const Chunk& b) { return a.begin < b.begin; });
  return chunks;
}

}  // namespace

TEST(Parallel, ChunksCoverTheRangeOnceAndTheFirstRunsOnTheCaller) {
  for (const std::int64_t n : {1, 63, 64, 129, 1000, 100000})
    for (const int threads : {1, 2, 3, 8})
      for (const std::int64_t minChunk : {1, 64, 4096}) {
        const auto chunks = chunksOf(n, threads, minChunk);
        const std::int64_t expected =
            std::max<std::int64_t>(1, std::min<std::int64_t>(threads, n / minChunk));
        ASSERT_EQ(std::int64_t(chunks.size()), expected)
            << "n " << n << " threads " << threads << " minChunk " << minChunk;
        std::int64_t at = 0;
        std::set<std::thread::id> ids;
        for (const Chunk& c : chunks) {
          EXPECT_EQ(c.begin, at);
          EXPECT_LT(c.begin, c.end);
          at = c.end;
          ids.insert(c.thread);
        }
        EXPECT_EQ(at, n);
        EXPECT_EQ(chunks.front().thread, std::this_thread::get_id());
        EXPECT_EQ(ids.size(), chunks.size()) << "each chunk on a thread of its own";
      }
  EXPECT_TRUE(chunksOf(0, 2, 1).empty());
}

TEST(Parallel, AnExceptionComesBackAfterEveryWorkerHasFinished) {
  for (const bool callerThrows : {true, false}) {
    std::atomic<int> finished{0};
    try {
      parallelFor(
          4, 4,
          [&](std::int64_t b, std::int64_t) {
            const bool onCaller = b == 0;
            if (onCaller == callerThrows) throw std::runtime_error("chunk " + std::to_string(b));
            // The others outlast the throw: were they not joined, this would run on after the
            // call returned and `finished` would be read too early.
            std::this_thread::sleep_for(std::chrono::milliseconds(50));
            ++finished;
          },
          1);
      FAIL() << "no exception";
    } catch (const std::runtime_error& e) {
      EXPECT_EQ(finished.load(), callerThrows ? 3 : 1);
      if (callerThrows) {
        EXPECT_STREQ(e.what(), "chunk 0");
      }
    }
  }
}
