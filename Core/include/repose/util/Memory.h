// The process's memory as the readers' budgets see it (Linux /proc and sysconf; 0 when unknown).
// The command line takes its budget from --memory; the workbench and Python, which have no such
// option by default, read within memoryBudgetByDefault() less what the process already holds, so
// a header that claims tens of gigabytes is refused with the numbers instead of attempted.
#pragma once

#include <string>

namespace repose {

double physicalMemoryBytes();
// The resident set now (VmRSS), once the allocator has given back the heap the process freed
// (glibc's malloc_trim: a setup's temporaries stay resident otherwise, and a budget measured
// against them refuses work that fits), and its peak so far (VmHWM).
double residentBytes();
double peakResidentBytes();
// Half the physical memory: --memory's default.
double memoryBudgetByDefault();
// What a read may still allocate under `budget` bytes (0: memoryBudgetByDefault()) in a
// long-lived process: the budget less the resident set now, at least 1 byte (0 is ReadOptions'
// "no limit"), or 0 when the physical memory is unknown.
double memoryLeftWithin(double budget = 0);

// "1.25 GiB": bytes in GiB to three significant digits, as the budget errors give them.
std::string gib(double bytes);

}  // namespace repose
