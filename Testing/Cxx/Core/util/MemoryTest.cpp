// Tests of repose/util/Memory.h: the figures the readers' default budget is made of.
#include "repose/util/Memory.h"

#include <gtest/gtest.h>

#include <cstring>
#include <memory>

TEST(Memory, FiguresAreThoseOfThisMachineAndProcess) {
  const double physical = repose::physicalMemoryBytes();
  EXPECT_GT(physical, 256e6);  // any machine that runs the suite
  EXPECT_DOUBLE_EQ(repose::memoryBudgetByDefault(), 0.5 * physical);
  const double resident = repose::residentBytes();
  EXPECT_GT(resident, 0);
  EXPECT_LE(resident, repose::peakResidentBytes());
  EXPECT_LT(resident, physical);
}

TEST(Memory, TouchedMemoryCountsAgainstWhatIsLeft) {
  const double budget = 4e9;
  const double before = repose::memoryLeftWithin(budget);
  EXPECT_LE(before, budget - repose::residentBytes() + 16e6);  // pages may come and go between
  constexpr std::size_t kBytes = 256u << 20;
  std::unique_ptr<char[]> block(new char[kBytes]);
  std::memset(block.get(), 1, kBytes);  // resident only once written
  const double after = repose::memoryLeftWithin(budget);
  EXPECT_LT(after, before - 0.9 * double(kBytes)) << "before " << before << ", after " << after;
  EXPECT_EQ(block[kBytes - 1], 1);
}

TEST(Memory, AUsedUpBudgetLeavesOneByteNeverNoLimit) {
  // 0 is ReadOptions' "no limit": a budget the process already exceeds must not become it.
  EXPECT_EQ(repose::memoryLeftWithin(1000), 1.0);
  // 0 asks for the default budget.
  EXPECT_NEAR(repose::memoryLeftWithin(0),
              repose::memoryBudgetByDefault() - repose::residentBytes(), 16e6);
}
