// `repose warp --input G --mesh tm.vtu --cage cage.obj --posed-cage posed.obj --out posed.nii.gz`:
// the full-resolution posed label map (and image) from a posed cage, with per-label volumes
// before and after, so a dosimetry user sees at once whether a tissue lost or gained volume.
#include "ArgParser.h"
#include "StderrLine.h"
#include "Commands.h"
#include "InputChecks.h"
#include "MemoryBudget.h"
#include "SlicerModuleXml.h"
#include "TerminalProgress.h"
#include "WarpSummary.h"

#include "repose/io/AtomicOutput.h"
#include "repose/io/MeshIO.h"
#include "repose/io/NiftiIO.h"
#include "repose/io/NrrdIO.h"
#include "repose/io/SliceCache.h"
#include "repose/io/VolumeIO.h"
#include "repose/mesh/RigiditySolver.h"
#include "repose/mesh/TransferMesh.h"
#include "repose/pose/PoseFrame.h"
#include "repose/raster/RasterFile.h"
#include "repose/raster/Rasterizer.h"
#include "repose/util/Error.h"
#include "repose/volume/LabelStatistics.h"

#include <nlohmann/json.hpp>

#include <unistd.h>

#include <chrono>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <optional>
#include <iostream>
#include <map>
#include <sstream>

