// `repose cage --parts S --out cage.obj|.vtk`: the control cage around the body, with optional
// limb separation, and the checks and enclosed fraction that say whether it can be trusted.
#include "ArgParser.h"
#include "SeparationOptions.h"
#include "Commands.h"
#include "InputChecks.h"
#include "MemoryBudget.h"
#include "TerminalProgress.h"

#include "repose/cage/CageBuilder.h"
#include "repose/io/AtomicOutput.h"
#include "repose/io/MeshIO.h"
#include "repose/io/VolumeIO.h"
#include "repose/util/Error.h"

#include <nlohmann/json.hpp>

#include <chrono>
#include <iostream>

namespace repose::cli {

int runCage(const Args& args) {
  ArgParser p("cage",
              "Build the control cage: the body (non-zero voxels of PARTS) dilated by an exact\n"
              "Euclidean distance, meshed as a restricted Delaunay surface and simplified with\n"
              "quadric error metrics. With --separate A:B --region ..., the cage passes between\n"
              "body parts A and B inside the region (e.g. a hand glued to the hip).");
  p.option("parts", "FILE", "body-part map S (or any label map; non-zero is body)")
      .option("out", "FILE", "output cage, .obj or .vtk (RAS mm)")
      .option("vertices", "N", "target number of cage vertices (50..2000)", "300")
      .option("dilate-mm", "MM", "dilation of the body before meshing", "10")
      .option("working-voxel-mm", "MM", "voxel size of the working grid (0: automatic)", "0")
      .option("threads", "N", "worker threads (0: all cores)", "0")
      .flag("json", "print a JSON report on stdout");
  declareSeparationOptions(p, "the cage passes between");
  declareMemoryOption(p, "above it a downsampled proxy of PARTS (label mode per block) is used");
  if (!p.parse(args)) return 0;
  if (!p.has("parts")) throw UsageError{"--parts is required"};
  if (!p.has("out")) throw UsageError{"--out is required"};
  CageOptions o;
  o.targetVertices = static_cast<int>(p.getInt("vertices"));
  o.dilateMm = p.getDouble("dilate-mm");
  o.workingVoxelMm = p.getDouble("working-voxel-mm");
  o.threads = static_cast<int>(p.getInt("threads"));
  if (const auto separation = parseSeparationOptions(p)) o.separations.push_back(*separation);
  const std::string out = p.get("out");
  refuseOverwritingInput(p.get("parts"), out);
  AtomicOutput probe(out);  // an unwritable output fails now, not after the work
  o.progress = terminalProgress();
  const auto start = std::chrono::steady_clock::now();
  // The builder holds S and working grids: about 3 bytes per voxel of S.
  int proxy = 1;
  const Volume parts =
      readLabelsWithinBudget(p.get("parts"), parseMemoryBudget(p.get("memory")), 3, proxy);
  requirePoseableLabels(parts, p.get("parts"));
  warnUnnamedLabels(parts, p.get("parts"), "cage");
  const Cage cage = buildCage(parts, o);
  writeTriangleMesh(cage.mesh, out);
  const double seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  const CageReport& r = cage.report;
  if (p.has("json")) {
    nlohmann::json j = {{"cage", out},
                        {"vertices", r.vertices},
                        {"faces", r.faces},
                        {"dense_vertices", r.denseVertices},
                        {"working_voxel_mm", r.workingVoxelMm},
                        {"simplification", r.simplification},
                        {"frozen_dense_vertices", r.frozenVertices},
                        {"dilate_mm", o.dilateMm},
                        {"proxy_factor", proxy},
                        {"checks",
                         {{"closed", r.closed},
                          {"manifold", r.manifold},
                          {"outward", r.outward},
                          {"self_intersection_free", r.selfIntersectionFree}}},
                        {"body_voxels", r.bodyVoxels},
                        {"enclosed_voxels", r.enclosedVoxels},
                        {"enclosed_fraction", r.enclosedFraction()},
                        {"seconds", seconds}};
    std::cout << j.dump(2) << "\n";
  } else {
    std::cout << "wrote " << out << ": " << r.vertices << " vertices, " << r.faces
              << " faces (from " << r.denseVertices << " on a " << r.workingVoxelMm << " mm grid, "
              << r.simplification << ")\n"
              << "checks: closed, manifold, outward, no self-intersection\n"
              << "encloses " << r.enclosedVoxels << " of " << r.bodyVoxels << " body voxels ("
              << 100.0 * r.enclosedFraction() << "%) in " << seconds << " s\n";
  }
  return 0;
}

}  // namespace repose::cli
