// Storage of a Volume: one contiguous byte buffer, layers one after the other.
#include "repose/volume/Volume.h"

#include <cstring>

namespace repose {

Volume::Volume(const VolumeGeometry& geometry, ScalarType type, int layers)
    : geometry_(geometry), type_(type), layers_(layers) {
  if (layers < 1) throw Error("a volume needs at least one layer");
  for (auto d : geometry.dims)
    if (d <= 0) throw Error("volume dimensions must be positive");
  bytes_.assign(static_cast<std::size_t>(geometry.numVoxels()) * scalarSize(type) * layers, 0);
}

void Volume::setGeometry(const VolumeGeometry& g) {
  if (g.dims != geometry_.dims) throw Error("setGeometry cannot change the dimensions");
  geometry_ = g;
}

void* Volume::layerData(int layer) {
  return const_cast<void*>(static_cast<const Volume*>(this)->layerData(layer));
}

const void* Volume::layerData(int layer) const {
  if (layer < 0 || layer >= layers_)
    throw Error("layer " + std::to_string(layer) + " out of range");
  return bytes_.data() + static_cast<std::size_t>(layer) * numVoxels() * scalarSize(type_);
}

double Volume::valueAsDouble(std::int64_t index, int layer) const {
  return dispatchScalar(type_, [&](auto* tag) -> double {
    using T = std::remove_pointer_t<decltype(tag)>;
    return static_cast<double>(static_cast<const T*>(layerData(layer))[index]);
  });
}

}  // namespace repose
