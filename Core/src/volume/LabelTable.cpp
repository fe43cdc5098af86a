// Label table kept sorted by (layer, value) so printing and writing are deterministic.
#include "repose/volume/LabelTable.h"

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
  const double h = std::fmod(value * 137.508, 360.0) / 60.0, s = 0.65, v = 0.9;
  const double c = v * s, x = c * (1 - std::fabs(std::fmod(h, 2.0) - 1)), m = v - c;
  std::array<double, 3> rgb{};
  switch (static_cast<int>(h)) {
    case 0:
      rgb = {c, x, 0};
      break;
    case 1:
      rgb = {x, c, 0};
      break;
    case 2:
      rgb = {0, c, x};
      break;
    case 3:
      rgb = {0, x, c};
      break;
    case 4:
      rgb = {x, 0, c};
      break;
    default:
      rgb = {c, 0, x};
      break;
  }
  for (double& ch : rgb) ch += m;
  return rgb;
}

}  // namespace repose
