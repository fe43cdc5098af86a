// V_c by generalized winding number (robust near the cage surface), T_c from V_c, and the Green
// coordinates of V_c.
#include "repose/mesh/Embedding.h"

#include "repose/cage/WindingNumber.h"
#include "repose/util/Error.h"

namespace repose {

Embedding embedInCage(const TransferMesh& mesh, const TriangleMesh& cage, int threads,
                      bool withCoordinates) {
  Embedding e;
  const Eigen::VectorXd w = windingNumbers(cage, mesh.vertices, threads);
  e.inside.assign(static_cast<std::size_t>(mesh.vertices.rows()), 0);
  for (Eigen::Index v = 0; v < mesh.vertices.rows(); ++v)
    if (w[v] >= 0.5) {
      e.inside[v] = 1;
      e.cageVertices.push_back(static_cast<int>(v));
    }
  if (e.cageVertices.empty())
    throw Error(
        "the cage encloses no transfer-mesh vertex: it cannot move anything (is it around the "
        "body?)");
  for (Eigen::Index t = 0; t < mesh.tets.rows(); ++t)
    if (e.inside[mesh.tets(t, 0)] && e.inside[mesh.tets(t, 1)] && e.inside[mesh.tets(t, 2)] &&
        e.inside[mesh.tets(t, 3)])
      e.cageTets.push_back(static_cast<int>(t));
  if (!withCoordinates) return e;
  Eigen::MatrixX3d points(e.cageVertices.size(), 3);
  for (std::size_t i = 0; i < e.cageVertices.size(); ++i)
    points.row(i) = mesh.vertices.row(e.cageVertices[i]);
  e.coordinates = computeGreenCoordinates(cage, points, threads);
  return e;
}

}  // namespace repose
