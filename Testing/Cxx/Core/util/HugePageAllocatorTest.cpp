// HugePageAllocator: large blocks 2 MiB-aligned and advised as huge pages (the kernel marks the
// mapping "hg" in /proc/self/smaps wherever THP exists), small ones ordinary; contents survive a
// vector growing across the threshold either way; a Volume's voxels use it.
#include "repose/util/HugePageAllocator.h"
#include "repose/volume/Volume.h"

#include <gtest/gtest.h>

#include <cstdint>
#include <fstream>
#include <sstream>
#include <string>

using namespace repose;

namespace {

// The VmFlags of the mapping that holds `p` ("" when not found).
std::string vmFlagsAt(const void* p) {
  std::ifstream smaps("/proc/self/smaps");
  const auto at = reinterpret_cast<std::uintptr_t>(p);
  bool inside = false;
  for (std::string line; std::getline(smaps, line);) {
    std::uintptr_t lo = 0, hi = 0;
    char dash = 0;
    std::istringstream range(line);
    if (range >> std::hex >> lo >> dash >> hi && dash == '-' && line.find(':') > line.find(' ')) {
      inside = lo <= at && at < hi;
      continue;
    }
    if (inside && line.rfind("VmFlags:", 0) == 0) return line;
  }
  return "";
}

bool kernelHasHugePages() {
  std::ifstream enabled("/sys/kernel/mm/transparent_hugepage/enabled");
  std::string mode;
  return std::getline(enabled, mode) && mode.find("[never]") == std::string::npos;
}

}  // namespace

TEST(HugePageAllocator, LargeBlocksAreAlignedAndAdvisedSmallOnesAreOrdinary) {
  HugePageVector<std::uint16_t> large(3 << 20);  // 6 MiB
  const auto address = reinterpret_cast<std::uintptr_t>(large.data());
  EXPECT_EQ(address % detail::kHugePageBytes, 0u);
  if (kernelHasHugePages()) {
    EXPECT_NE(vmFlagsAt(large.data()).find(" hg"), std::string::npos) << vmFlagsAt(large.data());
  }
  HugePageVector<std::uint8_t> small(1000, 7);
  EXPECT_EQ(small[999], 7);
  const std::string smallFlags = vmFlagsAt(small.data());
  ASSERT_FALSE(smallFlags.empty());  // its mapping (the heap) is found, so the next line tests
  EXPECT_EQ(smallFlags.find(" hg"), std::string::npos) << smallFlags;
}

TEST(HugePageAllocator, ContentsSurviveGrowingAndShrinkingAcrossTheThreshold) {
  HugePageVector<std::uint32_t> v;
  for (std::uint32_t i = 0; i < (3u << 20); ++i) v.push_back(i * 2654435761u);
  for (std::uint32_t i = 0; i < v.size(); i += 4099) ASSERT_EQ(v[i], i * 2654435761u);
  v.resize(10);
  v.shrink_to_fit();
  for (std::uint32_t i = 0; i < 10; ++i) EXPECT_EQ(v[i], i * 2654435761u);
  HugePageVector<std::uint32_t> copy = v;
  EXPECT_EQ(copy, v);
}

TEST(HugePageAllocator, AVolumesVoxelsAreInHugePages) {
  VolumeGeometry g;
  g.dims = {256, 256, 64};  // 4 MiB of uint8
  g.ijkToRas = Eigen::Matrix4d::Identity();
  Volume v(g, ScalarType::UInt8);
  EXPECT_EQ(reinterpret_cast<std::uintptr_t>(v.layerData()) % detail::kHugePageBytes, 0u);
  EXPECT_EQ(v.data<std::uint8_t>()[v.numVoxels() - 1], 0);  // zero-filled as before
}
