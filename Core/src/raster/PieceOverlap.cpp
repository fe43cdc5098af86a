#include "repose/raster/PieceOverlap.h"

#include "TetScan.h"

#include <algorithm>
#include <map>
#include <utility>

namespace repose {

std::vector<PieceOverlap> pieceOverlaps(const TransferMesh& mesh, const Eigen::MatrixX3d& deformed,
                                        const VolumeGeometry& grid) {
  if (mesh.rigid.empty()) return {};
  // Pieces by index; the slab buffer holds 16 bits, so the first 65535 are checked.
  std::map<PieceId, int> index;
  std::vector<PieceId> ids;
  for (Eigen::Index t = 0; t < mesh.tets.rows(); ++t)
    if (const int label = mesh.rigid[std::size_t(t)]; label != 0) {
      const PieceId id{label, mesh.labels[t]};
      if (index.try_emplace(id, int(ids.size())).second) ids.push_back(id);
    }
  const raster::ScanInput in = raster::makeScanInput(mesh, deformed, grid, grid);
  const std::int64_t nx = grid.dims[0], plane = nx * grid.dims[1];
  // Slabs of slices, each holding the first piece found at each voxel (1-based; 0: none), so
  // memory stays bounded whatever the grid. A tet is scanned in each slab its box meets.
  const std::int64_t slab = std::max<std::int64_t>(1, (std::int64_t(32) << 20) / (2 * plane));
  std::vector<std::uint16_t> first(std::size_t(plane * std::min(slab, grid.dims[2])));
  std::vector<Eigen::Index> pieceTets;
  for (Eigen::Index t = 0; t < mesh.tets.rows(); ++t)
    if (mesh.rigid[std::size_t(t)] != 0) pieceTets.push_back(t);
  std::map<std::pair<int, int>, std::int64_t> counts;
  raster::ScanTet s;
  for (std::int64_t k0 = 0; k0 < grid.dims[2]; k0 += slab) {
    const std::int64_t k1 = std::min(grid.dims[2], k0 + slab);
    std::fill(first.begin(), first.end(), std::uint16_t(0));
    for (const Eigen::Index t : pieceTets) {
      if (!raster::prepareTet(in, t, s) || s.hi[2] < k0 || s.lo[2] >= k1) continue;
      const int piece = index.at(PieceId{mesh.rigid[std::size_t(t)], mesh.labels[t]}) + 1;
      if (piece > 65535) continue;  // beyond 65535 pieces (no real map has so many) unchecked
      raster::scanTet(
          s, k0, k1, 0, grid.dims[1],
          [&](std::int64_t k, std::int64_t j, std::int64_t i0, std::int64_t i1,
              const Eigen::Vector3d&, const Eigen::Vector3d&) {
            std::uint16_t* row = first.data() + (k - k0) * plane + j * nx;
            for (std::int64_t i = i0; i <= i1; ++i) {
              if (row[i] == 0)
                row[i] = std::uint16_t(piece);
              else if (row[i] != piece)
                ++counts[{std::min<int>(row[i], piece) - 1, std::max<int>(row[i], piece) - 1}];
            }
          });
    }
  }
  std::vector<PieceOverlap> out;
  for (const auto& [pair, n] : counts) {
    PieceOverlap o;
    o.a = ids[std::size_t(pair.first)], o.b = ids[std::size_t(pair.second)];
    if (o.b < o.a) std::swap(o.a, o.b);
    o.voxels = n;
    out.push_back(o);
  }
  std::sort(out.begin(), out.end(), [](const PieceOverlap& x, const PieceOverlap& y) {
    return x.a == y.a ? x.b < y.b : x.a < y.a;
  });
  return out;
}

}  // namespace repose
