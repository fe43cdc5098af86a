#include "repose/dosimetry/LabelTissues.h"

#include "DielectricTables.h"  // generated from Resources/Dielectric/*.csv
#include "repose/dosimetry/ColeCole.h"
#include "repose/rig/LabelConvention.h"
#include "repose/util/Error.h"
#include "repose/util/NameMatch.h"
#include "repose/volume/LabelStatistics.h"

#include <cctype>
#include <fstream>
#include <set>
#include <sstream>
#include <utility>

namespace repose {
namespace {

std::vector<std::string> fields(const std::string& line) {
  std::vector<std::string> f;
  std::stringstream row(line);
  for (std::string x; std::getline(row, x, ',');) f.push_back(x);
  if (!line.empty() && line.back() == ',') f.emplace_back();
  return f;
}

// The compiled rules, checked once: every tissue they name is in the Cole-Cole table.
const std::vector<std::pair<std::string, std::string>>& rules() {
  static const std::vector<std::pair<std::string, std::string>> list = [] {
    std::vector<std::pair<std::string, std::string>> out;
    std::istringstream in(kTissueClassRulesCsv);
    std::string line;
    bool header = true;
    int number = 0;
    while (std::getline(in, line)) {
      ++number;
      if (line.empty() || line[0] == '#') continue;
      if (header) {
        header = false;
        continue;
      }
      const std::vector<std::string> f = fields(line);
      const std::string where = "tissue_classes.csv:" + std::to_string(number) + ": ";
      if (f.size() != 2) throw Error(where + "expected pattern,tissue");
      if (!findGabrielTissue(f[1])) throw Error(where + "unknown tissue \"" + f[1] + "\"");
      out.emplace_back(f[0], f[1]);
    }
    return out;
  }();
  return list;
}

std::string tissueList() {
  std::string list;
  for (const ColeColeTissue& t : gabrielTissues()) list += (list.empty() ? "" : ", ") + t.name;
  return list;
}

std::map<int, std::string> readUserCsv(const std::string& path) {
  std::ifstream in(path);
  if (!in) throw Error(path + ": cannot open");
  std::map<int, std::string> out;
  std::string line;
  int number = 0;
  bool header = true;
  while (std::getline(in, line)) {
    ++number;
    if (!line.empty() && line.back() == '\r') line.pop_back();
    if (line.empty() || line[0] == '#') continue;
    const std::string where = path + ":" + std::to_string(number) + ": ";
    const std::vector<std::string> f = fields(line);
    if (header) {
      if (f.size() != 2 || f[0] != "label" || f[1] != "tissue")
        throw Error(where + "expected the header label,tissue");
      header = false;
      continue;
    }
    if (f.size() != 2) throw Error(where + "expected 2 fields: label,tissue");
    int label = 0;
    try {
      std::size_t used = 0;
      label = std::stoi(f[0], &used);
      if (used != f[0].size()) throw std::invalid_argument("label");
    } catch (const std::exception&) {
      throw Error(where + "label must be an integer");
    }
    const ColeColeTissue* t = findGabrielTissue(f[1]);
    if (!t) throw Error(where + "unknown tissue \"" + f[1] + "\" (known: " + tissueList() + ")");
    if (!out.emplace(label, t->name).second)
      throw Error(where + "label " + std::to_string(label) + " given twice");
  }
  if (header) throw Error(path + ": empty (expected the header label,tissue)");
  return out;
}

}  // namespace

std::string tissueForName(const std::string& name, std::string* pattern) {
  const std::string key = normalizedLabelName(name);
  if (key.empty()) return "";
  for (const auto& [glob, tissue] : rules())
    if (globMatches(glob, key)) {
      if (pattern) *pattern = glob;
      return tissue;
    }
  return "";
}

std::map<int, LabelTissue> labelNamesAndDensities(const Volume& organs, const TissueTable* tissues,
                                                  const std::string& tissuesSource,
                                                  const std::string& convention,
                                                  const std::string& source) {
  if (!organs.isLabelMap()) throw Error(source + ": not a label map (float voxels)");
  std::set<int> present;
  for (const LabelCount& c : countLabels(organs)) present.insert(c.value);
  if (present.empty()) throw Error(source + ": no labelled voxel, nothing to export");
  std::map<int, LabelTissue> out;
  if (tissues) {
    std::string missing;
    int count = 0;
    for (const int v : present) {
      const auto it = tissues->find(v);
      if (it == tissues->end()) {
        if (count++ < 8) missing += (missing.empty() ? "" : ", ") + std::to_string(v);
        continue;
      }
      LabelTissue& l = out[v];
      l.name = it->second.name;
      l.densityKgM3 = it->second.densityKgM3;
      l.densitySource = tissuesSource;
    }
    if (count)
      throw Error(tissuesSource + ": lacks " + std::to_string(count) + " label(s) of " + source +
                  " (" + missing + (count > 8 ? ", ..." : "") + ")");
    return out;
  }
  const LabelConvention c = labelConvention(organs, convention, source);
  for (const int v : present) {
    LabelTissue& l = out[v];
    const LabelRole& r = c.roles.at(v);
    // The file's own name wins for the tissue rules (a user's names say more than "label_7").
    const Label* own = organs.labels().find(v);
    l.name = own && !own->name.empty() ? own->name : r.name;
    l.densityKgM3 = r.densityKgM3;
    l.densitySource = c.name;
  }
  return out;
}

void assignTissues(std::map<int, LabelTissue>& labels, const LabelTissueOptions& options) {
  const std::map<int, std::string> user =
      options.userCsv.empty() ? std::map<int, std::string>{} : readUserCsv(options.userCsv);
  std::string fallback;
  if (!options.defaultTissue.empty()) {
    const ColeColeTissue* t = findGabrielTissue(options.defaultTissue);
    if (!t)
      throw Error("--default-tissue \"" + options.defaultTissue + "\" is not a known tissue (" +
                  tissueList() + ")");
    fallback = t->name;
  }
  std::vector<std::string> unknown;
  for (auto& [value, l] : labels) {
    if (const auto it = user.find(value); it != user.end()) {
      l.tissue = it->second;
      l.rule = options.userCsv;
      continue;
    }
    std::string pattern;
    l.tissue = tissueForName(l.name, &pattern);
    if (!l.tissue.empty()) {
      l.rule = "name rule '" + pattern + "'";
    } else if (!fallback.empty()) {
      l.tissue = fallback;
      l.rule = "--default-tissue";
    } else {
      unknown.push_back(std::to_string(value) + (l.name.empty() ? "" : " (" + l.name + ")"));
    }
  }
  if (!unknown.empty()) {
    std::string list;
    for (std::size_t i = 0; i < unknown.size() && i < 10; ++i) list += (i ? ", " : "") + unknown[i];
    throw Error("no dielectric tissue for " + std::to_string(unknown.size()) +
                " label(s): " + list + (unknown.size() > 10 ? ", ..." : "") +
                "; give --tissue-map FILE.csv (label,tissue) or --default-tissue NAME");
  }
}

}  // namespace repose
