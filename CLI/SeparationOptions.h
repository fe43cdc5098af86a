// The --separate A:B --region SPEC options that `cage` and `mesh` share: declared and parsed in
// one place, and parsed before any work so a bad region fails at once.
#pragma once

#include "ArgParser.h"

#include "repose/cage/CageBuilder.h"

#include <optional>

namespace repose::cli {

// `what` completes the help of --separate, e.g. "the cage passes between".
void declareSeparationOptions(ArgParser& parser, const std::string& what);
// The separation asked for, if any; UsageError or repose::Error for bad text.
std::optional<LimbSeparation> parseSeparationOptions(const ArgParser& parser);

}  // namespace repose::cli
