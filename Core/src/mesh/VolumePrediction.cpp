#include "repose/mesh/VolumePrediction.h"

#include "repose/util/Error.h"

#include <Eigen/LU>

#include <algorithm>
#include <cmath>
#include <map>

namespace repose {
namespace {

double signedVolume(const Eigen::MatrixX3d& v, const Eigen::MatrixX4i& tets, Eigen::Index t) {
  Eigen::Matrix3d e;
  for (int c = 0; c < 3; ++c) e.col(c) = (v.row(tets(t, c + 1)) - v.row(tets(t, 0))).transpose();
  return e.determinant() / 6;
}

}  // namespace

VolumePrediction predictVolumeChange(const TransferMesh& mesh, const Eigen::MatrixX3d& deformed) {
  if (deformed.rows() != mesh.vertices.rows())
    throw Error("volume prediction: the posed vertices do not match the mesh");
  VolumePrediction out;
  const Eigen::Index nt = mesh.tets.rows();
  std::vector<double> change(std::size_t(nt), 0);
  std::map<int, PartVolumeChange> parts;
  for (Eigen::Index t = 0; t < nt; ++t) {
    const double rest = signedVolume(mesh.vertices, mesh.tets, t);
    // Oriented as at rest: a tet turned inside out counts negative.
    const double posed = signedVolume(deformed, mesh.tets, t) * (rest < 0 ? -1.0 : 1.0);
    PartVolumeChange& p = parts[mesh.labels[t]];
    p.part = mesh.labels[t];
    p.restMm3 += std::fabs(rest);
    p.posedMm3 += posed;
    out.restMm3 += std::fabs(rest);
    out.posedMm3 += posed;
    change[std::size_t(t)] = posed - std::fabs(rest);
  }
  double worst = 0;
  for (const auto& [label, p] : parts) {
    out.parts.push_back(p);
    if (std::fabs(p.posedMm3 - p.restMm3) > std::fabs(worst))
      worst = p.posedMm3 - p.restMm3, out.worstPart = label;
  }
  if (out.worstPart == 0) return out;
  // The parts around each vertex of the worst part's tets, and how much of its change each one
  // shares: a neighbour that drags the worst part shares the vertices of its stretched tets.
  std::vector<std::vector<int>> partsAt(std::size_t(mesh.vertices.rows()));
  for (Eigen::Index t = 0; t < nt; ++t)
    for (int c = 0; c < 4; ++c) {
      std::vector<int>& at = partsAt[std::size_t(mesh.tets(t, c))];
      if (std::find(at.begin(), at.end(), mesh.labels[t]) == at.end()) at.push_back(mesh.labels[t]);
    }
  std::map<int, double> shared;
  for (Eigen::Index t = 0; t < nt; ++t) {
    if (mesh.labels[t] != out.worstPart) continue;
    const double c = std::fabs(change[std::size_t(t)]);
    for (int v = 0; v < 4; ++v)
      for (const int other : partsAt[std::size_t(mesh.tets(t, v))])
        if (other != out.worstPart) shared[other] += c;
  }
  double most = 0;
  for (const auto& [label, c] : shared)
    if (c > most) most = c, out.draggedBy = label;
  return out;
}

}  // namespace repose
