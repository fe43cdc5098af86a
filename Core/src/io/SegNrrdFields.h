// The 3D Slicer segmentation fields of a .seg.nrrd header (Segment{N}_ID/Name/LabelValue/Layer/
// Color/Extent/Tags and the Segmentation_* fields), to and from a LabelTable.
#pragma once

#include "repose/volume/Volume.h"

#include <array>
#include <cstdint>
#include <map>
#include <string>
#include <utility>
#include <vector>

namespace repose::segnrrd {

using KeyValues = std::vector<std::pair<std::string, std::string>>;

// True when the key/value pairs carry Slicer segment fields.
bool hasSegmentFields(const std::map<std::string, std::string>& kv);
// Segments as labels (value, layer, name, colour, ID, tags); throws naming path on bad fields.
LabelTable parseSegments(const std::map<std::string, std::string>& kv, const std::string& path);
// Bounding boxes (imin imax jmin jmax kmin kmax) per label value of one layer.
using Extent = std::array<std::int64_t, 6>;
using Extents = std::map<int, Extent>;
// Grows `extents` by slices [k0, k1) of one layer (x fastest, values of an integer `type`).
void addExtents(const void* slices, ScalarType type, const std::array<std::int64_t, 3>& dims,
                std::int64_t k0, std::int64_t k1, Extents& extents);

// The fields Slicer writes for this segmentation (extents computed from the voxels), in order.
KeyValues formatSegments(const Volume& volume);
// The same from a segmentation's grid, layers, label table and each layer's extents (a map
// written slab by slab, never held whole).
KeyValues formatSegments(const VolumeGeometry& geometry, int layers, const LabelTable& labels,
                         const std::vector<Extents>& extents);

}  // namespace repose::segnrrd
