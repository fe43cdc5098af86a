// NRRD volumes with attached headers (.nrrd; raw or gzip data) through readVolume.
#include "FuzzFiles.h"
#include "repose/io/VolumeIO.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace repose;
  const std::string path = fuzz::writeInput("in.nrrd", data, size);
  try {
    const Volume v = readVolume(path, fuzz::readOptions());
    (void)v.numVoxels();
  } catch (const Error&) {
  }
  return 0;
}
