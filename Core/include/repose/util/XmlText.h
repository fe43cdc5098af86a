// Text inside XML written by hand (NIfTI label tables, Slicer scenes and module descriptions):
// the five characters XML reserves, escaped as entities, so a name like "A&B <left>" stays text.
#pragma once

#include <string>

namespace repose {

// & < > " ' as &amp; &lt; &gt; &quot; &apos; (valid in element text and in attribute values).
std::string escapeXml(const std::string& text);

}  // namespace repose
