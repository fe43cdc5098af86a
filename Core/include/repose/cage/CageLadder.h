// The automatic cage never fails a pose for want of a setting: when the cage asked for fails its
// checks (a thin contact on thick slices simplifies into a self-intersection), the next settings
// are tried in a fixed order, and what was tried is kept for report.json.
//
// The order (docs/ARCHITECTURE.md, "The cage builder"): the asked setting; more vertices at the
// asked dilation (twice, 1000, 2000: a finer cage follows the contact instead of cutting across
// it); then a smaller dilation (0.6 times: the contacts the pose's separations were found for
// stay within the cage's reach) at the asked and twice the vertices; then a larger one (1.5
// times) likewise. Only a failed check moves on: an empty map or a region that selects nothing
// fails at once, as buildCage says.
#pragma once

#include "repose/cage/CageBuilder.h"

#include <functional>
#include <string>
#include <vector>

namespace repose {

struct CageSetting {
  int vertices = 300;
  double dilateMm = 10;
  bool operator==(const CageSetting& o) const {
    return vertices == o.vertices && dilateMm == o.dilateMm;
  }
};

struct CageAttempt {
  CageSetting setting;
  std::string failure;  // what failed ("self-intersecting", ...); "" for the cage kept
};

// Which cage a rig has: the setting asked for, the one that gave the cage, and every setting
// tried before it with why it failed. A rig read from a scene folder has the choice recorded
// there (empty `tried` and asked == used for a scene written before the ladder).
struct CageChoice {
  CageSetting asked, used;
  std::vector<CageAttempt> tried;  // in order; the last is the one used
  bool fallback() const { return !(asked == used); }
  // report.json's and scene.json's "cage": asked, used, tried (docs/FORMATS.md).
  std::string json() const;
  // Reads what json() wrote; throws repose::Error on text that is not such an object.
  static CageChoice fromJson(const std::string& text);
  // A cage of a known setting with nothing else tried (a cage read from a file, or a scene that
  // recorded no choice): asked and used alike.
  static CageChoice given(const CageSetting& setting);
};

// The settings tried, in order, starting with `asked` (no setting twice; vertices within
// buildCage's 50..2000).
std::vector<CageSetting> cageLadder(const CageSetting& asked);

// buildCage at options.targetVertices / options.dilateMm, then down the ladder while the cage
// fails its checks. Throws repose::Error in one line listing every setting tried and why each
// failed when none gives a valid cage; any other error of buildCage at once. `choice` (optional)
// receives what was asked, used and tried.
// `build` builds one cage (buildCage unless given: a test's stand-in that fails on cue).
using CageBuildFn = std::function<Cage(const Volume&, const CageOptions&)>;
Cage buildCageTrying(const Volume& parts, const CageOptions& options, CageChoice* choice = nullptr,
                     const CageBuildFn& build = {});

}  // namespace repose