namespace repose::cli {

std::map<int, double> streamedLabelVolumes(SliceCache& cache) {
  const NiftiLayout& l = cache.layout();
  const std::int64_t n = l.geometry.dims[0] * l.geometry.dims[1];
  const double voxelMm3 = l.geometry.voxelVolumeMm3();
  std::map<int, std::int64_t> counts;
  dispatchScalar(l.type, [&](auto* tag) {
    using T = std::remove_pointer_t<decltype(tag)>;
    for (std::int64_t k = 0; k < l.geometry.dims[2]; ++k) {
      const T* v = static_cast<const T*>(cache.slice(k));
      for (std::int64_t i = 0; i < n; ++i)
        if (v[i] != 0) ++counts[static_cast<int>(v[i])];
    }
  });
  std::map<int, double> mm3;
  for (const auto& [value, count] : counts) mm3[value] = double(count) * voxelMm3;
  return mm3;
}

void printWarpSummary(const WarpSummary& s, bool json) {
  const auto& volumes = s.volumes;
  const auto& report = s.report;
  const auto& grid = s.grid;
  // Per-label volumes before and after (layer 0 and others alike).
  nlohmann::json perLabel = nlohmann::json::array();
  int lost = 0;
  std::vector<int> unnamed;  // labels with voxels that a label table present does not name
  for (const auto& [key, v] : volumes) {
    const Label* l = s.labels.find(key.second, key.first);
    perLabel.push_back({{"layer", key.first},
                        {"value", key.second},
                        {"name", l ? l->name : ""},
                        {"input_mm3", v.first},
                        {"output_mm3", v.second},
                        {"change_percent", v.first > 0 ? 100 * (v.second / v.first - 1) : 0.0}});
    lost += v.first > 0 && v.second == 0;
    if (!l && !s.labels.empty() && v.first > 0 && key.second != 0) unnamed.push_back(key.second);
  }
  warnUnnamedLabels(unnamed, s.input, "warp");
  nlohmann::json j = {{"output", s.out},
                      {"dims", {grid.dims[0], grid.dims[1], grid.dims[2]}},
                      {"spacing_mm", {grid.spacing()[0], grid.spacing()[1], grid.spacing()[2]}},
                      {"voxels", grid.numVoxels()},
                      {"out_of_core", s.outOfCore},
                      {"memory_budget_bytes", s.budget},
                      {"memory_in_use_before_volumes_bytes", s.usedBefore},
                      {"memory_volumes_need_in_core_bytes", s.inCoreNeed},
                      {"peak_resident_bytes", peakResidentBytes()},
                      {"voxels_inside_tets", report.voxelWrites},
                      {"voxels_in_shell", report.shellVoxels},
                      {"inverted_tets", report.invertedTets},
                      {"flat_tets", report.flatTets},
                      {"unreachable_vertices_left_at_rest", s.unreachable},
                      {"labels_lost", lost},
                      {"labels_unnamed", unnamed},
                      {"labels", perLabel},
                      {"seconds", s.seconds}};
  j["green_coordinates"] = {{"read", s.coordinatesRead}, {"note", s.coordinatesNote}};
  j["deformation_seconds"] = s.deformationSeconds;
  if (s.slabs > 0)
    j["mpi"] = {{"ranks", s.ranks}, {"slabs", s.slabs}, {"stage_seconds", s.stageSeconds}};
  if (json) {
    std::cout << j.dump(2) << "\n";
  } else {
    std::cout << "wrote " << s.out << ": " << grid.dims[0] << " x " << grid.dims[1] << " x "
              << grid.dims[2] << " voxels\n";
    for (const auto& l : perLabel)
      std::cout << "  label " << l["value"].get<int>() << " " << l["name"].get<std::string>()
                << ": " << l["input_mm3"].get<double>() / 1000 << " -> "
                << l["output_mm3"].get<double>() / 1000 << " cm3\n";
    if (report.invertedTets > 0)
      std::cout << "warning: " << report.invertedTets
                << " tets turned inside out (the pose folds the body there)\n";
    if (lost > 0) std::cout << "warning: " << lost << " labels vanished from the output\n";
    if (s.unreachable > 0)
      std::cout << "warning: " << s.unreachable
                << " mesh vertices in parts with no vertex inside the cage were left at rest\n";
  }
}

std::string warpCoordinatesFile(const ArgParser& p) {
  return p.has("coordinates") ? p.get("coordinates") : greenCoordinatesFileFor(p.get("mesh"));
}

void noteWarpCoordinates(const CageDeformation& deformation, const std::string& coordinatesFile,
                         WarpSummary& summary) {
  summary.coordinatesRead = deformation.coordinatesRead();
  summary.coordinatesNote = deformation.coordinatesNote();
  std::error_code ec;
  if (!summary.coordinatesRead && std::filesystem::exists(coordinatesFile, ec))
    stderrLine("repose warp: note: Green coordinates computed again: " + summary.coordinatesNote);
}

int runWarp(const Args& args) {
  if (printSlicerModuleXml(args, "warp")) return 0;  // 3D Slicer asking for the description
  ArgParser p(
      "warp",
      "Pose a label map: deform the transfer mesh with a posed cage (Green coordinates\n"
      "and the rigidity solver) and rasterize it at full resolution. The output grid keeps\n"
      "the input's axes and spacing (or --spacing-mm) and grows to hold the whole posed\n"
      "body. Prints per-label volumes before and after.");
  p.option("input", "FILE", "label map G to pose (NIfTI, NRRD, .seg.nrrd)")
      .option("mesh", "FILE", "transfer mesh from `repose mesh` (.vtu)")
      .option("cage", "FILE", "the cage the mesh was built with (.obj or .vtk)")
      .option("posed-cage", "FILE", "the same cage, posed (same vertices and faces)")
      .option("coordinates", "FILE",
              "the mesh's Green coordinates (default: beside --mesh, tm.vtu -> tm.green, as "
              "`repose mesh` and scene folders write them); computed when absent or not for "
              "this mesh and cage")
      .option("out", "FILE", "posed label map")
      .option("image", "FILE", "optional intensity image on G's grid, posed alongside")
      .option("image-out", "FILE", "posed image (with --image)")
      .option("background", "VALUE",
              "image value where no tissue is (with --image): a number, or min for the image's "
              "minimum (air in a CT)",
              "min")
      .option("transform-out", "FILE",
              "displacement-field transform (.nrrd, LPS, output->input as ITK and Slicer use)")
      .option("spacing-mm", "MM", "output voxel size along every axis (0: the input's)", "0")
      .option("shell-mm", "MM",
              "extrapolate this far outside the mesh (-1: two voxels of G or of the grid the mesh "
              "was built on, whichever is coarser)",
              "-1")
      .option("threads", "N", "worker threads (0: all cores)", "0")
      .flag("json", "print a JSON summary on stdout")
      .flag("slicer-progress",
            "progress as the <filter-progress> lines 3D Slicer's CLI modules print on stdout "
            "(the installed ReposeWarp module sets it)")
      .flag("mpi",
            "under mpirun: rasterize the output grid in slabs over the ranks and write one NIfTI "
            "with MPI-IO (out of core on every rank; --memory is per rank; NIfTI in and out)");
  declareMemoryOption(p, "above it the posed volume is made out of core (NIfTI in and out)");
  if (!p.parse(args)) return 0;
  if (p.has("mpi")) return runWarpOverRanks(p);
  if (p.has("slicer-progress")) startSlicerProgress("repose warp", "warping " + p.get("input"));
  for (const char* required : {"input", "mesh", "cage", "posed-cage", "out"})
    if (!p.has(required)) throw UsageError{std::string("--") + required + " is required"};
  const std::optional<double> background = p.getDoubleUnless("background", "min");
  if (p.has("image") != p.has("image-out")) throw UsageError{"--image and --image-out go together"};
  const std::string out = p.get("out");
  const std::string transformOut = p.has("transform-out") ? p.get("transform-out") : "";
  if (!transformOut.empty() &&
      (transformOut.size() < 5 || transformOut.compare(transformOut.size() - 5, 5, ".nrrd") != 0))
    throw UsageError{"--transform-out must name a .nrrd file"};
  for (const auto& [a, b] : {std::pair<const char*, const char*>{"out", "image-out"},
                             {"out", "transform-out"},
                             {"image-out", "transform-out"}})
    if (p.has(a) && p.has(b) &&
        std::filesystem::absolute(p.get(a)) == std::filesystem::absolute(p.get(b)))
      throw UsageError{std::string("--") + a + " and --" + b + " name the same file"};
  for (const char* in : {"input", "mesh", "cage", "posed-cage", "image"})
    if (p.has(in))
      for (const char* o : {"out", "image-out", "transform-out"})
        if (p.has(o)) refuseOverwritingInput(p.get(in), p.get(o));
  const double spacing = p.getDouble("spacing-mm");
  if (spacing < 0) throw UsageError{"--spacing-mm must be >= 0"};
  const double budget = parseMemoryBudget(p.get("memory"));
  // Every output is written into its own temporary folder and all are published together at the
  // end (commitTogether): an interrupted or failed run leaves none of them. Unwritable outputs
  // fail here, before the work.
  AtomicOutput outFile(out);
  std::optional<AtomicOutput> imageFile, transformFile;
  if (p.has("image-out")) imageFile.emplace(p.get("image-out"));
  if (!transformOut.empty()) transformFile.emplace(transformOut);
  const auto start = std::chrono::steady_clock::now();

  // The input's grid and type first: its voxels are read in core only if they fit the budget.
  const std::string input = p.get("input");
  const bool niftiInput = formatForPath(input) == FileFormat::Nifti;
  std::optional<Volume> labels;
  NiftiLayout layout;
  if (niftiInput) {
    layout = readNiftiLayout(input);
  } else {
    labels = readVolume(input, readOptionsWithin(budget, false));
    layout.geometry = labels->geometry(), layout.type = labels->scalarType();
    layout.labels = labels->labels();
  }
  if (!isIntegerType(layout.type))
    throw Error(input + ": not a label map (float voxels); pose images with --image");
  const int layers = labels ? labels->layers() : 1;
  const TransferMesh mesh = readTransferMesh(p.get("mesh"));
  const TriangleMesh cage = readTriangleMesh(p.get("cage"));
  const TriangleMesh posed = readTriangleMesh(p.get("posed-cage"));
  if (posed.vertices.rows() != cage.vertices.rows() || posed.faces != cage.faces)
    throw Error(p.get("posed-cage") + ": not a pose of " + p.get("cage") +
                " (vertices or faces differ)");
  const int threads = static_cast<int>(p.getInt("threads"));
  const auto deformStart = std::chrono::steady_clock::now();
  const std::string coordinatesFile = warpCoordinatesFile(p);
  const CageDeformation deformation(mesh, cage, threads, coordinatesFile, terminalProgress());
  const Eigen::MatrixX3d deformed = deformation.deform(posed.vertices);
  const double deformationSeconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - deformStart).count();
  const VolumeGeometry grid = deformedGrid(layout.geometry, deformed, spacing);

