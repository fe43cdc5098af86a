// Matching label names against the compiled-in name rules (tissue classes, display colours): a
// name is compared in lower case with '_' read as a space and ';' as ',', trimmed, against
// whole-text glob patterns.
#pragma once

#include <string>

namespace repose {

// "Humeri_upper half;cortical " -> "humeri upper half,cortical".
std::string normalizedLabelName(const std::string& name);
// Whole-text glob match with '*' (any text) and '?' (one character).
bool globMatches(const std::string& pattern, const std::string& text);

}  // namespace repose
