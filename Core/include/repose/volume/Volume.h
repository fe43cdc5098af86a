// repose::Volume: one type for label maps and intensity images, in memory, with geometry
// (IJK -> RAS), scalar type, optional layers (overlapping Slicer segmentations) and label table.
#pragma once

#include "repose/util/HugePageAllocator.h"
#include "repose/volume/LabelTable.h"
#include "repose/volume/ScalarType.h"
#include "repose/volume/VolumeGeometry.h"

#include <cstdint>
#include <vector>

namespace repose {

class Volume {
 public:
  Volume() = default;
  // Zero-filled volume. layers > 1 only for multi-layer segmentations.
  Volume(const VolumeGeometry& geometry, ScalarType type, int layers = 1);

  const VolumeGeometry& geometry() const { return geometry_; }
  void setGeometry(const VolumeGeometry& g);  // dims must stay the same
  const std::array<std::int64_t, 3>& dims() const { return geometry_.dims; }
  std::int64_t numVoxels() const { return geometry_.numVoxels(); }
  ScalarType scalarType() const { return type_; }
  int layers() const { return layers_; }

  // A label map holds discrete labels (nearest-neighbour only); an image holds intensities.
  bool isLabelMap() const { return labelMap_; }
  void setLabelMap(bool v) { labelMap_ = v; }
  LabelTable& labels() { return labels_; }
  const LabelTable& labels() const { return labels_; }

  // Voxel (i,j,k) of a layer is at index i + dims[0]*(j + dims[1]*k) of layerData(layer).
  void* layerData(int layer = 0);
  const void* layerData(int layer = 0) const;
  template <class T>
  T* data(int layer = 0) {
    checkType<T>();
    return static_cast<T*>(layerData(layer));
  }
  template <class T>
  const T* data(int layer = 0) const {
    checkType<T>();
    return static_cast<const T*>(layerData(layer));
  }
  std::int64_t index(std::int64_t i, std::int64_t j, std::int64_t k) const {
    return i + geometry_.dims[0] * (j + geometry_.dims[1] * k);
  }
  double valueAsDouble(std::int64_t index, int layer = 0) const;
  std::size_t byteSize() const { return bytes_.size(); }
  const HugePageVector<std::uint8_t>& bytes() const { return bytes_; }

 private:
  template <class T>
  void checkType() const;
  VolumeGeometry geometry_;
  ScalarType type_ = ScalarType::UInt8;
  int layers_ = 1;
  bool labelMap_ = false;
  LabelTable labels_;
  // Layers stored one after the other; in huge pages (HugePageAllocator.h: a volume is written
  // whole soon after it is made, and 4 KiB pages cost a fault each).
  HugePageVector<std::uint8_t> bytes_;
};

}  // namespace repose

#include "repose/util/Error.h"

namespace repose {
template <class T>
void Volume::checkType() const {
  if (scalarTypeOf<T>() != type_)
    throw Error(std::string("volume holds ") + scalarTypeName(type_) + ", not " +
                scalarTypeName(scalarTypeOf<T>()));
}
}  // namespace repose
