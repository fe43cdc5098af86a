#include "repose/volume/TissueTable.h"

#include "PhantomTissues.h"  // generated from Resources/Tissues/phantom.csv
#include "repose/util/Error.h"

#include <fstream>
#include <sstream>
#include <vector>

namespace repose {

TissueTable parseTissueTable(const std::string& csv, const std::string& source) {
  TissueTable table;
  std::istringstream in(csv);
  std::string line;
  int number = 0;
  bool header = true;
  std::size_t columns = 4;
  while (std::getline(in, line)) {
    ++number;
    if (!line.empty() && line.back() == '\r') line.pop_back();
    if (line.empty() || line[0] == '#') continue;
    const std::string where = source + ":" + std::to_string(number) + ": ";
    std::vector<std::string> fields;
    std::stringstream row(line);
    for (std::string f; std::getline(row, f, ',');) fields.push_back(f);
    if (header) {
      if ((fields.size() != 4 && fields.size() != 5) || fields[0] != "label" ||
          fields[2] != "density_kg_m3" || (fields.size() == 5 && fields[4] != "bone"))
        throw Error(where + "expected the header label,name,density_kg_m3,rigid[,bone]");
      columns = fields.size();
      header = false;
      continue;
    }
    if (fields.size() == columns - 1 && columns == 5 && !line.empty() && line.back() == ',')
      fields.emplace_back();  // an empty last field
    if (fields.size() != columns)
      throw Error(where + "expected " + std::to_string(columns) +
                  " fields: label,name,density_kg_m3,rigid" + (columns == 5 ? ",bone" : ""));
    Tissue t;
    int label = 0;
    try {
      std::size_t used = 0;
      label = std::stoi(fields[0], &used);
      if (used != fields[0].size()) throw std::invalid_argument("label");
      t.densityKgM3 = std::stod(fields[2], &used);
      if (used != fields[2].size()) throw std::invalid_argument("density");
    } catch (const std::exception&) {
      throw Error(where + "label must be an integer and density_kg_m3 a number");
    }
    if (t.densityKgM3 <= 0) throw Error(where + "density_kg_m3 must be positive");
    if (fields[3] != "0" && fields[3] != "1") throw Error(where + "rigid must be 0 or 1");
    t.name = fields[1];
    t.rigid = fields[3] == "1";
    if (columns == 5) t.bone = fields[4];
    if (!table.emplace(label, t).second)
      throw Error(where + "label " + std::to_string(label) + " given twice");
  }
  if (header) throw Error(source + ": empty tissue table");
  return table;
}

std::string tissueTableCsv(const TissueTable& table, const std::string& comment) {
  std::ostringstream out;
  std::istringstream lines(comment);
  for (std::string line; std::getline(lines, line);) out << "# " << line << "\n";
  out << "label,name,density_kg_m3,rigid,bone\n";
  for (const auto& [label, t] : table) {
    // Names with commas would break the columns: CSV without quoting, so they become ';'.
    std::string name = t.name, bone = t.bone;
    for (std::string* s : {&name, &bone})
      for (char& c : *s)
        if (c == ',' || c == '\n' || c == '\r') c = ';';
    out << label << "," << name << "," << t.densityKgM3 << "," << (t.rigid ? 1 : 0) << "," << bone
        << "\n";
  }
  return out.str();
}

TissueTable phantomTissueTable() {
  return parseTissueTable(kPhantomTissuesCsv, "phantom tissue table (compiled in)");
}

TissueTable readTissueTable(const std::string& path) {
  std::ifstream in(path);
  if (!in) throw Error(path + ": cannot open");
  std::stringstream text;
  text << in.rdbuf();
  return parseTissueTable(text.str(), path);
}

}  // namespace repose
