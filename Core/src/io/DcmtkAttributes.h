// Reading attributes from a DCMTK dataset the way Repose's DICOM readers need: absent or
// malformed values give an empty result (the reader then says what is missing), never an
// exception or a crash. Include only after dcmtk/config/osconfig.h.
#pragma once

#include <dcmtk/dcmdata/dcdeftag.h>
#include <dcmtk/dcmdata/dcfilefo.h>
#include <dcmtk/dcmdata/dcitem.h>

#include "repose/util/Error.h"

#include "DcmtkCommon.h"
#include "DicomScreen.h"
#include "ReaderCommon.h"

#include <cmath>
#include <string>
#include <vector>

namespace repose::io {

// Text of an attribute (all values, backslash-separated), without DICOM's padding.
inline std::string dicomText(DcmItem* item, const DcmTagKey& tag) {
  OFString v;
  if (!item || item->findAndGetOFStringArray(tag, v).bad()) return "";
  std::string t(v.c_str());
  while (!t.empty() && (t.back() == ' ' || t.back() == '\0')) t.pop_back();
  std::size_t start = 0;
  while (start < t.size() && t[start] == ' ') ++start;
  return t.substr(start);
}

// The numeric values of a DS/IS/FD/FL attribute; empty when absent, malformed or not finite.
inline std::vector<double> dicomNumbers(DcmItem* item, const DcmTagKey& tag) {
  std::vector<double> out;
  DcmElement* e = nullptr;
  if (!item || item->findAndGetElement(tag, e).bad() || !e) return out;
  const unsigned long n = e->getVM();
  out.reserve(n);
  for (unsigned long i = 0; i < n; ++i) {
    Float64 v = 0;
    Sint32 integer = 0;  // IS (ROI Display Color) has no floating-point getter
    if (e->getFloat64(v, i).good() && std::isfinite(v))
      out.push_back(v);
    else if (e->getSint32(integer, i).good())
      out.push_back(double(integer));
    else
      return {};
  }
  return out;
}

// An attribute of any integer VR (US, UL, SS, SL, IS); `fallback` when absent or out of range.
inline long dicomInteger(DcmItem* item, const DcmTagKey& tag, long fallback) {
  long v = 0;
  if (!item || item->findAndGetLongInt(tag, v).bad() || std::labs(v) > 2000000000L) return fallback;
  return v;
}

// Item `index` of a sequence, or null.
inline DcmItem* dicomItem(DcmItem* parent, const DcmTagKey& sequence, long index = 0) {
  DcmItem* out = nullptr;
  if (parent && parent->findAndGetSequenceItem(sequence, out, index).good()) return out;
  return nullptr;
}

// Loads `path` into `file` and checks its SOP class; throws naming the file otherwise ("not
// <what> (SOP class ...)").
inline DcmDataset& loadDicomOfClass(DcmFileFormat& file, const std::string& path,
                                    const std::string& sopClass, const std::string& what) {
  requireReadableFile(path);
  prepareDcmtk(path);
  if (!screenDicomFile(path)) throwFileError(path, "not a DICOM file");
  const OFCondition loaded = file.loadFile(path.c_str());
  if (loaded.bad())
    throwFileError(path, std::string("not a readable DICOM file (") + loaded.text() + ")");
  DcmDataset* ds = file.getDataset();
  const std::string sop = dicomText(ds, DCM_SOPClassUID);
  if (sop != sopClass)
    throwFileError(path, "not " + what + " (SOP class " + (sop.empty() ? "missing" : sop) + ")");
  return *ds;
}

}  // namespace repose::io
