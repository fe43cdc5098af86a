// poseFrameToFolder: the whole frame made slab by slab and written as it goes (issue 56), for a
// frame whose posed volumes do not fit in memory. Two passes over the output slices:
//  1. each slab's labels as sampled (with the slices beside it): the rounding's counts and
//     candidates, the pockets' trace; the field and the image, final already, written;
//  2. after the rounding's choice and the pockets' fill: each slab's labels made again, relabelled
//     and filled, counted for the report and written.
// Every step is the one poseFrame runs over the whole grid (one slab), so the files and the report
// are the in-core frame's, voxel for voxel (PoseFrameStreamTest).
#include "repose/pose/PoseFrame.h"

#include "PoseFrameSteps.h"
#include "repose/io/ColorTableIO.h"
#include "repose/io/NiftiIO.h"
#include "repose/io/NrrdIO.h"
#include "repose/util/Interrupt.h"
#include "repose/util/Memory.h"

#include <algorithm>
#include <cmath>
#include <optional>
#include <set>

namespace repose {
namespace {

// Output slices per slab for `freeBytes`: 40 % of it for one slab's buffers (G and S with
// the slices beside them, the field and its LPS copy, the image, the rounding's scratch).
std::int64_t slabsFor(const VolumeGeometry& grid, const Volume& organs, const Volume& parts,
                      const Volume* image, double freeBytes) {
  const double plane = double(grid.dims[0]) * double(grid.dims[1]);
  const double perVoxel = double(scalarSize(organs.scalarType())) * organs.layers() +
                          double(scalarSize(parts.scalarType())) * parts.layers() + 24 +
                          (image ? double(scalarSize(image->scalarType())) : 0) + 8;
  const double slices = std::floor(0.4 * freeBytes / (plane * perVoxel)) - 2;
  return std::clamp<std::int64_t>(std::int64_t(std::max(1.0, slices)), 1, grid.dims[2]);
}

// Layer 0 of a slab buffer that holds each layer's `slices` slices one after another.
const void* layerZero(const std::vector<std::uint8_t>& buffer) {
  return buffer.data();
}

// Non-zero values of layer 0 of `n` voxels, added to `present`.
void addPresent(const void* data, ScalarType type, std::int64_t n, std::set<int>& present) {
  dispatchScalar(type, [&](auto* tag) {
    using T = std::remove_pointer_t<decltype(tag)>;
    if constexpr (std::is_integral_v<T>) {
      const T* v = static_cast<const T*>(data);
      T last = T(0);
      for (std::int64_t i = 0; i < n; ++i)
        if (v[i] != T(0) && v[i] != last) present.insert(int(v[i])), last = v[i];
    }
  });
}

// A DICOM SEG is made whole in memory (dcmseg holds every frame): refused before the work.
void refuseDicomSeg(const FrameWriteOptions& write, const std::string& folder) {
  if (write.labelMapFiles == LabelMapFiles::DicomSeg)
    throw Error(folder +
                ": a DICOM SEG is made whole in memory, and this frame's posed maps do not fit the "
                "memory budget; write nii.gz or seg.nrrd (--output-format), or raise --memory");
}

}  // namespace

std::string poseFrameToFolder(const PoseRig& rig, std::size_t index, const Volume& organs,
                              const Volume& parts, const PoseFrameOptions& options,
                              const std::string& folder, const FrameWriteOptions& write,
                              double memoryBudget, std::int64_t slabSlices) {
  refuseDicomSeg(write, folder);
  frame::FrameStart start = frame::startFrame(rig, index, organs, parts, options);
  if (options.checkGrid) options.checkGrid(start.grid);
  return frame::poseFrameToFolderFrom(start, rig, organs, parts, options, folder, write,
                                      memoryBudget, slabSlices, {});
}

std::string frame::poseFrameToFolderFrom(
    FrameStart& start, const PoseRig& rig, const Volume& organs, const Volume& parts,
    const PoseFrameOptions& options, const std::string& folder, const FrameWriteOptions& write,
    double memoryBudget, std::int64_t slabSlices,
    const std::function<std::string(const std::string&)>& complete) {
  const LabelMapFiles files = write.labelMapFiles;
  refuseDicomSeg(write, folder);
  const TransferMesh& mesh = rig.mesh();
  const Eigen::MatrixX3d& deformed = start.frame.deformed;
  const VolumeGeometry& grid = start.grid;
  const std::int64_t nz = grid.dims[2], plane = grid.dims[0] * grid.dims[1];
  RasterOptions ro = frame::rasterOptions(start, organs, parts, options);
  const LabelSlabs organSlabs(organs, mesh, deformed, grid, ro);
  const LabelSlabs partSlabs(parts, mesh, deformed, grid, ro);
  const DisplacementSlabs fieldSlabs(mesh, deformed, organs.geometry(), grid, ro);
  std::optional<ImageSlabs> imageSlabs;
  if (options.image)
    imageSlabs.emplace(*options.image, mesh, deformed, grid,
                       options.background ? *options.background : imageBackground(*options.image),
                       ro);
  // What is free once the scans are set up (the pieces' owners, the shells' coverage: arrays on
  // the input's grid) decides the slabs' size.
  if (memoryBudget <= 0) memoryBudget = memoryBudgetByDefault();
  const double freeBytes = memoryBudget > 0 ? memoryBudget - residentBytes() : 8.0 * (1 << 30);
  const std::int64_t slab = slabSlices > 0
                                ? std::min(slabSlices, nz)
                                : slabsFor(grid, organs, parts, options.image, freeBytes);
  // At least a slab of one slice with the slices beside it must fit beside what is held.
  const double oneSlab = double(grid.dims[0] * grid.dims[1]) *
                         (3 * posedBytesPerVoxel(organs, parts, options.image) + 12);
  if (memoryBudget > 0 && freeBytes < oneSlab)
    throw Error(folder + ": frame " + start.frame.name + " needs " + gib(oneSlab) +
                " for a slab of one slice beside the " + gib(residentBytes()) +
                " in use, more than the memory budget of " + gib(memoryBudget) +
                " (--memory; the rig and the rest maps stay in memory)");

  // The rounding's candidates beyond a quarter of what is free go to a temporary file.
  std::optional<LabelSlabRounding> rounding;
  if (options.preserveLabelVolumes)
    rounding.emplace(organSlabs, std::size_t(std::max(0.0, 0.25 * freeBytes)));
  std::optional<PosePockets> pockets;
  if (options.fillPockets) pockets.emplace(organs, grid);

  FrameFolder out(folder, write.lockFolder);
  const std::filesystem::path& temp = out.temp();
  const bool nifti = files == LabelMapFiles::Nifti || files == LabelMapFiles::Both;
  const bool seg = files == LabelMapFiles::SegNrrd || files == LabelMapFiles::Both;
  auto progress = [&](double from, double to, std::int64_t k0, std::int64_t k1,
                      const std::string& stage) -> ProgressFn {
    if (!options.progress) return {};
    return [&, from, to, k0, k1, stage](double f, const std::string&) {
      const double done = (double(k0) + f * double(k1 - k0)) / double(nz);
      return options.progress(from + (to - from) * done, stage);
    };
  };
  const std::size_t organBytes = std::size_t(organSlabs.sliceBytes()),
                    partBytes = std::size_t(partSlabs.sliceBytes());
  RasterReport raster;
  PocketReport pocketReport;
  PosedTally posed(organs, parts, &start.frame.handles, grid, options.threads);
  try {
    // Pass 1: the labels as sampled, the field and the image.
    DisplacementFieldNrrdWriter fieldWriter(grid, (temp / "transform.nrrd").string());
    std::optional<NiftiSlabWriter> imageWriter;
    if (options.image)
      imageWriter.emplace((temp / "posed_image.nii.gz").string(), grid, options.image->scalarType(),
                          LabelTable(), false);
    std::vector<std::uint8_t> organBuffer, partBuffer, imageBuffer;
    std::vector<float> field;
    RasterReport unused;
    for (std::int64_t k0 = 0; k0 < nz; k0 += slab) {
      const std::int64_t k1 = std::min(nz, k0 + slab);
      const std::int64_t lo = std::max<std::int64_t>(0, k0 - 1), hi = std::min(nz, k1 + 1);
      organBuffer.resize(std::size_t(hi - lo) * organBytes);
      partBuffer.resize(std::size_t(hi - lo) * partBytes);
      organSlabs.rasterize(lo, hi, organBuffer.data(), unused,
                           progress(0, 0.5, k0, k1, "rasterize labels"));
      partSlabs.rasterize(lo, hi, partBuffer.data(), unused);
      // Layer 0 of slices [lo, hi): the slab at k0 - lo, the slices beside it.
      const std::size_t organValue = scalarSize(organs.scalarType()),
                        partValue = scalarSize(parts.scalarType());
      const auto* g = static_cast<const std::uint8_t*>(layerZero(organBuffer));
      const auto* s = static_cast<const std::uint8_t*>(layerZero(partBuffer));
      const std::uint8_t* gSlab = g + std::size_t((k0 - lo) * plane) * organValue;
      const std::uint8_t* sSlab = s + std::size_t((k0 - lo) * plane) * partValue;
      const std::uint8_t* gBelow = k0 > 0 ? gSlab - std::size_t(plane) * organValue : nullptr;
      const std::uint8_t* sBelow = k0 > 0 ? sSlab - std::size_t(plane) * partValue : nullptr;
      const std::uint8_t* gAbove =
          k1 < nz ? gSlab + std::size_t((k1 - k0) * plane) * organValue : nullptr;
      const std::uint8_t* sAbove =
          k1 < nz ? sSlab + std::size_t((k1 - k0) * plane) * partValue : nullptr;
      if (rounding) rounding->addSlab(k0, k1, gBelow, gSlab, gAbove);
      field.resize(std::size_t((k1 - k0) * fieldSlabs.sliceFloats()));
      fieldSlabs.rasterize(k0, k1, field.data());
      if (pockets)
        pockets->addSlab(k0, k1, gBelow, gSlab, gAbove, sBelow, sSlab, sAbove, parts.scalarType(),
                         field.data());
      fieldWriter.writeSlices(field.data(), k1 - k0);
      if (imageSlabs) {
        imageBuffer.resize(std::size_t((k1 - k0) * imageSlabs->sliceBytes()));
        imageSlabs->rasterize(k0, k1, imageBuffer.data(), unused);
        imageWriter->writeSlices(imageBuffer.data(), k1 - k0);
      }
      throwIfInterrupted();
    }
    field.clear(), field.shrink_to_fit();
    imageBuffer.clear(), imageBuffer.shrink_to_fit();
    fieldWriter.finish();
    if (imageWriter) imageWriter->finish();

    // The choices every slab waits for.
    if (rounding) rounding->choose(raster);
    if (pockets)
      pocketReport =
          pockets->fill(rounding ? std::function<std::int64_t(std::int64_t, std::int64_t)>(
                                       [&](std::int64_t voxel, std::int64_t sampled) {
                                         return rounding->finalLabel(voxel, sampled);
                                       })
                                 : std::function<std::int64_t(std::int64_t, std::int64_t)>());

    // Pass 2: the labels made again, relabelled, filled, counted and written.
    std::optional<NiftiSlabWriter> niftiG, niftiS;
    std::optional<SegNrrdSlabWriter> segG, segS;
    if (nifti) {
      if (organs.layers() > 1 || parts.layers() > 1)
        throw Error(folder + ": a layered segmentation can only be written as .seg.nrrd");
      niftiG.emplace((temp / "posed_G.nii.gz").string(), grid, organs.scalarType(), organs.labels(),
                     true);
      niftiS.emplace((temp / "posed_S.nii.gz").string(), grid, parts.scalarType(), parts.labels(),
                     true);
    }
    if (seg) {
      segG.emplace((temp / "posed_G.seg.nrrd").string(), grid, organs.scalarType(), organs.layers(),
                   organs.labels());
      segS.emplace((temp / "posed_S.seg.nrrd").string(), grid, parts.scalarType(), parts.layers(),
                   parts.labels());
    }
    std::set<int> presentS;
    for (std::int64_t k0 = 0; k0 < nz; k0 += slab) {
      const std::int64_t k1 = std::min(nz, k0 + slab);
      organBuffer.resize(std::size_t(k1 - k0) * organBytes);
      partBuffer.resize(std::size_t(k1 - k0) * partBytes);
      organSlabs.rasterize(k0, k1, organBuffer.data(), raster,
                           progress(0.5, 1, k0, k1, "rasterize labels"));
      partSlabs.rasterize(k0, k1, partBuffer.data(), unused);
      if (rounding) rounding->apply(k0, k1, organBuffer.data());
      if (pockets) pockets->apply(k0, k1, organBuffer.data(), partBuffer.data());
      posed.add(organBuffer.data(), partBuffer.data(), k0, k1);
      addPresent(partBuffer.data(), parts.scalarType(), (k1 - k0) * plane, presentS);
      if (niftiG) niftiG->writeSlices(organBuffer.data(), k1 - k0);
      if (niftiS) niftiS->writeSlices(partBuffer.data(), k1 - k0);
      if (segG) segG->writeSlices(organBuffer.data(), k1 - k0);
      if (segS) segS->writeSlices(partBuffer.data(), k1 - k0);
      throwIfInterrupted();
    }
    organBuffer.clear(), organBuffer.shrink_to_fit();
    partBuffer.clear(), partBuffer.shrink_to_fit();
    for (auto* w : {&niftiG, &niftiS})
      if (*w) (*w)->finish();
    for (auto* w : {&segG, &segS})
      if (*w) (*w)->finish();
    if (nifti) {
      std::vector<int> presentG;
      for (const auto& [value, voxels] : posed.labelVoxels()) presentG.push_back(value);
      writeColorTable(organs.labels(), presentG, (temp / "posed_G.ctbl").string());
      writeColorTable(parts.labels(), std::vector<int>(presentS.begin(), presentS.end()),
                      (temp / "posed_S.ctbl").string());
    }
  } catch (const Cancelled&) {
    throw;
  } catch (const Error& e) {
    throw out.named(e);
  }
  // G's counts: the writes and shell of pass 2 (each slice once), the rounding's of the choice.
  PoseFrameOptions reportOptions = options;
  reportOptions.labelMapFiles = files;
  std::string text = frameReport(start, rig, organs, parts, reportOptions, raster, pocketReport,
                                 posed, options.image != nullptr);
  if (complete) text = complete(text);
  nlohmann::json report = nlohmann::json::parse(text);
  report["streamed"] = {{"slab_slices", slab},
                        {"slabs", (nz + slab - 1) / slab},
                        {"memory_budget_bytes", memoryBudget}};
  return out.commit(report, write, options.image != nullptr);
}

}  // namespace repose
