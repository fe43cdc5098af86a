// Motion-adaptive refinement of the transfer mesh (seed §4.2): mesh with the sizing field,
// deform, measure the error metric, shrink the field where the error is above the mean, repeat.
#pragma once

#include "repose/mesh/RigiditySolver.h"
#include "repose/mesh/TransferMesh.h"

#include <vector>

namespace repose {

struct RefinementOptions {
  double initialSizeMm = 0;  // 0: 5% of S's diagonal, as the seed
  int maxIterations = 6;
  int maxVertices = 200000;  // stop before a mesh would exceed this
  double uniformity = 1.5;   // stop when max(e^G) <= uniformity * mean(e^G)
  int threads = 0;
  ProgressFn progress;
  // Whole pieces meshed as subdomains of their own (TransferMeshOptions::rigidTissue), each mesh.
  const Volume* rigidTissue = nullptr;
};

struct RefinementStep {
  int vertices = 0, tets = 0;
  double meanError = 0;    // e_mean over covered voxels of the sizing grid
  double maxError = 0;     // max e^G
  double maxTetError = 0;  // max e_t
};

struct RefinementResult {
  TransferMesh mesh;   // the last mesh built
  SizingField sizing;  // the field it was built with
  std::vector<RefinementStep> steps;
};

// Embeds `mesh` in the cage, deforms it (exact precision) and measures the metric: e_t, and e^G
// on `grid` (errorGrid and covered receive it when given). Also measures uniform meshes, to
// compare them with refined ones.
RefinementStep measureDeformationError(const TransferMesh& mesh, const TriangleMesh& cage,
                                       const Eigen::MatrixX3d& deformedCage,
                                       const VolumeGeometry& grid, int threads = 0,
                                       std::vector<float>* errorGrid = nullptr,
                                       std::vector<char>* covered = nullptr);

// The sizing grid is S's grid coarsened by a whole factor to at most ~8M voxels.
SizingField initialSizingField(const Volume& parts, double sizeMm);

// deformedCage: the pose to adapt to (#cage vertices by 3).
RefinementResult refineTransferMesh(const Volume& parts, const TriangleMesh& cage,
                                    const Eigen::MatrixX3d& deformedCage,
                                    const RefinementOptions& options = {});

}  // namespace repose
