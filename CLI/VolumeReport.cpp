// Volume descriptions: geometry in RAS mm, orientation codes, labels with names and counts.
#include "VolumeReport.h"

#include "repose/volume/LabelStatistics.h"

#include <algorithm>
#include <cmath>
#include <iomanip>
#include <limits>
#include <sstream>

namespace repose::cli {

nlohmann::json describeVolume(const Volume& volume, const std::string& path) {
  const VolumeGeometry& g = volume.geometry();
  nlohmann::json j;
  j["file"] = path;
  j["format"] = formatName(formatForPath(path));
  j["dimensions"] = g.dims;
  const Eigen::Vector3d s = g.spacing();
  j["spacing_mm"] = {s.x(), s.y(), s.z()};
  j["orientation"] = g.axisCodes();
  // Sheared grids are read and described, but a rig cannot be built from one (VolumeGeometry.h).
  j["axis_skew_deg"] = g.axisSkewDegrees();
  j["voxel_volume_mm3"] = g.voxelVolumeMm3();
  nlohmann::json m = nlohmann::json::array();
  for (int r = 0; r < 4; ++r)
    m.push_back({g.ijkToRas(r, 0), g.ijkToRas(r, 1), g.ijkToRas(r, 2), g.ijkToRas(r, 3)});
  j["ijk_to_ras"] = m;
  const Eigen::Vector3d o = g.origin();
  j["origin_ras_mm"] = {o.x(), o.y(), o.z()};
  const auto [lo, hi] = g.rasBounds();
  j["extent_ras_mm"] = {{"min", {lo.x(), lo.y(), lo.z()}},
                        {"max", {hi.x(), hi.y(), hi.z()}},
                        {"size", {hi.x() - lo.x(), hi.y() - lo.y(), hi.z() - lo.z()}}};
  j["scalar_type"] = scalarTypeName(volume.scalarType());
  j["voxels"] = volume.numVoxels();
  j["layers"] = volume.layers();
  j["label_map"] = volume.isLabelMap();
  if (volume.isLabelMap()) {
    nlohmann::json labels = nlohmann::json::array();
    for (const LabelCount& c : countLabels(volume)) {
      const Label* l = volume.labels().find(c.value, c.layer);
      nlohmann::json e = {{"value", c.value},
                          {"name", l ? l->name : ""},
                          {"voxels", c.voxels},
                          {"volume_ml", c.volumeMm3 / 1000.0}};
      if (volume.layers() > 1) e["layer"] = c.layer;
      if (l) e["color"] = l->color;
      labels.push_back(e);
    }
    j["labels_present"] = labels.size();
    j["labels"] = labels;
    // Names the file declares for values that have no voxel: useful when checking a table.
    nlohmann::json unused = nlohmann::json::array();
    for (const Label& l : volume.labels().labels()) {
      const bool present = std::any_of(labels.begin(), labels.end(), [&](const nlohmann::json& e) {
        return e["value"] == l.value && e.value("layer", 0) == l.layer;
      });
      if (!present) unused.push_back({{"value", l.value}, {"name", l.name}});
    }
    j["labels_declared_absent"] = unused;
    // The reverse: values with voxels that a non-empty table does not name.
    nlohmann::json unnamed = nlohmann::json::array();
    for (const LabelCount& c : unnamedLabels(volume)) unnamed.push_back(c.value);
    j["labels_unnamed"] = unnamed;
  } else {
    double lo = std::numeric_limits<double>::max(), hi = -lo, sum = 0;
    for (std::int64_t i = 0; i < volume.numVoxels(); ++i) {
      const double v = volume.valueAsDouble(i);
      lo = std::min(lo, v), hi = std::max(hi, v), sum += v;
    }
    j["intensity"] = {
        {"min", lo}, {"max", hi}, {"mean", sum / std::max<std::int64_t>(1, volume.numVoxels())}};
  }
  return j;
}

std::string formatVolumeText(const nlohmann::json& j) {
  std::ostringstream out;
  out << std::setprecision(6);
  auto triple = [](const nlohmann::json& a, const char* sep) {
    std::ostringstream s;
    s << std::setprecision(6) << a[0].get<double>() << sep << a[1].get<double>() << sep
      << a[2].get<double>();
    return s.str();
  };
  out << j["file"].get<std::string>() << " (" << j["format"].get<std::string>() << ")\n";
  out << "  dimensions   " << triple(j["dimensions"], " x ") << "  (" << j["voxels"] << " voxels";
  if (j["layers"].get<int>() > 1) out << ", " << j["layers"] << " layers";
  out << ")\n";
  out << "  spacing      " << triple(j["spacing_mm"], " x ") << " mm\n";
  out << "  orientation  " << j["orientation"].get<std::string>() << "\n";
  if (j["axis_skew_deg"].get<double>() > kMaxAxisSkewDegrees)
    out << "  warning      voxel axes are not orthogonal (sheared by "
        << j["axis_skew_deg"].get<double>() << " degrees): resample before posing\n";
  out << "  origin       (" << triple(j["origin_ras_mm"], ", ") << ") mm RAS\n";
  out << "  extent       (" << triple(j["extent_ras_mm"]["min"], ", ") << ") .. ("
      << triple(j["extent_ras_mm"]["max"], ", ") << ") mm RAS, size "
      << triple(j["extent_ras_mm"]["size"], " x ") << " mm\n";
  out << "  scalar type  " << j["scalar_type"].get<std::string>()
      << (j["label_map"].get<bool>() ? "  (label map)" : "  (image)") << "\n";
  if (j.contains("labels")) {
    out << "  labels       " << j["labels_present"] << " present\n";
    const bool layered = j["layers"].get<int>() > 1;
    for (const auto& l : j["labels"]) {
      out << "    " << std::setw(5) << l["value"].get<int>();
      if (layered) out << " (layer " << l["layer"].get<int>() << ")";
      out << "  " << std::left << std::setw(32) << l["name"].get<std::string>() << std::right
          << std::setw(12) << l["voxels"].get<std::int64_t>() << " voxels  " << std::setw(10)
          << std::fixed << std::setprecision(2) << l["volume_ml"].get<double>() << " ml\n"
          << std::defaultfloat << std::setprecision(6);
    }
    if (!j["labels_unnamed"].empty())
      out << "  warning      values with voxels but no name in the label table: "
          << j["labels_unnamed"].dump() << "\n";
  } else if (j.contains("intensity")) {
    out << "  intensity    min " << j["intensity"]["min"].get<double>() << ", max "
        << j["intensity"]["max"].get<double>() << ", mean " << j["intensity"]["mean"].get<double>()
        << "\n";
  }
  return out.str();
}

}  // namespace repose::cli
