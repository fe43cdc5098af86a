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
#include "repose/io/DicomSegIO.h"
#include "repose/io/NiftiIO.h"
#include "repose/io/NrrdIO.h"
#include "repose/util/Interrupt.h"
#include "repose/util/Memory.h"

#include <Eigen/Core>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <optional>
#include <set>
#include <tuple>

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

// Rounded up to 8 bytes: where the next part of a slab's bytes starts (a float field aligned).
std::size_t aligned(std::size_t bytes) {
  return (bytes + 7) & ~std::size_t(7);
}

// `bytes` resized to `n` without a copy of what it held (the caller overwrites it all): grown, it
// is released first and made room for `atLeast`, so a slab a slice larger than the last does not
// hold both buffers at once while it moves.
void resizeForSlab(std::vector<std::uint8_t>& bytes, std::size_t n, std::size_t atLeast) {
  if (bytes.capacity() < n) {
    std::vector<std::uint8_t>().swap(bytes);
    bytes.reserve(std::max(n, atLeast));
  }
  bytes.resize(n);
}

// A slab's raster counts after its voxels (pass 2): writes, shell, the mesh's tet counts, and
// the voxels of each label, as int64s.
void appendCounts(const RasterReport& counts, std::vector<std::uint8_t>& bytes) {
  std::vector<std::int64_t> v{counts.voxelWrites, counts.shellVoxels, counts.invertedTets,
                              counts.flatTets};
  for (const auto& [value, voxels] : counts.labelVoxels) v.push_back(value), v.push_back(voxels);
  const std::size_t at = bytes.size();
  bytes.resize(at + v.size() * sizeof(std::int64_t));
  std::memcpy(bytes.data() + at, v.data(), v.size() * sizeof(std::int64_t));
}

// Adds the counts appendCounts put at byte `at` to `report`, as LabelSlabs::rasterize adds a
// slab's (the tet counts are the mesh's: the last slab's stand).
void addCounts(const std::vector<std::uint8_t>& bytes, std::size_t at, RasterReport& report) {
  std::vector<std::int64_t> v((bytes.size() - at) / sizeof(std::int64_t));
  std::memcpy(v.data(), bytes.data() + at, v.size() * sizeof(std::int64_t));
  report.voxelWrites += v.at(0);
  report.shellVoxels += v.at(1);
  report.invertedTets = int(v.at(2));
  report.flatTets = int(v.at(3));
  for (std::size_t i = 4; i + 1 < v.size(); i += 2) report.labelVoxels[int(v[i])] += v[i + 1];
}

// Rank 0's posed mesh and output grid on every rank: the ranks' slabs agree to the bit whatever
// their hardware and threads.
void shareStart(SlabRanks& ranks, frame::FrameStart& start) {
  Eigen::MatrixX3d& deformed = start.frame.deformed;
  std::vector<std::uint8_t> bytes;
  if (ranks.root()) {
    const std::int64_t rows = deformed.rows();
    const std::size_t matrix = sizeof(double) * 16, mesh = sizeof(double) * 3 * std::size_t(rows);
    bytes.resize(sizeof(std::int64_t) * 4 + matrix + mesh);
    std::uint8_t* at = bytes.data();
    for (std::int64_t v : {rows, start.grid.dims[0], start.grid.dims[1], start.grid.dims[2]})
      std::memcpy(at, &v, sizeof v), at += sizeof v;
    std::memcpy(at, start.grid.ijkToRas.data(), matrix), at += matrix;
    std::memcpy(at, deformed.data(), mesh);
  }
  ranks.broadcast(bytes);
  if (ranks.root()) return;
  const std::uint8_t* at = bytes.data();
  std::int64_t v[4];
  std::memcpy(v, at, sizeof v), at += sizeof v;
  for (int a = 0; a < 3; ++a) start.grid.dims[std::size_t(a)] = v[a + 1];
  std::memcpy(start.grid.ijkToRas.data(), at, sizeof(double) * 16), at += sizeof(double) * 16;
  deformed.resize(v[0], 3);
  std::memcpy(deformed.data(), at, sizeof(double) * 3 * std::size_t(v[0]));
}

}  // namespace

