#include "repose/io/LabelProxy.h"

#include "repose/util/Error.h"

#include <algorithm>
#include <cmath>
#include <type_traits>
#include <vector>

namespace repose {

int proxyFactor(std::int64_t voxels, std::size_t bytesPerVoxel, double bytes) {
  int f = 1;
  while (double(voxels) * double(bytesPerVoxel) / (double(f) * f * f) > bytes && f < 64) ++f;
  return f;
}

Volume labelModeProxy(SliceCache& source, int factor, const ProgressFn& progress) {
  const NiftiLayout& layout = source.layout();
  if (!isIntegerType(layout.type)) throw Error("a label proxy needs integer labels");
  if (factor < 1) throw Error("a label proxy needs a factor of at least 1");
  const VolumeGeometry& g = layout.geometry;
  VolumeGeometry coarse;
  for (int a = 0; a < 3; ++a) coarse.dims[a] = (g.dims[a] + factor - 1) / factor;
  coarse.ijkToRas = g.ijkToRas;
  coarse.ijkToRas.block<3, 3>(0, 0) *= double(factor);
  const double shift = (factor - 1) / 2.0;
  coarse.ijkToRas.block<3, 1>(0, 3) = g.voxelToRas(shift, shift, shift);
  Volume proxy(coarse, layout.type);
  proxy.setLabelMap(true);
  proxy.labels() = layout.labels;
  const std::int64_t nx = g.dims[0], ny = g.dims[1];
  dispatchScalar(layout.type, [&](auto* tag) {
    using T = std::remove_pointer_t<decltype(tag)>;
    T* out = proxy.data<T>();
    // One proxy slice at a time: copy its `factor` source slices (the cache may hold fewer).
    std::vector<T> slab(static_cast<std::size_t>(nx * ny * factor));
    std::vector<T> block;
    block.reserve(static_cast<std::size_t>(factor) * factor * factor);
    for (std::int64_t K = 0; K < coarse.dims[2]; ++K) {
      const std::int64_t k0 = K * factor, k1 = std::min(g.dims[2], k0 + factor);
      for (std::int64_t k = k0; k < k1; ++k) {
        const T* s = static_cast<const T*>(source.slice(k));
        std::copy(s, s + nx * ny, slab.begin() + (k - k0) * nx * ny);
      }
      for (std::int64_t J = 0; J < coarse.dims[1]; ++J)
        for (std::int64_t I = 0; I < coarse.dims[0]; ++I) {
          block.clear();
          for (std::int64_t k = 0; k < k1 - k0; ++k)
            for (std::int64_t j = J * factor; j < std::min(ny, (J + 1) * factor); ++j)
              for (std::int64_t i = I * factor; i < std::min(nx, (I + 1) * factor); ++i)
                block.push_back(slab[static_cast<std::size_t>((k * ny + j) * nx + i)]);
          std::sort(block.begin(), block.end());
          T best = block.front();
          std::size_t bestCount = 0;
          for (std::size_t a = 0; a < block.size();) {
            std::size_t b = a;
            while (b < block.size() && block[b] == block[a]) ++b;
            const std::size_t count = b - a;
            // Sorted ascending: a later (larger) label wins only with more votes, except that
            // any label beats background on a tie.
            if (count > bestCount || (count == bestCount && best == T(0)))
              best = block[a], bestCount = count;
            a = b;
          }
          out[proxy.index(I, J, K)] = best;
        }
      reportProgress(progress, double(K + 1) / double(coarse.dims[2]), "label proxy");
    }
  });
  return proxy;
}

}  // namespace repose
