// The process-wide stop request (util/Interrupt.h) in Core on its own: nothing is stopped before
// a signal arrives; afterwards every progress point and every commit of an output stops the run
// (repose::Cancelled), nothing is published, and the first signal is the one kept. Each test of
// this file runs in its own process (gtest_discover_tests), so the request set here stays here.
// The command line's handlers and exit status: Testing/Python/test_interrupt.py.
#include "TestPaths.h"

#include "repose/io/AtomicOutput.h"
#include "repose/util/Error.h"
#include "repose/util/Interrupt.h"
#include "repose/util/Progress.h"

#include <gtest/gtest.h>

#include <csignal>
#include <filesystem>
#include <fstream>
#include <memory>

using namespace repose;

TEST(Interrupt, ARequestStopsEveryProgressPointAndEveryCommit) {
  repose::test::ScratchDir dir("interrupt");
  const std::string before = dir.file("before.txt"), after = dir.file("after.txt");
  ASSERT_EQ(interruptSignal(), 0);
  EXPECT_NO_THROW(throwIfInterrupted());
  int calls = 0;
  const ProgressFn count = [&](double, const std::string&) { return ++calls, true; };
  EXPECT_NO_THROW(reportProgress(count, 0.5, "working"));
  EXPECT_EQ(calls, 1);
  {
    AtomicOutput out(before);
    std::ofstream(out.tempPath()) << "written before the signal";
    out.commit();
  }
  EXPECT_TRUE(std::filesystem::exists(before));

  // An output being written when the signal comes is never published.
  auto pending = std::make_unique<AtomicOutput>(after);
  std::ofstream(pending->tempPath()) << "written while the signal came";
  requestInterrupt(SIGTERM);
  requestInterrupt(SIGINT);  // the first signal is the one kept
  EXPECT_EQ(interruptSignal(), SIGTERM);
  EXPECT_THROW(throwIfInterrupted(), Cancelled);
  EXPECT_THROW(reportProgress(count, 0.6, "working"), Cancelled);
  EXPECT_EQ(calls, 1);  // stopped before the caller's function is asked
  EXPECT_THROW(pending->commit(), Cancelled);
  pending.reset();  // removes what it wrote
  EXPECT_FALSE(std::filesystem::exists(after));
  EXPECT_TRUE(std::filesystem::exists(before));  // what was published stays
  // Nothing left beside the outputs: the temporary folder went with the unpublished one.
  int entries = 0;
  for ([[maybe_unused]] const auto& e : std::filesystem::directory_iterator(dir.path())) ++entries;
  EXPECT_EQ(entries, 1);
}

// A request with signal number 0 still counts (it is kept as -1, never as "none").
TEST(Interrupt, ARequestWithoutASignalNumberStillStops) {
  requestInterrupt(0);
  EXPECT_NE(interruptSignal(), 0);
  EXPECT_THROW(throwIfInterrupted(), Cancelled);
}
