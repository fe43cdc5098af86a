// `repose warp --mpi`: the posed label map of one output grid made by the ranks of an MPI job
// (WarpRanks.h), each holding the mesh, the deformation and its own slab of the output, and the
// file written once, together. Out of core on every rank: the input is read in place through a
// slice cache and no rank holds more of the output than its slab.
#include "InputChecks.h"
#include "MemoryBudget.h"
#include "TerminalProgress.h"
#include "WarpRanks.h"
#include "WarpSummary.h"

#include "repose/io/AtomicOutput.h"
#include "repose/io/MeshIO.h"
#include "repose/io/NiftiIO.h"
#include "repose/io/SliceCache.h"
#include "repose/io/VolumeIO.h"
#include "repose/mesh/RigiditySolver.h"
#include "repose/mesh/TransferMesh.h"
#include "repose/util/Error.h"

#include <chrono>
#include <filesystem>
#include <optional>

namespace repose::cli {
int runWarpOverRanks(const ArgParser& p) {
  const auto start = std::chrono::steady_clock::now();
  const std::unique_ptr<WarpRanks> ranks = makeWarpRanks();
  const bool root = ranks->rank() == 0;
  std::string input, out;
  double spacing = 0, budget = 0;
  NiftiLayout layout;
  TransferMesh mesh;
  std::optional<AtomicOutput> outFile;
  Eigen::MatrixX3d deformed;
  int unreachable = 0;
  WarpSummary summary;  // filled on rank 0
  // Every rank checks the request and reads the mesh; rank 0 alone creates the output (so an
  // unwritable one fails before the work) and computes the deformation.
  ranks->together([&] {
    for (const char* required : {"input", "mesh", "cage", "posed-cage", "out"})
      if (!p.has(required)) throw UsageError{std::string("--") + required + " is required"};
    for (const char* other : {"image", "image-out", "transform-out"})
      if (p.has(other))
        throw UsageError{std::string("--mpi poses the label map only; --") + other +
                         " is not available with it"};
    input = p.get("input");
    out = p.get("out");
    if (formatForPath(input) != FileFormat::Nifti)
      throw Error(input +
                  ": --mpi reads the label map in place and needs NIfTI (.nii, .nii.gz); "
                  "convert it with `repose convert`");
    if (formatForPath(out) != FileFormat::Nifti)
      throw Error(out + ": --mpi writes NIfTI (.nii or .nii.gz)");
    for (const char* in : {"input", "mesh", "cage", "posed-cage"})
      refuseOverwritingInput(p.get(in), out);
    spacing = p.getDouble("spacing-mm");
    if (spacing < 0) throw UsageError{"--spacing-mm must be >= 0"};
    budget = rankMemoryBudget(p.get("memory"));
    layout = readNiftiLayout(input);
    if (!isIntegerType(layout.type))
      throw Error(input + ": not a label map (float voxels); pose images with --image");
    mesh = readTransferMesh(p.get("mesh"));
    if (!root) return;
    outFile.emplace(out);
    const TriangleMesh cage = readTriangleMesh(p.get("cage"));
    const TriangleMesh posed = readTriangleMesh(p.get("posed-cage"));
    if (posed.vertices.rows() != cage.vertices.rows() || posed.faces != cage.faces)
      throw Error(p.get("posed-cage") + ": not a pose of " + p.get("cage") +
                  " (vertices or faces differ)");
    const auto deformStart = std::chrono::steady_clock::now();
    const std::string coordinatesFile = warpCoordinatesFile(p);
    const CageDeformation deformation(mesh, cage, static_cast<int>(p.getInt("threads")),
                                      coordinatesFile);
    deformed = deformation.deform(posed.vertices);
    unreachable = deformation.solver().unconstrainedVertices();
    noteWarpCoordinates(deformation, coordinatesFile, summary);
    summary.deformationSeconds =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - deformStart).count();
  });
  // One deformation for all: the ranks' outputs agree to the bit whatever their hardware.
  ranks->broadcast(deformed);
  const VolumeGeometry grid = deformedGrid(layout.geometry, deformed, spacing);
  const std::string path = ranks->broadcast(root ? outFile->tempPath() : std::string());
  const double voxelBytes = double(scalarSize(layout.type));
  const double outBytes = double(grid.numVoxels()) * voxelBytes;

  std::unique_ptr<SliceCache> cache;
  std::unique_ptr<LabelSlabRasterizer> slabs;
  std::vector<std::uint8_t> outer;
  double used = 0, available = 0;
  ranks->together([&] {
    if (root) {
      const auto space = std::filesystem::space(std::filesystem::absolute(out).parent_path());
      if (double(space.available) < outBytes)
        throw Error(out + ": " + gib(outBytes) + " uncompressed would not fit in the " +
                    gib(double(space.available)) + " free on its disk");
    }
    used = peakResidentBytes();
    available = budget - used;
    const double slices16 = 16.0 * double(grid.dims[0] * grid.dims[1]) * voxelBytes;
    if (available < slices16)
      throw Error(out + ": a rank's budget of " + gib(budget) + " leaves " + gib(available) +
                  " beyond the " + gib(used) + " the mesh uses; its slabs need at least " +
                  gib(slices16) + " (16 output slices)");
    cache = std::make_unique<SliceCache>(input, static_cast<std::size_t>(available / 2));
    RasterOptions ro;
    ro.shellMm = p.getDouble("shell-mm");
    outer = outerFaces(mesh);
    ro.outerFaces = &outer;
    slabs = std::make_unique<LabelSlabRasterizer>(*cache, mesh, deformed, grid, ro);
  });
  const auto rasterStart = std::chrono::steady_clock::now();
  const RasterReport report =
      ranks->writeLabels(*slabs, grid, layout, path, static_cast<std::size_t>(available / 4),
                         root ? terminalProgress() : ProgressFn());
  if (!root) return 0;

  const auto countStart = std::chrono::steady_clock::now();
  for (const auto& [value, mm3] : streamedLabelVolumes(*cache))
    summary.volumes[{0, value}].first = mm3;
  const auto end = std::chrono::steady_clock::now();
  auto seconds = [](auto a, auto b) { return std::chrono::duration<double>(b - a).count(); };
  summary.stageSeconds = {{"setup", seconds(start, rasterStart)},
                          {"slabs", seconds(rasterStart, countStart)},
                          {"input_volumes", seconds(countStart, end)}};
  for (const auto& [value, count] : report.labelVoxels)
    summary.volumes[{0, value}].second = double(count) * grid.voxelVolumeMm3();
  outFile->commit();
  summary.input = input;
  summary.out = out;
  summary.labels = layout.labels;
  summary.grid = grid;
  summary.outOfCore = true;
  summary.budget = budget;
  summary.usedBefore = used;
  summary.inCoreNeed = outBytes + double(layout.geometry.numVoxels()) * voxelBytes;
  summary.report = report;
  summary.unreachable = unreachable;
  summary.ranks = ranks->size();
  summary.slabs = ranks->slabs();
  summary.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  printWarpSummary(summary, p.has("json"));
  return 0;
}

}  // namespace repose::cli
