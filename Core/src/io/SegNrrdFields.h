// The 3D Slicer segmentation fields of a .seg.nrrd header (Segment{N}_ID/Name/LabelValue/Layer/
// Color/Extent/Tags and the Segmentation_* fields), to and from a LabelTable.
#pragma once

#include "repose/volume/Volume.h"

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
// The fields Slicer writes for this segmentation (extents computed from the voxels), in order.
KeyValues formatSegments(const Volume& volume);

}  // namespace repose::segnrrd
