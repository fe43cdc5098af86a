// Label names and colours of a label map, and the extra fields a 3D Slicer segment carries
// (ID, layer, terminology tags) so a .seg.nrrd survives a round trip through Repose.
#pragma once

#include <array>
#include <optional>
#include <string>
#include <vector>

namespace repose {

struct Label {
  int value = 0;                               // voxel value of this label (in its layer)
  std::string name;                            // e.g. "liver"
  std::array<double, 3> color{0.5, 0.5, 0.5};  // RGB in [0,1]
  int layer = 0;                               // layer of a multi-layer segmentation, else 0
  std::string id;                              // Slicer segment ID; empty when the file had none
  std::string tags;                            // Slicer segment tags (terminology), verbatim
};

class LabelTable {
 public:
  // Adds or replaces the entry with the same (value, layer).
  void set(const Label& label);
  const Label* find(int value, int layer = 0) const;
  const std::vector<Label>& labels() const { return labels_; }
  bool empty() const { return labels_.empty(); }
  std::size_t size() const { return labels_.size(); }
  // A distinct, stable colour for a value with no colour given (golden-angle hue walk).
  static std::array<double, 3> defaultColor(int value);

 private:
  std::vector<Label> labels_;  // sorted by (layer, value)
};

}  // namespace repose