  // What the volumes need against what the budget leaves after the mesh and cage (the process's
  // peak so far): in core if both fit, else out of core, else refuse before the work.
  const double voxelBytes = double(scalarSize(layout.type)) * layers;
  const double outBytes = double(grid.numVoxels()) * voxelBytes;
  // (A non-NIfTI input is already read: its bytes are in the peak below.)
  const double inBytes = labels ? 0.0 : double(layout.geometry.numVoxels()) * voxelBytes;
  // In core, --image holds the image and its posed copy (up to 4 bytes a voxel each) and
  // --transform-out the field (3 floats an output voxel) beside the label maps.
  const double imageBytes =
      p.has("image") ? 4.0 * double(layout.geometry.numVoxels() + grid.numVoxels()) : 0.0;
  const double fieldBytes = p.has("transform-out") ? 12.0 * double(grid.numVoxels()) : 0.0;
  const double used = peakResidentBytes();
  const double available = budget - used;
  const double inCoreNeed = inBytes + outBytes + imageBytes + fieldBytes;
  const bool inCore = inCoreNeed <= available;
  const bool niftiOutput = formatForPath(out) == FileFormat::Nifti;
  if (!inCore) {
    const std::string why = out + ": posing in memory needs " + gib(inCoreNeed) + " (" +
                            std::to_string(grid.numVoxels()) + " output voxels) beyond the " +
                            gib(used) + " the mesh and cage use, more than the budget of " +
                            gib(budget);
    if (!niftiInput || !niftiOutput || layers > 1)
      throw Error(why + "; out of core needs NIfTI in and out");
    if (p.has("image") || p.has("transform-out"))
      throw Error(why + "; --image and --transform-out are not available out of core yet");
    if (available < 16.0 * double(grid.dims[0] * grid.dims[1]) * voxelBytes)
      throw Error(why + ", even out of core");
  }
  const auto space = std::filesystem::space(std::filesystem::absolute(out).parent_path());
  if (double(space.available) < outBytes)
    throw Error(out + ": " + gib(outBytes) + " uncompressed would not fit in the " +
                gib(double(space.available)) + " free on its disk");

