// Tissue properties per label for reports: mass density (kg/m^3) and whether the tissue is rigid
// (bone: it must move as a rigid copy). Read from CSV: `label,name,density_kg_m3,rigid` with a
// header line; `#` starts a comment line. Resources/Tissues/phantom.csv is the default table of
// the generated phantom (docs/QUALITY.md gives its sources).
#pragma once

#include <map>
#include <string>

namespace repose {

struct Tissue {
  std::string name;
  double densityKgM3 = 0;
  bool rigid = false;
};

using TissueTable = std::map<int, Tissue>;  // label value -> tissue

// Throws repose::Error "<path>:<line>: <problem>" for a malformed line, a density <= 0 or a label
// given twice.
TissueTable readTissueTable(const std::string& path);
TissueTable parseTissueTable(const std::string& csv, const std::string& source);

}  // namespace repose
