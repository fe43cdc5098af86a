// NIfTI-1/2 label maps and images (.nii, .nii.gz) through readVolume.
#include "FuzzFiles.h"
#include "repose/io/VolumeIO.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace repose;
  const std::string path =
      fuzz::writeInput(fuzz::isGzip(data, size) ? "in.nii.gz" : "in.nii", data, size);
  try {
    const Volume v = readVolume(path, fuzz::readOptions());
    (void)v.numVoxels();
  } catch (const Error&) {
  }
  return 0;
}