  RasterOptions ro;
  ro.threads = threads;
  ro.shellMm = p.getDouble("shell-mm");
  ro.progress = terminalProgress();
  const std::vector<std::uint8_t> outer = outerFaces(mesh);
  ro.outerFaces = &outer;
  RasterReport report;
  std::map<std::pair<int, int>, std::pair<double, double>> volumes;  // (layer, value) -> mm3
  if (inCore) {
    if (!labels) labels = readVolume(input, readOptionsWithin(budget, false));
    const Volume posedLabels = rasterizeLabels(*labels, mesh, deformed, grid, ro, &report);
    if (p.has("image")) {
      const Volume image = readVolume(p.get("image"), readOptionsWithin(budget, false));
      const Volume posedImage = rasterizeImage(
          image, mesh, deformed, grid, background ? *background : imageBackground(image), ro);
      writeVolume(posedImage, imageFile->tempPath());
    }
    if (p.has("transform-out"))
      writeDisplacementFieldNrrd(
          rasterizeDisplacement(mesh, deformed, labels->geometry(), grid, ro), grid,
          transformFile->tempPath());
    writeVolume(posedLabels, outFile.tempPath());
    for (const LabelCount& c : countLabels(*labels))
      volumes[{c.layer, c.value}].first = c.volumeMm3;
    for (const LabelCount& c : countLabels(posedLabels))
      volumes[{c.layer, c.value}].second = c.volumeMm3;
  } else {
    SliceCache cache(input, static_cast<std::size_t>(available / 2));
    rasterizeLabelsToFile(cache, mesh, deformed, grid, outFile.tempPath(),
                          static_cast<std::size_t>(available / 4), ro, &report);
    for (const auto& [value, mm3] : streamedLabelVolumes(cache)) volumes[{0, value}].first = mm3;
    const double voxelMm3 = grid.voxelVolumeMm3();
    for (const auto& [value, count] : report.labelVoxels)
      volumes[{0, value}].second = double(count) * voxelMm3;
  }
  commitTogether(
      {&outFile, imageFile ? &*imageFile : nullptr, transformFile ? &*transformFile : nullptr});
  WarpSummary summary;
  summary.input = input;
  summary.out = out;
  summary.labels = layout.labels;
  summary.grid = grid;
  summary.outOfCore = !inCore;
  summary.budget = budget;
  summary.usedBefore = used;
  summary.inCoreNeed = inCoreNeed;
  summary.report = report;
  summary.unreachable = deformation.solver().unconstrainedVertices();
  noteWarpCoordinates(deformation, coordinatesFile, summary);
  summary.deformationSeconds = deformationSeconds;
  summary.volumes = volumes;
  summary.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  printWarpSummary(summary, p.has("json"));
  endSlicerProgress("repose warp");
  return 0;
}

}  // namespace repose::cli
