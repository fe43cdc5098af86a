// The coded terminology of a segment (DICOM SEG's category, type and anatomic region codes) and
// its text form in a 3D Slicer segment's tags ("TerminologyEntry:..."), which is how Label::tags
// carries it: a DICOM SEG read by Repose and saved as .seg.nrrd opens in Slicer with its codes,
// and a Slicer segmentation posed and written as DICOM SEG keeps them.
#pragma once

#include <optional>
#include <string>

namespace repose {

// One code of a DICOM code sequence: coding scheme designator, code value, code meaning.
struct TerminologyCode {
  std::string scheme;   // e.g. "SCT"
  std::string value;    // e.g. "10200004"
  std::string meaning;  // e.g. "Liver"
  bool empty() const { return value.empty(); }
  bool operator==(const TerminologyCode& o) const {
    return scheme == o.scheme && value == o.value && meaning == o.meaning;
  }
};

struct SegmentTerminology {
  TerminologyCode category;  // SegmentedPropertyCategoryCodeSequence
  TerminologyCode type;      // SegmentedPropertyTypeCodeSequence
  TerminologyCode typeModifier;
  TerminologyCode region;  // AnatomicRegionSequence
  TerminologyCode regionModifier;
  bool operator==(const SegmentTerminology& o) const {
    return category == o.category && type == o.type && typeModifier == o.typeModifier &&
           region == o.region && regionModifier == o.regionModifier;
  }
};

// What DICOM SEG writers (dcmqi, Slicer) use when nothing more is known: SCT 85756007 "Tissue"
// as category and type.
SegmentTerminology genericTissueTerminology();

// The "TerminologyEntry:..." field of Slicer's segment tags (with the trailing '|'), in the
// context names Slicer gives codes that came from DICOM.
std::string terminologyTag(const SegmentTerminology& t);

// The terminology in a segment's tags (Label::tags), or nothing when the tags hold no
// TerminologyEntry, or one without a category and a type code.
std::optional<SegmentTerminology> terminologyFromTags(const std::string& tags);

}  // namespace repose
