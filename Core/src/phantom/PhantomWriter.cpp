// writePhantom: generates G and S slab by slab straight into two streaming NIfTI writers, so
// memory stays at two slab buffers whatever the voxel size, and writes the skeleton JSON.
#include "repose/phantom/Phantom.h"

#include "repose/io/AtomicOutput.h"
#include "repose/io/NiftiIO.h"
#include "repose/util/Error.h"

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <future>
#include <memory>
#include <vector>

namespace repose {

namespace {

// Per map buffer: enough slices to keep the threads busy, small enough to be invisible in RSS.
constexpr std::int64_t kSlabBytes = 32ll << 20;

}  // namespace

PhantomFiles writePhantom(const Phantom& phantom, const std::string& outDir, const std::string& ext,
                          const ProgressFn& progress, const std::string& prefix, bool image) {
  if (ext != ".nii.gz" && ext != ".nii")
    throw Error("phantom: unsupported output extension '" + ext + "' (use .nii.gz or .nii)");
  if (prefix.find('/') != std::string::npos)
    throw Error("phantom: the file prefix '" + prefix + "' must not contain a folder");
  if (image && phantom.options().labels != PhantomLabelling::Phantom)
    throw Error("phantom: the synthetic CT needs the phantom's own labels, not ICRP's");
  std::error_code ec;
  if (!std::filesystem::is_directory(outDir, ec))
    throwFileError(outDir, "output folder does not exist");
  const std::filesystem::path dir(outDir);
  PhantomFiles files;
  files.organs = (dir / (prefix + "G" + ext)).string();
  files.parts = (dir / (prefix + "S" + ext)).string();
  files.skeleton = (dir / (prefix + "skeleton.json")).string();
  if (image) files.image = (dir / (prefix + "CT" + ext)).string();

  // The skeleton is staged first and committed last, so a failed run leaves no new file at all
  // unless the voxel maps were complete.
  AtomicOutput skeleton(files.skeleton);
  {
    std::ofstream out(skeleton.tempPath(), std::ios::binary);
    out << phantom.skeletonJson();
    if (!out.flush()) throwFileError(files.skeleton, "write failed (disk full?)");
  }

  const VolumeGeometry& g = phantom.geometry();
  const bool big = *std::max_element(g.dims.begin(), g.dims.end()) > 32767;
  const int version = big ? 2 : 1;
  NiftiSlabWriter organs(files.organs, g, ScalarType::UInt8, phantom.organLabels(), true, version);
  NiftiSlabWriter parts(files.parts, g, ScalarType::UInt8, phantom.partLabels(), true, version);
  std::unique_ptr<NiftiSlabWriter> ct;
  if (image)
    ct = std::make_unique<NiftiSlabWriter>(files.image, g, ScalarType::Int16, LabelTable(), false,
                                           version);

  const std::int64_t sliceVoxels = g.dims[0] * g.dims[1];
  const std::int64_t slab = std::clamp<std::int64_t>(kSlabBytes / sliceVoxels, 1, g.dims[2]);
  std::vector<std::uint8_t> organBuf(static_cast<std::size_t>(slab * sliceVoxels));
  std::vector<std::uint8_t> partBuf(organBuf.size());
  std::vector<std::int16_t> ctBuf(image ? organBuf.size() : 0);
  reportProgress(progress, 0.0, "phantom");
  for (std::int64_t k = 0; k < g.dims[2]; k += slab) {
    const std::int64_t n = std::min(slab, g.dims[2] - k);
    phantom.fillSlices(k, k + n, organBuf.data(), partBuf.data());
    // The two gzip streams are independent: compress them side by side.
    auto partsDone = std::async(std::launch::async, [&] {
      parts.writeSlices(partBuf.data(), n);
      if (ct) {
        syntheticCTVoxels(organBuf.data(), ctBuf.data(), n * sliceVoxels, k * sliceVoxels);
        ct->writeSlices(ctBuf.data(), n);
      }
    });
    organs.writeSlices(organBuf.data(), n);
    partsDone.get();
    reportProgress(progress, double(k + n) / g.dims[2], "phantom");
  }
  organs.finish();
  parts.finish();
  if (ct) ct->finish();
  skeleton.commit();
  return files;
}

}  // namespace repose
