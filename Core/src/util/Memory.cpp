#include "repose/util/Memory.h"

#include <unistd.h>
#if defined(__GLIBC__)
#include <malloc.h>
#endif

#include <algorithm>
#include <fstream>
#include <limits>
#include <sstream>
#include <string>

namespace repose {

namespace {

// One "Key: N kB" line of /proc/self/status, in bytes.
double statusBytes(const char* wanted) {
  std::ifstream status("/proc/self/status");
  std::string key;
  while (status >> key) {
    if (key == wanted) {
      double kib = 0;
      status >> kib;
      return kib * 1024;
    }
    status.ignore(std::numeric_limits<std::streamsize>::max(), '\n');
  }
  return 0;
}

}  // namespace

double physicalMemoryBytes() {
  const long pages = sysconf(_SC_PHYS_PAGES), pageSize = sysconf(_SC_PAGE_SIZE);
  return pages > 0 && pageSize > 0 ? double(pages) * double(pageSize) : 0;
}

double residentBytes() {
#if defined(__GLIBC__)
  // What the process holds, not what its allocator keeps of what it freed: a setup's
  // temporaries (a grid-sized mask, a sort's buffer) leave free heap that stays resident until
  // given back, and a budget measured against it would refuse work that fits.
  malloc_trim(0);
#endif
  return statusBytes("VmRSS:");
}

double peakResidentBytes() {
  return statusBytes("VmHWM:");
}

double memoryBudgetByDefault() {
  return 0.5 * physicalMemoryBytes();
}

double memoryLeftWithin(double budget) {
  if (budget <= 0) budget = memoryBudgetByDefault();
  if (budget <= 0) return 0;  // physical memory unknown: no limit rather than refusing every read
  // A peak from an earlier, finished job does not count against this read: the resident set now.
  return std::max(1.0, budget - residentBytes());
}

std::string gib(double bytes) {
  std::ostringstream s;
  s.precision(3);
  s << bytes / (1024.0 * 1024 * 1024) << " GiB";
  return s.str();
}

}  // namespace repose
