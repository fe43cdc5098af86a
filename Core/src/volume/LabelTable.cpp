// Label table kept sorted by (layer, value) so printing and writing are deterministic.
#include "repose/volume/LabelTable.h"

#include "repose/volume/AnatomyColors.h"

#include <algorithm>
#include <cmath>

namespace repose {

void LabelTable::set(const Label& label) {
  auto key = [](const Label& l) { return std::make_pair(l.layer, l.value); };
  auto it = std::lower_bound(labels_.begin(), labels_.end(), label,
                             [&](const Label& a, const Label& b) { return key(a) < key(b); });
  if (it != labels_.end() && key(*it) == key(label))
    *it = label;
  else
    labels_.insert(it, label);
}

const Label* LabelTable::find(int value, int layer) const {
  for (const Label& l : labels_)
    if (l.value == value && l.layer == layer) return &l;
  return nullptr;
}

std::array<double, 3> LabelTable::defaultColor(int value) {
  // Golden-angle hue steps keep neighbouring label values visually distinct.
  return hsvToRgb(value * 137.508, 0.65, 0.9);
}

std::array<double, 3> LabelTable::defaultColor(int value, const std::string& name, int variant) {
  if (const auto c = anatomyColor(name, value, variant)) return *c;
  return defaultColor(value + 1013 * variant);
}

}  // namespace repose
