// The allocator of the large buffers a posing job fills (volumes, the Green coordinates): a block
// of 2 MiB or more is aligned to 2 MiB, its size rounded up to whole 2 MiB pages, and advised as
// transparent huge pages (madvise MADV_HUGEPAGE) before anything touches it. Where THP is in
// "madvise" mode (Debian's default) each 4 KiB page of such a buffer otherwise costs a page fault
// on first write: a `repose warp` of the 0.85 mm phantom took 280K faults and 2.3 s of system
// time on a 2-core VM, 13K with huge pages (docs/PERFORMANCE.md). Smaller blocks, and systems
// without THP, get ordinary memory.
#pragma once

#include <cstddef>
#include <limits>
#include <new>
#include <vector>

namespace repose {

namespace detail {
constexpr std::size_t kHugePageBytes = std::size_t(2) << 20;
// 2 MiB-aligned memory of `bytes` rounded up to whole huge pages, advised; throws std::bad_alloc.
void* allocateHugePages(std::size_t bytes);
void freeHugePages(void* p) noexcept;
}  // namespace detail

template <class T>
struct HugePageAllocator {
  using value_type = T;
  HugePageAllocator() noexcept = default;
  template <class U>
  HugePageAllocator(const HugePageAllocator<U>&) noexcept {}
  T* allocate(std::size_t n) {
    if (n > std::numeric_limits<std::size_t>::max() / sizeof(T)) throw std::bad_array_new_length();
    const std::size_t bytes = n * sizeof(T);
    if (bytes >= detail::kHugePageBytes) return static_cast<T*>(detail::allocateHugePages(bytes));
    return static_cast<T*>(::operator new(bytes));
  }
  void deallocate(T* p, std::size_t n) noexcept {
    if (n * sizeof(T) >= detail::kHugePageBytes)
      detail::freeHugePages(p);
    else
      ::operator delete(p);
  }
  template <class U>
  bool operator==(const HugePageAllocator<U>&) const noexcept {
    return true;
  }
  template <class U>
  bool operator!=(const HugePageAllocator<U>&) const noexcept {
    return false;
  }
};

template <class T>
using HugePageVector = std::vector<T, HugePageAllocator<T>>;

}  // namespace repose
