// Repose's private block in the items of a DICOM SEG's SegmentSequence: the label value and layer
// a segment had in Repose (creator "REPOSE" reserving (0071,10xx); (0071,1001) IS value,
// (0071,1002) IS layer). SEG numbers its segments 1..n; a label map's values need not be that
// (a tissue map's values index its tissue table), so a SEG Repose wrote gives back its values.
// Other readers ignore the block, as DICOM asks of private data they do not know.
#pragma once

class DcmItem;

namespace repose::io {

void putReposeLabel(DcmItem& segmentItem, int value, int layer);
// False when the item has no (valid) block.
bool getReposeLabel(DcmItem& segmentItem, int& value, int& layer);

}  // namespace repose::io
