// One DICOM file as a series of one slice, through GDCM and readDicomSeries (sorting, geometry
// from IPP/IOP, rescale, pixel data of any transfer syntax GDCM decodes).
#include "FuzzFiles.h"
#include "repose/io/DicomSeriesIO.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace repose;
  fuzz::writeInput("series/1.dcm", data, size);
  try {
    const Volume v = readDicomSeries((fuzz::workFolder() / "series").string(), fuzz::readOptions());
    (void)v.numVoxels();
  } catch (const Error&) {
  }
  return 0;
}
