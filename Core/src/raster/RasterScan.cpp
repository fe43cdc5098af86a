// The scan's shell and the pieces' rims, made once per scan (RasterScan.h).
#include "RasterScan.h"

#include <set>

namespace repose::raster {

// Per piece tet, bit f for face f (opposite vertex f) when the tet across it is not a tet of the
// same piece label (soft tissue, another piece, or nothing).
std::vector<std::uint8_t> pieceRimFaces(const TransferMesh& mesh) {
  const Eigen::Index nt = mesh.tets.rows();
  std::vector<std::uint8_t> out(std::size_t(nt), 0);
  if (mesh.rigid.empty()) return out;
  std::map<std::array<int, 3>, std::vector<std::int32_t>> faces;
  auto key = [&](Eigen::Index t, int f) { return sortedFace(mesh, t, f); };
  for (Eigen::Index t = 0; t < nt; ++t)
    if (mesh.rigid[std::size_t(t)])
      for (int f = 0; f < 4; ++f) faces[key(t, f)].push_back(std::int32_t(t));
  for (Eigen::Index t = 0; t < nt; ++t)
    if (!mesh.rigid[std::size_t(t)])
      for (int f = 0; f < 4; ++f) {
        const auto it = faces.find(key(t, f));
        if (it != faces.end()) it->second.push_back(std::int32_t(t));
      }
  for (const auto& [k, tets] : faces)
    for (const std::int32_t t : tets) {
      if (!mesh.rigid[std::size_t(t)]) continue;
      bool samePiece = false;
      for (const std::int32_t u : tets)
        samePiece =
            samePiece || (u != t && mesh.rigid[std::size_t(u)] == mesh.rigid[std::size_t(t)]);
      if (samePiece) continue;
      for (int f = 0; f < 4; ++f)
        if (key(t, f) == k) out[std::size_t(t)] |= std::uint8_t(1u << f);
    }
  return out;
}

// Marks in `covered` the input voxels that the shell (`mm` beyond the outer faces) of a rest tet
// of their own body part reaches. Mesh_3 puts the surface up to a voxel inside the label
// boundary, so the outermost voxels (skin, on 8 mm slices a whole slice of it) lie outside every
// rest tet; their own part's shell carries them. Another part's shell must not: a thigh swinging
// forward would carry along the hand's skin that rested on it.
static void markOwnPartShells(const TransferMesh& mesh, const VolumeGeometry& input,
                              const std::vector<std::uint8_t>& outer, double mm,
                              const Volume& parts, std::vector<std::uint8_t>& covered) {
  const ScanInput in = raster::makeScanInput(mesh, mesh.vertices, input, input);
  const Eigen::Matrix3d M = input.ijkToRas.block<3, 3>(0, 0);
  const Eigen::Matrix3d normalToMm = M.inverse().transpose();
  std::array<double, 3> growth;
  for (int c = 0; c < 3; ++c) growth[c] = mm * M.inverse().row(c).norm();
  const std::int64_t nx = input.dims[0], plane = nx * input.dims[1];
  raster::ScanTet s;
  for (Eigen::Index t = 0; t < mesh.tets.rows(); ++t) {
    if (!outer[std::size_t(t)] ||
        !raster::prepareShell(in, t, outer[std::size_t(t)], mm, normalToMm, growth, s))
      continue;
    const double part = mesh.labels[t];
    raster::scanTet(s, 0, input.dims[2], 0, input.dims[1],
                    [&](std::int64_t k, std::int64_t j, std::int64_t i0, std::int64_t i1,
                        const Eigen::Vector3d&, const Eigen::Vector3d&) {
                      for (std::int64_t i = i0; i <= i1; ++i) {
                        const std::int64_t at = k * plane + j * nx + i;
                        if (!covered[std::size_t(at)] && parts.valueAsDouble(at) == part)
                          covered[std::size_t(at)] = 1;
                      }
                    });
  }
}

double pieceReachMm(const TransferMesh& mesh, const VolumeGeometry& input) {
  return std::max(input.spacing().maxCoeff(), mesh.sourceSpacingMm);
}

double shellWidthMm(const TransferMesh& mesh, const VolumeGeometry& input,
                    const RasterOptions& options) {
  return options.shellMm < 0 ? 2 * pieceReachMm(mesh, input) : options.shellMm;
}

Shell makeShell(const TransferMesh& mesh, const VolumeGeometry& input, const VolumeGeometry& output,
                const RasterOptions& options) {
  Shell sh;
  if (options.pieceLabels && !mesh.rigid.empty()) {
    if (options.pieceLabels->dims() != input.dims)
      throw Error("rasterizer: the label map of the pieces is not on the input's grid");
    sh.pieceLabels = options.pieceLabels;
    sh.pieceFaces = pieceRimFaces(mesh);
    sh.tetParts = &mesh.labels;
    if (options.restParts && options.restParts->dims() == input.dims)
      sh.rimParts = options.restParts;
    // Per label, the piece it is meshed in (0: none): the piece ids themselves and, through
    // RigSettings::bonePieces, the other labels of a bone. A bone Mesh_3 gave no tets of its own
    // (ribs one voxel thick on 8 mm slices) is a piece all the same: its ghosts move it with
    // its body part's other pieces (PieceGhosts.h).
    const std::set<int> ids(mesh.rigid.begin(), mesh.rigid.end());
    std::vector<int> pieceOf;
    auto assign = [&](int label, int piece) {
      if (std::size_t(label) >= pieceOf.size()) pieceOf.resize(std::size_t(label) + 1, 0);
      pieceOf[std::size_t(label)] = piece;
    };
    for (const int v : ids)
      if (v > 0) assign(v, v);
    if (options.bonePieces)
      for (const auto& [label, piece] : *options.bonePieces)
        if (label > 0 && piece > 0) assign(label, piece);
    sh.boneLabel.resize(pieceOf.size());
    for (std::size_t v = 0; v < pieceOf.size(); ++v) sh.boneLabel[v] = pieceOf[v] != 0;
    sh.ghosts = raster::pieceGhosts(mesh, *options.pieceLabels, pieceOf, sh.rimParts);
    sh.pieceOf = std::move(pieceOf);
    sh.pieceMm = pieceReachMm(mesh, input);
    const Eigen::Matrix3d Minv = output.ijkToRas.block<3, 3>(0, 0).inverse();
    for (int c = 0; c < 3; ++c) sh.pieceGrowth[c] = sh.pieceMm * Minv.row(c).norm();
    sh.normalToMm = output.ijkToRas.block<3, 3>(0, 0).inverse().transpose();
  }
  sh.mm = shellWidthMm(mesh, input, options);
  if (sh.mm <= 0) return sh;
  sh.outer = options.outerFaces ? *options.outerFaces : outerFaces(mesh);
  if (sh.outer.size() != static_cast<std::size_t>(mesh.tets.rows()))
    throw Error("rasterizer: outer-face flags do not match the mesh");
  if (options.restParts) {
    if (options.restParts->dims() != input.dims)
      throw Error("rasterizer: the body-part map is not on the input's grid");
    sh.restParts = options.restParts;
    sh.tetParts = &mesh.labels;
    RasterOptions coverage;
    coverage.threads = options.threads;
    const Volume c = rasterizeCoverage(mesh, mesh.vertices, input, coverage);
    sh.restCovered.assign(c.data<std::uint8_t>(), c.data<std::uint8_t>() + c.numVoxels());
    markOwnPartShells(mesh, input, sh.outer, sh.mm, *options.restParts, sh.restCovered);
  }
  const Eigen::Matrix3d M = output.ijkToRas.block<3, 3>(0, 0);
  sh.normalToMm = M.inverse().transpose();
  const Eigen::Matrix3d Minv = M.inverse();
  for (int c = 0; c < 3; ++c) sh.boxGrowth[c] = sh.mm * Minv.row(c).norm();
  return sh;
}

}  // namespace repose::raster
