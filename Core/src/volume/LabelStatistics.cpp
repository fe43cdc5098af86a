// Per-label voxel counts: one pass per layer with a dense histogram for small integer types.
#include "repose/volume/LabelStatistics.h"

#include <map>

namespace repose {

std::vector<LabelCount> countLabels(const Volume& volume) {
  if (!isIntegerType(volume.scalarType()))
    throw Error("label statistics need an integer volume, not float32");
  const double voxelMm3 = volume.geometry().spacing().prod();
  std::vector<LabelCount> out;
  for (int layer = 0; layer < volume.layers(); ++layer) {
    std::map<int, std::int64_t> counts;
    dispatchScalar(volume.scalarType(), [&](auto* tag) {
      using T = std::remove_pointer_t<decltype(tag)>;
      const T* v = volume.data<T>(layer);
      const std::int64_t n = volume.numVoxels();
      if constexpr (sizeof(T) <= 2) {
        // Dense histogram: labels of 8/16-bit maps index directly.
        std::vector<std::int64_t> hist(1 << (8 * sizeof(T)), 0);
        for (std::int64_t i = 0; i < n; ++i)
          ++hist[static_cast<std::size_t>(static_cast<std::make_unsigned_t<T>>(v[i]))];
        for (std::size_t b = 0; b < hist.size(); ++b)
          if (hist[b]) counts[static_cast<int>(static_cast<T>(b))] += hist[b];
      } else {
        for (std::int64_t i = 0; i < n; ++i) ++counts[static_cast<int>(v[i])];
      }
    });
    for (const auto& [value, voxels] : counts)
      if (value != 0) out.push_back({layer, value, voxels, voxels * voxelMm3});
  }
  return out;
}

}  // namespace repose
