// What the DCMTK-based readers and writers (DICOM SEG, RT Structure Sets) share: DCMTK set up
// once per process, and a file's SOP class read without loading the rest of the file. DCMTK's
// types stay out of this header.
#pragma once

#include <string>

namespace repose::io {

// Once per process: DCMTK's own logging off (its messages reach the user as one-line
// repose::Errors instead) and its RLE decoder registered. Throws naming `path` when DCMTK's data
// dictionary is not installed (libdcmtk17's dicom.dic): without it no attribute can be found.
void prepareDcmtk(const std::string& path);

// The SOP Class UID of a DICOM file, read only up to that attribute (the meta header's
// MediaStorageSOPClassUID when the dataset has none); "" when the file is not DICOM.
std::string dicomSopClassOf(const std::string& path);

// The SOP classes the DCMTK readers take.
inline const char* kSegmentationStorageUid = "1.2.840.10008.5.1.4.1.1.66.4";
inline const char* kRtStructureSetStorageUid = "1.2.840.10008.5.1.4.1.1.481.3";

}  // namespace repose::io
