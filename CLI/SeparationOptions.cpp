// Shared limb-separation options of `repose cage` and `repose mesh`.
#include "SeparationOptions.h"

#include <tuple>

namespace repose::cli {

void declareSeparationOptions(ArgParser& parser, const std::string& what) {
  parser.option("separate", "A:B", what + " body-part labels A and B inside --region")
      .option("region", "SPEC", "box:x0,y0,z0,x1,y1,z1 or sphere:x,y,z,r in RAS mm");
}

std::optional<LimbSeparation> parseSeparationOptions(const ArgParser& parser) {
  if (parser.has("separate") != parser.has("region"))
    throw UsageError{"--separate and --region go together"};
  if (!parser.has("separate")) return std::nullopt;
  LimbSeparation separation;
  std::tie(separation.labelA, separation.labelB) =
      parseLabelPair(parser.get("separate"), "separate");
  separation.region = Region::parse(parser.get("region"));
  return separation;
}

}  // namespace repose::cli
