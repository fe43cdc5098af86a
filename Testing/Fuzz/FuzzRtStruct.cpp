// One file as an RT Structure Set through DCMTK and readRtStruct (ROIs, contours, the spanning
// grid, the even-odd fill, layers), on a grid of 2 mm voxels.
#include "FuzzFiles.h"
#include "repose/io/RtStructIO.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace repose;
  fuzz::writeInput("rtss.dcm", data, size);
  try {
    RtStructOptions options;
    options.spacingMm = 2;
    options.memoryLimitBytes = fuzz::readOptions().memoryLimitBytes;
    const Volume v = readRtStruct((fuzz::workFolder() / "rtss.dcm").string(), options);
    (void)v.numVoxels();
  } catch (const Error&) {
  }
  return 0;
}
