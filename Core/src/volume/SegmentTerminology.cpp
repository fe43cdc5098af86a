// Slicer writes a segment's terminology as
//   TerminologyEntry:<context>~<category>~<type>~<type modifier>~<anatomic context>~<region>~
//   <region modifier>|
// with each code as <scheme>^<value>^<meaning> (empty: "^^"), in a tag list separated by '|'
// (vtkSlicerTerminologyEntry's serialization, seen in Slicer's own .seg.nrrd files).
#include "repose/volume/SegmentTerminology.h"

#include <vector>

namespace repose {
namespace {

const char* const kTag = "TerminologyEntry:";
const char* const kTypeContext = "Segmentation category and type - DICOM master list";
const char* const kRegionContext = "Anatomic codes - DICOM master list";

std::vector<std::string> split(const std::string& s, char sep) {
  std::vector<std::string> out;
  std::string::size_type start = 0;
  for (;;) {
    const auto end = s.find(sep, start);
    out.push_back(s.substr(start, end == std::string::npos ? std::string::npos : end - start));
    if (end == std::string::npos) return out;
    start = end + 1;
  }
}

std::string format(const TerminologyCode& c) {
  return c.scheme + "^" + c.value + "^" + c.meaning;
}

TerminologyCode parse(const std::string& s) {
  const std::vector<std::string> f = split(s, '^');
  TerminologyCode c;
  if (f.size() >= 3) {
    c.scheme = f[0];
    c.value = f[1];
    c.meaning = f[2];
    // A meaning with '^' in it (never in DICOM's code meanings, but harmless to keep).
    for (std::size_t i = 3; i < f.size(); ++i) c.meaning += "^" + f[i];
  }
  return c;
}

}  // namespace

SegmentTerminology genericTissueTerminology() {
  SegmentTerminology t;
  t.category = {"SCT", "85756007", "Tissue"};
  t.type = t.category;
  return t;
}

std::string terminologyTag(const SegmentTerminology& t) {
  return std::string(kTag) + kTypeContext + "~" + format(t.category) + "~" + format(t.type) + "~" +
         format(t.typeModifier) + "~" + kRegionContext + "~" + format(t.region) + "~" +
         format(t.regionModifier) + "|";
}

std::optional<SegmentTerminology> terminologyFromTags(const std::string& tags) {
  for (const std::string& entry : split(tags, '|')) {
    if (entry.rfind(kTag, 0) != 0) continue;
    const std::vector<std::string> f = split(entry.substr(std::string(kTag).size()), '~');
    if (f.size() < 4) return std::nullopt;
    SegmentTerminology t;
    t.category = parse(f[1]);
    t.type = parse(f[2]);
    t.typeModifier = parse(f[3]);
    if (f.size() >= 7) {
      t.region = parse(f[5]);
      t.regionModifier = parse(f[6]);
    }
    if (t.category.empty() || t.type.empty()) return std::nullopt;
    return t;
  }
  return std::nullopt;
}

}  // namespace repose
