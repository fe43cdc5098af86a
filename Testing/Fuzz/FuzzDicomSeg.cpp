// One file as a DICOM SEG through DCMTK and readDicomSeg (segments, functional groups, frame
// placement, layers, packed bits and fractional bytes).
#include "FuzzFiles.h"
#include "repose/io/DicomSegIO.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace repose;
  fuzz::writeInput("seg.dcm", data, size);
  try {
    const Volume v = readDicomSeg((fuzz::workFolder() / "seg.dcm").string(), fuzz::readOptions());
    (void)v.numVoxels();
  } catch (const Error&) {
  }
  return 0;
}
