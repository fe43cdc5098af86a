// Self-contact of a posed transfer mesh: where a fold (the tissue above an arm raised past the
// shoulder, the inner side of a bent elbow or hip) pushes one side of the body into another, two
// layers of tissue claim the same space. Each tet keeps its volume, so the volume restoration
// sees nothing wrong, but the rasterizer writes one layer over the other and the first one's
// voxels are lost: the body and the labels of the fold shrink by the overlap.
//
// Found on the posed mesh as surface vertices that lie inside (or on) a posed tet of another layer:
// one with no corner within `ownRings` edges of the vertex through the mesh. Distance at rest
// cannot tell the layers apart: the two sides of a cut contact (a hand on the thigh) coincide at
// rest. A vertex inside a tet of its own neighbourhood is a tet turned inside out, which the
// untangling handles (TetUntangle.h). Each contact names the way out: the nearest point of the
// surface of the other side (a surface face with no corner within those rings).
#pragma once

#include "repose/mesh/TransferMesh.h"

#include <Eigen/Core>

#include <array>
#include <vector>

namespace repose {

struct SelfContactOptions {
  // The vertex's own layer: the vertices within this many edges of it through the mesh. Farther
  // (or not joined at all: the two sides of a cut contact) is another layer. Folds closer than
  // this to their crease are left to the untangling.
  int ownRings = 3;
};

struct SelfContact {
  int vertex = -1;
  Eigen::Vector3d point = Eigen::Vector3d::Zero();   // nearest point of the other side's surface
  Eigen::Vector3d normal = Eigen::Vector3d::Zero();  // unit, from the vertex towards `point`
  double depthMm = 0;                                // the vertex's distance to `point`
};

class SelfContactFinder {
 public:
  explicit SelfContactFinder(const TransferMesh& mesh, SelfContactOptions options = {});
  // Contacts at the posed positions; `candidates` (optional, one per vertex): only those vertices
  // are tested.
  std::vector<SelfContact> find(const Eigen::MatrixX3d& posed,
                                const std::vector<char>* candidates = nullptr) const;
  const std::vector<int>& surfaceVertices() const { return surfaceVertices_; }

 private:
  // Copies of the rest mesh (the finder outlives moves of the mesh it was built from).
  Eigen::MatrixX3d rest_;
  Eigen::MatrixX4i tets_;
  SelfContactOptions options_;
  std::vector<int> surfaceVertices_;
  std::vector<std::array<int, 3>> surfaceFaces_;
  std::vector<int> adjacencyStart_, adjacency_;  // vertex neighbours through tet edges (CSR)
  double cellMm_ = 1;
};

}  // namespace repose
