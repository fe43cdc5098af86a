// `repose mesh --parts S --cage cage.obj --out tm.vtu`: the labelled transfer mesh, optionally
// split between two body parts, with how much of it the cage holds (V_c) and what it misses.
#include "ArgParser.h"
#include "SeparationOptions.h"
#include "Commands.h"
#include "InputChecks.h"
#include "MemoryBudget.h"
#include "TerminalProgress.h"

#include "repose/io/AtomicOutput.h"
#include "repose/io/MeshIO.h"
#include "repose/io/VolumeIO.h"
#include "repose/mesh/Embedding.h"
#include "repose/mesh/RigiditySolver.h"
#include "repose/mesh/TransferMesh.h"

#include <nlohmann/json.hpp>

#include <chrono>
#include <iostream>
#include <optional>

namespace repose::cli {

int runMesh(const Args& args) {
  ArgParser p(
      "mesh",
      "Build the transfer mesh: a tetrahedral mesh of the body parts of PARTS (CGAL Mesh_3,\n"
      "one label per tet), embed it in the cage (vertices inside it get Green coordinates;\n"
      "the others, the outliers, follow through the rigidity solver) and write it as a VTK\n"
      "unstructured grid (.vtu, RAS mm, cell array 'label'). The Green coordinates are\n"
      "written beside it (tm.vtu -> tm.green) for `repose warp` to reuse.");
  p.option("parts", "FILE", "body-part map S (or any label map)")
      .option("cage", "FILE", "cage from `repose cage` (.obj or .vtk)")
      .option("out", "FILE", "output transfer mesh (.vtu)")
      .option("size-mm", "MM", "tet size (0: 5% of the volume's diagonal)", "0")
      .option("threads", "N", "worker threads (0: all cores)", "0")
      .flag("json", "print a JSON summary on stdout")
      .flag("slicer-progress",
            "progress as the <filter-progress> lines 3D Slicer's CLI modules print on stdout");
  declareSeparationOptions(p, "split the mesh between");
  declareMemoryOption(p, "above it a downsampled proxy of PARTS (label mode per block) is used");
  if (!p.parse(args)) return 0;
  if (p.has("slicer-progress")) startSlicerProgress("repose mesh", "meshing " + p.get("parts"));
  for (const char* required : {"parts", "cage", "out"})
    if (!p.has(required)) throw UsageError{std::string("--") + required + " is required"};
  const std::optional<LimbSeparation> separation = parseSeparationOptions(p);
  const std::string out = p.get("out");
  refuseOverwritingInput(p.get("parts"), out);
  refuseOverwritingInput(p.get("parts"), greenCoordinatesFileFor(out));
  refuseOverwritingInput(p.get("cage"), greenCoordinatesFileFor(out));
  AtomicOutput probe(out);  // an unwritable output fails before the work
  const auto start = std::chrono::steady_clock::now();
  // Mesh_3 holds S, a padded 16-bit copy and its triangulation: about 8 bytes per voxel of S.
  int proxy = 1;
  const Volume parts =
      readLabelsWithinBudget(p.get("parts"), parseMemoryBudget(p.get("memory")), 8, proxy);
  requirePoseableLabels(parts, p.get("parts"));
  warnUnnamedLabels(parts, p.get("parts"), "mesh");
  const TriangleMesh cage = readTriangleMesh(p.get("cage"));
  TransferMeshOptions o;
  o.sizeMm = p.getDouble("size-mm");
  if (o.sizeMm < 0) throw UsageError{"--size-mm must be >= 0"};
  o.progress = terminalProgress();
  TransferMeshReport report;
  TransferMesh mesh = buildTransferMesh(parts, o, &report);
  int added = 0;
  if (separation)
    added = separateLabels(mesh, separation->labelA, separation->labelB, separation->region);
  const int threads = static_cast<int>(p.getInt("threads"));
  // The embedding, its Green coordinates and the solver's factorization: what every later
  // deformation of this mesh needs. The coordinates are kept beside the mesh (tm.vtu ->
  // tm.green) so that `repose warp` reads them instead of computing them again.
  const CageDeformation deformation(mesh, cage, threads, "", terminalProgress());
  const Embedding& embedding = deformation.embedding();
  const RigiditySolver& solver = deformation.solver();
  const std::string coordinates = greenCoordinatesFileFor(out);
  deformation.saveCoordinates(coordinates);
  writeTransferMesh(mesh, out);
  const double seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  nlohmann::json labels = nlohmann::json::object();
  for (const auto& [label, count] : report.tetsPerLabel) labels[std::to_string(label)] = count;
  const nlohmann::json j = {{"mesh", out},
                            {"green_coordinates", coordinates},
                            {"green_coordinates_bytes", deformation.coefficientBytes()},
                            {"unreproduced_vertices", deformation.unreproducedVertices()},
                            {"vertices", mesh.vertices.rows()},
                            {"tets", mesh.tets.rows()},
                            {"tets_per_label", labels},
                            {"degenerate_tets_removed", report.degenerateTets},
                            {"inverted_tets_reoriented", report.invertedTets},
                            {"short_edges_collapsed", report.collapsedEdges},
                            {"separation_vertices_added", added},
                            {"vertices_inside_cage", embedding.cageVertices.size()},
                            {"tets_inside_cage", embedding.cageTets.size()},
                            {"outliers", embedding.outliers()},
                            {"proxy_factor", proxy},
                            {"unreachable_vertices", solver.unconstrainedVertices()},
                            {"seconds", seconds}};
  if (p.has("json")) {
    std::cout << j.dump(2) << "\n";
  } else {
    std::cout << "wrote " << out << ": " << mesh.vertices.rows() << " vertices, "
              << mesh.tets.rows() << " tets\n"
              << "wrote " << coordinates << ": the Green coordinates of the vertices in the cage\n"
              << "inside the cage: " << embedding.cageVertices.size() << " vertices, "
              << embedding.cageTets.size()
              << " tets; outliers (moved by the rigidity solver): " << embedding.outliers() << "\n";
    if (solver.unconstrainedVertices() > 0)
      std::cout << "warning: " << solver.unconstrainedVertices()
                << " vertices belong to parts with no vertex in the cage; they will not move\n";
  }
  endSlicerProgress("repose mesh");
  return 0;
}

}  // namespace repose::cli
