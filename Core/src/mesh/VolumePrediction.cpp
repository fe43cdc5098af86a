#include "repose/mesh/VolumePrediction.h"

#include "repose/util/Error.h"

#include <Eigen/LU>

#include <algorithm>
#include <cmath>
#include <limits>
#include <utility>
#include <vector>

namespace repose {
namespace {

// The signed volume of tet t over the columns of `v` (column-major #V x 3, so
// x, y and z are three arrays), in scalars: the workbench asks for the prediction on every live
// frame, two of these per tet.
double signedVolume(const Eigen::MatrixX3d& v, const Eigen::MatrixX4i& tets, Eigen::Index t) {
  const Eigen::Index n = v.rows();
  const double *x = v.data(), *y = x + n, *z = y + n;
  const Eigen::Index a = tets(t, 0), b = tets(t, 1), c = tets(t, 2), d = tets(t, 3);
  const double bx = x[b] - x[a], by = y[b] - y[a], bz = z[b] - z[a];
  const double cx = x[c] - x[a], cy = y[c] - y[a], cz = z[c] - z[a];
  const double dx = x[d] - x[a], dy = y[d] - y[a], dz = z[d] - z[a];
  // det [b c d] (columns), as Eigen's 3x3 determinant expands it.
  return (bx * (cy * dz - cz * dy) - cx * (by * dz - bz * dy) + dx * (by * cz - bz * cy)) / 6;
}

}  // namespace

VolumePrediction predictVolumeChange(const TransferMesh& mesh, const Eigen::MatrixX3d& deformed) {
  if (deformed.rows() != mesh.vertices.rows())
    throw Error("volume prediction: the posed vertices do not match the mesh");
  VolumePrediction out;
  const Eigen::Index nt = mesh.tets.rows();
  if (nt == 0) return out;
  // Parts in a dense table by label (S's labels are a few small numbers): the workbench asks for
  // this on every live frame, so no map lookup per tet.
  const auto [lowest, highest] = std::minmax_element(mesh.labels.begin(), mesh.labels.end());
  const int base = *lowest;
  std::vector<PartVolumeChange> parts(std::size_t(*highest - base + 1));
  std::vector<char> present(parts.size(), 0);
  std::vector<double> change(std::size_t(nt), 0);
  for (Eigen::Index t = 0; t < nt; ++t) {
    const double rest = signedVolume(mesh.vertices, mesh.tets, t);
    // Oriented as at rest: a tet turned inside out counts negative.
    const double posed = signedVolume(deformed, mesh.tets, t) * (rest < 0 ? -1.0 : 1.0);
    const std::size_t k = std::size_t(mesh.labels[t] - base);
    PartVolumeChange& p = parts[k];
    present[k] = 1;
    p.part = mesh.labels[t];
    p.restMm3 += std::fabs(rest);
    p.posedMm3 += posed;
    out.restMm3 += std::fabs(rest);
    out.posedMm3 += posed;
    change[std::size_t(t)] = posed - std::fabs(rest);
  }
  double worst = 0;
  for (std::size_t k = 0; k < parts.size(); ++k) {
    if (!present[k]) continue;
    const PartVolumeChange& p = parts[k];
    out.parts.push_back(p);
    if (std::fabs(p.posedMm3 - p.restMm3) > std::fabs(worst))
      worst = p.posedMm3 - p.restMm3, out.worstPart = p.part;
  }
  if (out.worstPart == 0) return out;
  // How much of the worst part's change each neighbouring part shares: at every vertex of the
  // worst part's tets, that change (summed over its tets there) is shared once with each other
  // part with a tet at the vertex. A neighbour that drags the worst part shares the vertices of
  // its stretched tets. Linear in the tets (the workbench asks on every live frame): the tets
  // are visited part by part, and a vertex counts once per part by the part it was last seen in.
  const std::size_t nv = std::size_t(mesh.vertices.rows());
  std::vector<double> atVertex(nv, 0);
  for (Eigen::Index t = 0; t < nt; ++t)
    if (mesh.labels[t] == out.worstPart)
      for (int c = 0; c < 4; ++c)
        atVertex[std::size_t(mesh.tets(t, c))] += std::fabs(change[std::size_t(t)]);
  std::vector<std::size_t> start(parts.size() + 1, 0);  // tets by part (a counting sort)
  for (Eigen::Index t = 0; t < nt; ++t) ++start[std::size_t(mesh.labels[t] - base) + 1];
  for (std::size_t k = 0; k < parts.size(); ++k) start[k + 1] += start[k];
  std::vector<Eigen::Index> byPart(static_cast<std::size_t>(nt));
  {
    std::vector<std::size_t> next(start.begin(), start.end() - 1);
    for (Eigen::Index t = 0; t < nt; ++t) byPart[next[std::size_t(mesh.labels[t] - base)]++] = t;
  }
  std::vector<int> lastPart(nv, std::numeric_limits<int>::min());
  std::vector<double> shared(parts.size(), 0);
  for (std::size_t k = 0; k < parts.size(); ++k) {
    const int part = int(k) + base;
    if (part == out.worstPart) continue;
    for (std::size_t i = start[k]; i < start[k + 1]; ++i)
      for (int c = 0; c < 4; ++c) {
        const std::size_t v = std::size_t(mesh.tets(byPart[i], c));
        if (atVertex[v] > 0 && lastPart[v] != part) {
          lastPart[v] = part;
          shared[k] += atVertex[v];
        }
      }
  }
  double most = 0;
  for (std::size_t k = 0; k < shared.size(); ++k)
    if (shared[k] > most) most = shared[k], out.draggedBy = int(k) + base;
  return out;
}

}  // namespace repose
