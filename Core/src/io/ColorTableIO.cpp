// Slicer's .ctbl layout (Libs/MRML/Core/vtkMRMLColorTableStorageNode.cxx): comment lines start
// with '#', each entry is "index name r g b a" split on whitespace, colours on a 0-255 scale,
// indices not listed stay undefined (so gaps survive).
#include "repose/io/ColorTableIO.h"

#include "repose/io/AtomicOutput.h"
#include "repose/util/Error.h"
#include "repose/volume/AnatomyColors.h"
#include "repose/volume/LabelStatistics.h"

#include <algorithm>
#include <cmath>
#include <fstream>
#include <sstream>

namespace repose {
namespace {

int byte(double channel) {
  return static_cast<int>(std::lround(std::clamp(channel, 0.0, 1.0) * 255.0));
}

// One whitespace-free token: Slicer splits on any whitespace and reads '_' back as a space.
std::string token(const std::string& name, int value) {
  std::string out = name.empty() ? "label_" + std::to_string(value) : name;
  for (char& c : out)
    if (c == ' ' || c == '\t' || c == '\n' || c == '\r') c = '_';
  return out;
}

}  // namespace

void writeColorTable(const Volume& labelMap, const std::string& path) {
  std::vector<int> present;
  for (const LabelCount& c : countLabels(labelMap))
    if (c.layer == 0) present.push_back(c.value);
  writeColorTable(labelMap.labels(), present, path);
}

void writeColorTable(const LabelTable& table, const std::vector<int>& present,
                     const std::string& path) {
  LabelTable labels = table;
  for (const int value : present)
    if (value != 0 && !labels.find(value)) {
      Label l;
      l.value = value;
      l.color = LabelTable::defaultColor(value);
      l.colorGenerated = true;
      labels.set(l);
    }
  int highest = 0;
  for (const Label& l : labels.labels()) {
    if (l.layer != 0) continue;
    if (l.value < 0)
      throwFileError(path, "label " + std::to_string(l.value) +
                               " is negative; a colour table cannot index it");
    highest = std::max(highest, l.value);
  }
  std::ostringstream out;
  out << "# Color table file " << path << "\n# " << highest + 1 << " values\n";
  out << "0 Background 0 0 0 0\n";
  for (const Label& l : labels.labels()) {
    if (l.layer != 0 || l.value == 0) continue;
    out << l.value << " " << token(l.name, l.value) << " " << byte(l.color[0]) << " "
        << byte(l.color[1]) << " " << byte(l.color[2]) << " 255\n";
  }
  writeTextFileAtomically(path, out.str());
}

LabelTable readColorTable(const std::string& path) {
  std::ifstream in(path);
  if (!in) throwFileError(path, "cannot open");
  std::stringstream text;
  text << in.rdbuf();
  return parseColorTable(text.str(), path);
}

}  // namespace repose
