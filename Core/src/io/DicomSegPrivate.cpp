#include "DicomSegPrivate.h"

// clang-format off
#include <dcmtk/config/osconfig.h>  // first, as DCMTK requires
// clang-format on
#include <dcmtk/dcmdata/dcitem.h>
#include <dcmtk/dcmdata/dctag.h>

#include <string>

namespace repose::io {
namespace {

constexpr Uint16 kGroup = 0x0071;
const char* const kCreator = "REPOSE";

}  // namespace

void putReposeLabel(DcmItem& item, int value, int layer) {
  item.putAndInsertString(DcmTag(kGroup, 0x0010, EVR_LO), kCreator);
  DcmTag valueTag(kGroup, 0x1001, EVR_IS), layerTag(kGroup, 0x1002, EVR_IS);
  valueTag.setPrivateCreator(kCreator);
  layerTag.setPrivateCreator(kCreator);
  item.putAndInsertString(valueTag, std::to_string(value).c_str());
  item.putAndInsertString(layerTag, std::to_string(layer).c_str());
}

bool getReposeLabel(DcmItem& item, int& value, int& layer) {
  OFString creator;
  if (item.findAndGetOFString(DcmTagKey(kGroup, 0x0010), creator).bad()) return false;
  while (!creator.empty() && creator[creator.size() - 1] == ' ') creator.erase(creator.size() - 1);
  if (creator != kCreator) return false;
  Sint32 v = 0, l = 0;
  if (item.findAndGetSint32(DcmTagKey(kGroup, 0x1001), v).bad() ||
      item.findAndGetSint32(DcmTagKey(kGroup, 0x1002), l).bad())
    return false;
  value = int(v);
  layer = int(l);
  return true;
}

}  // namespace repose::io
