// 3D Slicer segmentations (.seg.nrrd: segment fields, layers, extents) through readVolume.
#include "FuzzFiles.h"
#include "repose/io/VolumeIO.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace repose;
  const std::string path = fuzz::writeInput("in.seg.nrrd", data, size);
  try {
    const Volume v = readVolume(path, fuzz::readOptions());
    (void)v.labels();
  } catch (const Error&) {
  }
  return 0;
}
