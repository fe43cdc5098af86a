#include "repose/util/HugePageAllocator.h"

#include <sys/mman.h>

#include <cstdlib>

namespace repose::detail {

void* allocateHugePages(std::size_t bytes) {
  const std::size_t rounded = (bytes + kHugePageBytes - 1) / kHugePageBytes * kHugePageBytes;
  if (rounded < bytes) throw std::bad_alloc();
  void* p = nullptr;
  if (posix_memalign(&p, kHugePageBytes, rounded) != 0) throw std::bad_alloc();
#ifdef MADV_HUGEPAGE
  // Advice only: a kernel without THP (EINVAL) leaves ordinary pages, which is what this was.
  madvise(p, rounded, MADV_HUGEPAGE);
#endif
  return p;
}

void freeHugePages(void* p) noexcept {
  std::free(p);
}

}  // namespace repose::detail
