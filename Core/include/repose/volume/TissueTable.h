// Tissue properties per label for reports: mass density (kg/m^3), whether the tissue is rigid
// (bone: it must move as a rigid copy) and which bone it is part of (a humerus is its cortical
// shell, spongiosa and medullary cavity: three labels, one bone). Read from CSV:
// `label,name,density_kg_m3,rigid[,bone]` with a header line; `#` starts a comment line.
// Resources/Tissues/phantom.csv is the default table of the generated phantom (docs/QUALITY.md
// gives its sources), compiled into Core.
#pragma once

#include <map>
#include <string>

namespace repose {

struct Tissue {
  std::string name;
  double densityKgM3 = 0;
  bool rigid = false;
  std::string bone;  // the bone a rigid label belongs to; "" means the label is a bone by itself
  const std::string& boneName() const { return bone.empty() ? name : bone; }
};

using TissueTable = std::map<int, Tissue>;  // label value -> tissue

// Throws repose::Error "<path>:<line>: <problem>" for a malformed line, a density <= 0 or a label
// given twice.
TissueTable readTissueTable(const std::string& path);
TissueTable parseTissueTable(const std::string& csv, const std::string& source);
// The table as CSV text (with the bone column).
std::string tissueTableCsv(const TissueTable& table, const std::string& comment = "");

// The generated phantom's table (Resources/Tissues/phantom.csv, compiled in).
TissueTable phantomTissueTable();

}  // namespace repose
