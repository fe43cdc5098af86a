// A coarse map (issue 65): few labels, one of them the body's outline and one the whole skeleton,
// as most dosimetry users have one (a CT's bone threshold and body mask, a simulation phantom's
// coarse classes). Recognised by the labels' names ("body", "skeleton") or, unnamed, by their
// shapes, only where that is unambiguous.
#pragma once

#include "repose/volume/Volume.h"

#include <optional>
#include <string>
#include <vector>

namespace repose::rig {

struct CoarseMap {
  int body = 0;      // the outline's label (0: none)
  int skeleton = 0;  // the skeleton's label
  std::string how;   // what was recognised, for rig.json's detection
};

// `labels`: the values present in G's layer 0, increasing.
std::optional<CoarseMap> recogniseCoarseMap(const Volume& organs, const std::vector<int>& labels);

}  // namespace repose::rig
