// A guard in front of GDCM: GDCM allocates (and zero-fills) each element's value at the length the
// file claims, so a corrupt 500 KB file can make it take 4 GB (found by Testing/Fuzz/FuzzDicom).
// This walks the element headers of a file, without reading values, and refuses a file whose
// element claims more bytes than the file has left.
#pragma once

#include <string>

namespace repose::io {

// False when the file does not look like DICOM: neither "DICM" at byte 128 (Part 10) nor, without
// the preamble, a first element of group 0002 or 0008; such files are not given to GDCM at all
// (its lenient parsing of arbitrary bytes reaches assert()s: Testing/Fuzz/FuzzDicom). Throws
// repose::Error ("path: truncated or corrupt DICOM: element (gggg,eeee) claims N bytes, M
// remain") for a DICOM file with such an element. Data after a deflated transfer syntax or an
// unparseable element header is left to GDCM.
bool screenDicomFile(const std::string& path);

}  // namespace repose::io
