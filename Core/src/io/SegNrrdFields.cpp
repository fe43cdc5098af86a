// Slicer's segment fields, with the exact names and value formats Slicer itself writes, so a file
// written here opens in Slicer as a segmentation with the same names, colours and terminology.
#include "SegNrrdFields.h"

#include <algorithm>
#include <array>
#include <cstdlib>
#include <limits>
#include <sstream>

namespace repose::segnrrd {
namespace {

std::string get(const std::map<std::string, std::string>& kv, const std::string& key) {
  auto it = kv.find(key);
  return it == kv.end() ? std::string() : it->second;
}

int parseInt(const std::string& s, const std::string& key, const std::string& path) {
  char* end = nullptr;
  const long v = std::strtol(s.c_str(), &end, 10);
  if (s.empty() || *end != '\0' || v < std::numeric_limits<int>::min() ||
      v > std::numeric_limits<int>::max())
    throwFileError(path, "segment field " + key + " is not an integer: '" + s + "'");
  return static_cast<int>(v);
}

using Extent = std::array<std::int64_t, 6>;

// Bounding boxes (imin imax jmin jmax kmin kmax) of every value of one layer, in one pass.
std::map<int, Extent> extentsOf(const Volume& volume, int layer) {
  std::map<int, Extent> out;
  if (!isIntegerType(volume.scalarType())) return out;
  const auto& d = volume.dims();
  dispatchScalar(volume.scalarType(), [&](auto* tag) {
    using T = std::remove_pointer_t<decltype(tag)>;
    const T* v = volume.data<T>(layer);
    std::int64_t idx = 0;
    for (std::int64_t k = 0; k < d[2]; ++k)
      for (std::int64_t j = 0; j < d[1]; ++j)
        for (std::int64_t i = 0; i < d[0]; ++i, ++idx) {
          if (v[idx] == 0) continue;
          const int value = static_cast<int>(v[idx]);
          auto [it, fresh] = out.try_emplace(value, Extent{i, i, j, j, k, k});
          if (!fresh) {
            Extent& e = it->second;
            e[0] = std::min(e[0], i);
            e[1] = std::max(e[1], i);
            e[2] = std::min(e[2], j);
            e[3] = std::max(e[3], j);
            e[4] = std::min(e[4], k);
            e[5] = std::max(e[5], k);
          }
        }
  });
  return out;
}

}  // namespace

bool hasSegmentFields(const std::map<std::string, std::string>& kv) {
  return kv.count("Segment0_LabelValue") || kv.count("Segment0_ID") ||
         kv.count("Segmentation_MasterRepresentation");
}

LabelTable parseSegments(const std::map<std::string, std::string>& kv, const std::string& path) {
  LabelTable table;
  for (int n = 0;; ++n) {
    const std::string prefix = "Segment" + std::to_string(n) + "_";
    if (!kv.count(prefix + "ID") && !kv.count(prefix + "LabelValue") && !kv.count(prefix + "Name"))
      break;
    Label label;
    label.id = get(kv, prefix + "ID");
    label.name = get(kv, prefix + "Name");
    if (label.name.empty()) label.name = label.id;
    const std::string value = get(kv, prefix + "LabelValue");
    // Files from Slicer before label values existed: segment N has value N+1.
    label.value = value.empty() ? n + 1 : parseInt(value, prefix + "LabelValue", path);
    const std::string layer = get(kv, prefix + "Layer");
    label.layer = layer.empty() ? 0 : parseInt(layer, prefix + "Layer", path);
    std::istringstream color(get(kv, prefix + "Color"));
    double r, g, b;
    if (color >> r >> g >> b)
      label.color = {r, g, b};
    else
      label.color = LabelTable::defaultColor(label.value);
    label.tags = get(kv, prefix + "Tags");
    if (table.find(label.value, label.layer))
      throwFileError(path, "two segments share label value " + std::to_string(label.value) +
                               " on layer " + std::to_string(label.layer));
    table.set(label);
  }
  return table;
}

KeyValues formatSegments(const Volume& volume) {
  KeyValues out;
  const Eigen::Matrix4d& m = volume.geometry().ijkToRas;
  const auto& d = volume.dims();
  std::ostringstream geometry;
  geometry.precision(17);
  for (int r = 0; r < 4; ++r)
    for (int c = 0; c < 4; ++c) geometry << m(r, c) << ";";
  geometry << "0;" << d[0] - 1 << ";0;" << d[1] - 1 << ";0;" << d[2] - 1 << ";";
  out.emplace_back("Segmentation_ContainedRepresentationNames", "Binary labelmap|");
  out.emplace_back("Segmentation_ConversionParameters",
                   "Reference image geometry|" + geometry.str() +
                       "|Image geometry description string determining the geometry of the "
                       "labelmap that is created in course of conversion.&");
  out.emplace_back("Segmentation_MasterRepresentation", "Binary labelmap");
  out.emplace_back("Segmentation_ReferenceImageExtentOffset", "0 0 0");

  std::vector<std::map<int, Extent>> extents;
  for (int layer = 0; layer < volume.layers(); ++layer) extents.push_back(extentsOf(volume, layer));
  // Every value present gets a segment, named from the label table when it has the value.
  std::vector<Label> segments;
  for (int layer = 0; layer < volume.layers(); ++layer)
    for (const auto& [value, extent] : extents[layer]) {
      const Label* known = volume.labels().find(value, layer);
      Label l = known ? *known : Label{};
      l.value = value;
      l.layer = layer;
      if (l.name.empty()) l.name = "Segment_" + std::to_string(value);
      if (!known) l.color = LabelTable::defaultColor(value);
      segments.push_back(l);
    }
  std::sort(segments.begin(), segments.end(), [](const Label& a, const Label& b) {
    return std::make_pair(a.layer, a.value) < std::make_pair(b.layer, b.value);
  });
  for (std::size_t n = 0; n < segments.size(); ++n) {
    const Label& l = segments[n];
    const std::string p = "Segment" + std::to_string(n) + "_";
    std::ostringstream color;
    color << l.color[0] << " " << l.color[1] << " " << l.color[2];
    const Extent& e = extents[l.layer].at(l.value);
    std::ostringstream extent;
    extent << e[0] << " " << e[1] << " " << e[2] << " " << e[3] << " " << e[4] << " " << e[5];
    out.emplace_back(p + "Color", color.str());
    out.emplace_back(p + "ColorAutoGenerated", "0");
    out.emplace_back(p + "Extent", extent.str());
    out.emplace_back(p + "ID", l.id.empty() ? "Segment_" + std::to_string(n + 1) : l.id);
    out.emplace_back(p + "LabelValue", std::to_string(l.value));
    out.emplace_back(p + "Layer", std::to_string(l.layer));
    out.emplace_back(p + "Name", l.name);
    out.emplace_back(p + "NameAutoGenerated", "0");
    out.emplace_back(p + "Tags", l.tags.empty() ? "Segmentation.Status:inprogress|" : l.tags);
  }
  return out;
}

}  // namespace repose::segnrrd
