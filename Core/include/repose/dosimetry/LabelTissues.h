// Which dielectric tissue each label of a body model is, for the FDTD export: a user's CSV by
// label value first, then the compiled-in name rules (Resources/Dielectric/tissue_classes.csv:
// the phantom's, ICRP 110's and TotalSegmentator's names), then a default tissue if one is given.
// Labels left without a tissue are a one-line error listing them.
#pragma once

#include "repose/util/NameMatch.h"  // globMatches, used with the rules
#include "repose/volume/TissueTable.h"
#include "repose/volume/Volume.h"

#include <map>
#include <string>
#include <vector>

namespace repose {

// What the export knows of one label of G: its name and mass density (from the tissue table or
// the label convention) and the tissue it is given.
struct LabelTissue {
  std::string name;
  double densityKgM3 = 0;
  std::string densitySource;  // "tissues.csv", "icrp110 (AM)", ...
  std::string tissue;         // a name of gabrielTissues()
  std::string rule;           // how: "FILE.csv", "name rule '*cortical*'", "--default-tissue"
};

struct LabelTissueOptions {
  std::string userCsv;        // label,tissue with a header; "" for none
  std::string defaultTissue;  // for labels no rule names; "" means they are an error
};

// Names and densities for every label present in G: from `tissues` when given (every present
// label must be in it), else from G's label convention (labelConvention with `convention`:
// auto, phantom, icrp110, totalsegmentator or a CSV). Throws repose::Error with one line.
std::map<int, LabelTissue> labelNamesAndDensities(const Volume& organs, const TissueTable* tissues,
                                                  const std::string& tissuesSource,
                                                  const std::string& convention,
                                                  const std::string& source);

// Fills each label's tissue and rule. Throws repose::Error listing the labels without a tissue
// ("no dielectric tissue for 3 labels: 41 (foo), ...; give --tissue-map FILE.csv or
// --default-tissue NAME"), or naming a user CSV line with an unknown tissue.
void assignTissues(std::map<int, LabelTissue>& labels, const LabelTissueOptions& options);

// The rule file's tissue for a name (lower case, '_' as space, ';' as ','), or "" when no
// pattern matches; `pattern` receives the pattern that matched.
std::string tissueForName(const std::string& name, std::string* pattern = nullptr);

}  // namespace repose