std::string poseFrameToFolder(const PoseRig& rig, std::size_t index, const Volume& organs,
                              const Volume& parts, const PoseFrameOptions& options,
                              const std::string& folder, const FrameWriteOptions& write,
                              double memoryBudget, std::int64_t slabSlices, SlabRanks* ranks) {
  frame::FrameStart start = frame::startFrame(rig, index, organs, parts, options);
  if (options.checkGrid) options.checkGrid(start.grid);
  return frame::poseFrameToFolderFrom(start, rig, organs, parts, options, folder, write,
                                      memoryBudget, slabSlices, {}, ranks);
}

std::string frame::poseFrameToFolderFrom(
    FrameStart& start, const PoseRig& rig, const Volume& organs, const Volume& parts,
    const PoseFrameOptions& options, const std::string& folder, const FrameWriteOptions& write,
    double memoryBudget, std::int64_t slabSlices,
    const std::function<std::string(const std::string&)>& complete, SlabRanks* ranksOrNull) {
  std::unique_ptr<SlabRanks> alone;
  SlabRanks& ranks = ranksOrNull ? *ranksOrNull : *(alone = oneSlabRank());
  const bool root = ranks.root(), several = ranks.size() > 1;
  const LabelMapFiles files = write.labelMapFiles;
  // A DICOM SEG beyond its format's 4 GiB is said before the work.
  nlohmann::json dicomSeg;
  ranks.together([&] {
    if (root && files == LabelMapFiles::DicomSeg)
      dicomSeg = frame::checkDicomSegFits(start, rig.mesh(), organs, parts, folder);
  });
  if (several) shareStart(ranks, start);
  const TransferMesh& mesh = rig.mesh();
  const Eigen::MatrixX3d& deformed = start.frame.deformed;
  const VolumeGeometry& grid = start.grid;
  const std::int64_t nz = grid.dims[2], plane = grid.dims[0] * grid.dims[1];
  RasterOptions ro;
  std::optional<LabelSlabs> organSlabs, partSlabs;
  std::optional<DisplacementSlabs> fieldSlabs;
  std::optional<ImageSlabs> imageSlabs;
  // Rank 0's: the ordered steps and the files.
  std::optional<LabelSlabRounding> rounding;
  std::optional<PosePockets> pockets;
  std::optional<PosedTally> posed;
  std::optional<FrameFolder> out;
  std::int64_t slab = 0;
  if (memoryBudget <= 0) memoryBudget = memoryBudgetByDefault();
  ranks.together([&] {
    ro = frame::rasterOptions(start, organs, parts, options);
    organSlabs.emplace(organs, mesh, deformed, grid, ro);
    partSlabs.emplace(parts, mesh, deformed, grid, ro);
    fieldSlabs.emplace(mesh, deformed, organs.geometry(), grid, ro);
    if (options.image)
      imageSlabs.emplace(*options.image, mesh, deformed, grid,
                         options.background ? *options.background : imageBackground(*options.image),
                         ro);
    // What is free once the scans are set up (the pieces' owners, the shells' coverage: arrays
    // on the input's grid) decides the slabs' size; over ranks a maker holds two slabs (one
    // on its way to rank 0) and rank 0 one it uses and one it receives.
    const double freeBytes = memoryBudget > 0 ? memoryBudget - residentBytes() : 8.0 * (1 << 30);
    slab = slabSlices > 0
               ? std::min(slabSlices, nz)
               : slabsFor(grid, organs, parts, options.image, several ? freeBytes / 2 : freeBytes);
    // At least a slab of one slice with the slices beside it must fit beside what is held.
    const double oneSlab = double(plane) *
                           (3 * posedBytesPerVoxel(organs, parts, options.image) + 12) *
                           (several ? 2 : 1);
    if (memoryBudget > 0 && freeBytes < oneSlab)
      throw Error(folder + ": frame " + start.frame.name + " needs " + gib(oneSlab) +
                  " for a slab of one slice beside the " + gib(residentBytes()) +
                  " in use, more than the memory budget of " + gib(memoryBudget) +
                  " (--memory; the rig and the rest maps stay in memory)");
    if (!root) return;
    // The rounding's candidates beyond a quarter of what is free go to a temporary file.
    if (options.preserveLabelVolumes)
      rounding.emplace(*organSlabs, std::size_t(std::max(0.0, 0.25 * freeBytes)));
    if (options.fillPockets) pockets.emplace(organs, grid, frame::rigidLabels(mesh, options));
    posed.emplace(organs, parts, &start.frame.handles, grid, options.threads);
    posed->countCollisions(frame::rigidLabels(mesh, options));
    out.emplace(folder, write.lockFolder);
  });
  // The same slabs on every rank; over ranks at least eight per maker, so that rank 0 uses one
  // while the makers make the next.
  slab = ranks.minimum(slab);
  if (several) slab = std::min(slab, std::max<std::int64_t>(1, nz / (8 * (ranks.size() - 1))));
  const std::int64_t count = (nz + slab - 1) / slab;
  auto slices = [&](std::int64_t s) {
    return std::pair<std::int64_t, std::int64_t>(s * slab, std::min(nz, (s + 1) * slab));
  };
  // Rank 0's steps name a writer's file where the user will look for it.
  auto named = [&](const std::function<void()>& step) {
    try {
      step();
    } catch (const Error& e) {
      throw out->named(e);
    }
  };
  const std::filesystem::path temp = root ? out->temp() : std::filesystem::path();
  const bool nifti = files == LabelMapFiles::Nifti || files == LabelMapFiles::Both;
  const bool seg = files == LabelMapFiles::SegNrrd || files == LabelMapFiles::Both;
  // Progress: within each slab as it is made when alone, else as rank 0 uses each slab.
  auto progress = [&](double from, double to, std::int64_t k0, std::int64_t k1) -> ProgressFn {
    if (!options.progress || several) return {};
    return [&, from, to, k0, k1](double f, const std::string&) {
      const double done = (double(k0) + f * double(k1 - k0)) / double(nz);
      return options.progress(from + (to - from) * done, "rasterize labels");
    };
  };
  auto used = [&](double from, double to, std::int64_t k1) {
    if (several && options.progress &&
        !options.progress(from + (to - from) * double(k1) / double(nz), "rasterize labels"))
      throw Cancelled();
    throwIfInterrupted();
  };
  const std::size_t organBytes = std::size_t(organSlabs->sliceBytes()),
                    partBytes = std::size_t(partSlabs->sliceBytes());
  const std::size_t organValue = scalarSize(organs.scalarType()),
                    partValue = scalarSize(parts.scalarType());
  RasterReport raster;
  PocketReport pocketReport;

  // Pass 1: the labels as sampled (with the slices beside them), the field and the image. A
  // slab's bytes: G's and S's slices [lo, hi), the field's and the image's [k0, k1).
  std::optional<DisplacementFieldNrrdWriter> fieldWriter;
  std::optional<NiftiSlabWriter> imageWriter;
  ranks.together([&] {
    if (root)
      named([&] {
        fieldWriter.emplace(grid, (temp / "transform.nrrd").string());
        if (options.image)
          imageWriter.emplace((temp / "posed_image.nii.gz").string(), grid,
                              options.image->scalarType(), LabelTable(), false);
      });
  });
  struct Pass1Slab {
    std::int64_t k0, k1, lo, hi;
    std::size_t s, field, image, end;  // byte offsets of S, the field, the image; the size
  };
  auto pass1Layout = [&](std::int64_t s) {
    Pass1Slab l{};
    std::tie(l.k0, l.k1) = slices(s);
    l.lo = std::max<std::int64_t>(0, l.k0 - 1), l.hi = std::min(nz, l.k1 + 1);
    l.s = aligned(std::size_t(l.hi - l.lo) * organBytes);
    l.field = aligned(l.s + std::size_t(l.hi - l.lo) * partBytes);
    l.image =
        aligned(l.field + std::size_t((l.k1 - l.k0) * fieldSlabs->sliceFloats()) * sizeof(float));
    l.end = l.image + (imageSlabs ? std::size_t((l.k1 - l.k0) * imageSlabs->sliceBytes()) : 0);
    return l;
  };
  ranks.pipeline(
      count,
      [&](std::int64_t s, std::vector<std::uint8_t>& bytes) {
        const Pass1Slab l = pass1Layout(s);
        resizeForSlab(bytes, l.end, pass1Layout(std::min(s + 1, count - 1)).end);
        RasterReport unused;
        organSlabs->rasterize(l.lo, l.hi, bytes.data(), unused, progress(0, 0.5, l.k0, l.k1));
        partSlabs->rasterize(l.lo, l.hi, bytes.data() + l.s, unused);
        fieldSlabs->rasterize(l.k0, l.k1, reinterpret_cast<float*>(bytes.data() + l.field));
        if (imageSlabs) imageSlabs->rasterize(l.k0, l.k1, bytes.data() + l.image, unused);
        throwIfInterrupted();
      },
      [&](std::int64_t s, std::vector<std::uint8_t>& bytes) {
        const Pass1Slab l = pass1Layout(s);
        const std::int64_t k0 = l.k0, k1 = l.k1;
        // Layer 0 of slices [lo, hi): the slab at k0 - lo, the slices beside it.
        const std::uint8_t* gSlab = bytes.data() + std::size_t((k0 - l.lo) * plane) * organValue;
        const std::uint8_t* sSlab =
            bytes.data() + l.s + std::size_t((k0 - l.lo) * plane) * partValue;
        const std::uint8_t* gBelow = k0 > 0 ? gSlab - std::size_t(plane) * organValue : nullptr;
        const std::uint8_t* sBelow = k0 > 0 ? sSlab - std::size_t(plane) * partValue : nullptr;
        const std::uint8_t* gAbove =
            k1 < nz ? gSlab + std::size_t((k1 - k0) * plane) * organValue : nullptr;
        const std::uint8_t* sAbove =
            k1 < nz ? sSlab + std::size_t((k1 - k0) * plane) * partValue : nullptr;
        const float* field = reinterpret_cast<const float*>(bytes.data() + l.field);
        if (rounding) rounding->addSlab(k0, k1, gBelow, gSlab, gAbove);
        if (pockets)
          pockets->addSlab(k0, k1, gBelow, gSlab, gAbove, sBelow, sSlab, sAbove, parts.scalarType(),
                           field);
        named([&] {
          fieldWriter->writeSlices(field, k1 - k0);
          if (imageWriter) imageWriter->writeSlices(bytes.data() + l.image, k1 - k0);
        });
        used(0, 0.5, k1);
      });

  // The choices every slab waits for; pass 2's files.
  std::optional<NiftiSlabWriter> niftiG, niftiS;
  std::optional<SegNrrdSlabWriter> segG, segS;
  std::optional<DicomSegSlabWriter> dcmG, dcmS;
  ranks.together([&] {
    if (!root) return;
    named([&] {
      fieldWriter->finish();
      if (imageWriter) imageWriter->finish();
    });
    fieldWriter.reset(), imageWriter.reset();
    if (rounding) rounding->choose(raster);
    if (pockets)
      pocketReport =
          pockets->fill(rounding ? std::function<std::int64_t(std::int64_t, std::int64_t)>(
                                       [&](std::int64_t voxel, std::int64_t sampled) {
                                         return rounding->finalLabel(voxel, sampled);
                                       })
                                 : std::function<std::int64_t(std::int64_t, std::int64_t)>());
    named([&] {
      if (nifti) {
        if (organs.layers() > 1 || parts.layers() > 1)
          throw Error(folder + ": a layered segmentation can only be written as .seg.nrrd");
        niftiG.emplace((temp / "posed_G.nii.gz").string(), grid, organs.scalarType(),
                       organs.labels(), true);
        niftiS.emplace((temp / "posed_S.nii.gz").string(), grid, parts.scalarType(), parts.labels(),
                       true);
      }
      if (seg) {
        segG.emplace((temp / "posed_G.seg.nrrd").string(), grid, organs.scalarType(),
                     organs.layers(), organs.labels());
        segS.emplace((temp / "posed_S.seg.nrrd").string(), grid, parts.scalarType(), parts.layers(),
                     parts.labels());
      }
      if (files == LabelMapFiles::DicomSeg) {
        DicomSegWriteOptions d;
        d.sourceDicom = write.sourceDicom;
        dcmG.emplace((temp / "posed_G.dcm").string(), grid, organs.scalarType(), organs.layers(),
                     organs.labels(), d);
        dcmS.emplace((temp / "posed_S.dcm").string(), grid, parts.scalarType(), parts.layers(),
                     parts.labels(), d);
      }
    });
  });

  // Pass 2: the labels made again, relabelled, filled, counted and written. A slab's bytes: G's
  // slices, S's, then G's raster counts (RasterCounts).
  std::set<int> presentS;
  ranks.pipeline(
      count,
      [&](std::int64_t s, std::vector<std::uint8_t>& bytes) {
        const std::int64_t k0 = slices(s).first, k1 = slices(s).second;
        const std::size_t g = std::size_t(k1 - k0) * organBytes,
                          sEnd = aligned(g + std::size_t(k1 - k0) * partBytes);
        // (Room for the counts after the voxels, a few labels' worth.)
        resizeForSlab(bytes, sEnd, sEnd + 4096);
        RasterReport counts;
        organSlabs->rasterize(k0, k1, bytes.data(), counts, progress(0.5, 1, k0, k1));
        RasterReport unused;  // the report counts G's voxels
        partSlabs->rasterize(k0, k1, bytes.data() + g, unused);
        appendCounts(counts, bytes);
        throwIfInterrupted();
      },
      [&](std::int64_t s, std::vector<std::uint8_t>& bytes) {
        const std::int64_t k0 = slices(s).first, k1 = slices(s).second;
        const std::size_t g = std::size_t(k1 - k0) * organBytes,
                          sEnd = aligned(g + std::size_t(k1 - k0) * partBytes);
        addCounts(bytes, sEnd, raster);
        std::uint8_t* organSlab = bytes.data();
        std::uint8_t* partSlab = bytes.data() + g;
        if (rounding) rounding->apply(k0, k1, organSlab);
        if (pockets) pockets->apply(k0, k1, organSlab, partSlab);
        posed->add(organSlab, partSlab, k0, k1);
        addPresent(partSlab, parts.scalarType(), (k1 - k0) * plane, presentS);
        named([&] {
          if (niftiG) niftiG->writeSlices(organSlab, k1 - k0);
          if (niftiS) niftiS->writeSlices(partSlab, k1 - k0);
          if (segG) segG->writeSlices(organSlab, k1 - k0);
          if (segS) segS->writeSlices(partSlab, k1 - k0);
          if (dcmG) dcmG->writeSlices(organSlab, k1 - k0);
          if (dcmS) dcmS->writeSlices(partSlab, k1 - k0);
        });
        used(0.5, 1, k1);
      });

  std::string text;
  ranks.together([&] {
    if (!root) return;
    named([&] {
      for (auto* w : {&niftiG, &niftiS})
        if (*w) (*w)->finish();
      for (auto* w : {&segG, &segS})
        if (*w) (*w)->finish();
      for (auto* w : {&dcmG, &dcmS})
        if (*w) (*w)->finish();
      niftiG.reset(), niftiS.reset(), segG.reset(), segS.reset();  // their side files go
      dcmG.reset(), dcmS.reset();
      if (nifti) {
        std::vector<int> presentG;
        for (const auto& [value, voxels] : posed->labelVoxels()) presentG.push_back(value);
        writeColorTable(organs.labels(), presentG, (temp / "posed_G.ctbl").string());
        writeColorTable(parts.labels(), std::vector<int>(presentS.begin(), presentS.end()),
                        (temp / "posed_S.ctbl").string());
      }
    });
    // G's counts: the writes and shell of pass 2 (each slice once), the rounding's of the choice.
    PoseFrameOptions reportOptions = options;
    reportOptions.labelMapFiles = files;
    text = frameReport(start, rig, organs, parts, reportOptions, raster, pocketReport, *posed,
                       options.image != nullptr);
    if (complete) text = complete(text);
    nlohmann::json report = nlohmann::json::parse(text);
    if (!dicomSeg.is_null()) report["dicom_seg"] = dicomSeg;
    report["streamed"] = {{"slab_slices", slab},
                          {"slabs", count},
                          {"ranks", ranks.size()},
                          {"memory_budget_bytes", memoryBudget}};
    text = out->commit(report, write, options.image != nullptr);
  });
  return text;
}

}  // namespace repose
