#include "DcmtkCommon.h"

#include "repose/util/Error.h"

#include "DicomScreen.h"

// clang-format off
#include <dcmtk/config/osconfig.h>  // first, as DCMTK requires
// clang-format on
#include <dcmtk/dcmdata/dcdeftag.h>
#include <dcmtk/dcmdata/dcdict.h>
#include <dcmtk/dcmdata/dcfilefo.h>
#include <dcmtk/dcmdata/dcmetinf.h>
#include <dcmtk/dcmdata/dcrledrg.h>
#include <dcmtk/oflog/oflog.h>

#include <mutex>

namespace repose::io {

void prepareDcmtk(const std::string& path) {
  static std::once_flag once;
  std::call_once(once, [] {
    OFLog::configure(OFLogger::OFF_LOG_LEVEL);
    DcmRLEDecoderRegistration::registerCodecs();
  });
  if (!dcmDataDict.isDictionaryLoaded())
    throwFileError(path,
                   "DCMTK's data dictionary is not installed (libdcmtk17's dicom.dic, or "
                   "DCMDICTPATH)");
}

std::string dicomSopClassOf(const std::string& path) {
  try {
    if (!screenDicomFile(path)) return "";
  } catch (const Error&) {
    return "";  // corrupt: the reader that gets it says so
  }
  prepareDcmtk(path);
  DcmFileFormat file;
  if (file.loadFileUntilTag(path.c_str(), EXS_Unknown, EGL_noChange, DCM_MaxReadLength,
                            ERM_autoDetect, DCM_SOPInstanceUID)
          .bad())
    return "";
  OFString uid;
  if (file.getDataset()->findAndGetOFString(DCM_SOPClassUID, uid).good() && !uid.empty())
    return uid.c_str();
  if (file.getMetaInfo()->findAndGetOFString(DCM_MediaStorageSOPClassUID, uid).good())
    return uid.c_str();
  return "";
}

}  // namespace repose::io
