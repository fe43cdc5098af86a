// Before the work: whether a frame's posed maps fit a DICOM SEG (issue 56). A SEG holds one frame
// per segment and slice where the segment has voxels, so its pixel data is known only once every
// slice is made; native pixel data holds at most 4 GiB. This bounds each segment's posed slices
// from the mesh instead: a posed voxel takes the label of the input voxel nearest its rest
// position, which lies in the rest tet that holds the voxel, or for the shell, a piece's rim or
// ghost, within their reach of it (times the tet's inverse stretch), and the shell takes no other
// body part's tissue that the rest mesh carries. So a segment's slices lie within the posed slice
// extents of the tets whose rest box holds one of its voxels, or whose box grown by that reach
// holds one of its voxels in the tet's own body part; one slice more each side for the rounding
// and the pockets. The estimate counts, per slice, the segments whose extent holds it (at least
// one: an empty slice's frame), and once each segment with none.
#include "PoseFrameSteps.h"
#include "repose/raster/RasterReach.h"

#include "repose/io/DicomSegIO.h"
#include "repose/util/Memory.h"

#include <Eigen/Dense>

#include <algorithm>
#include <array>
#include <cmath>
#include <filesystem>
#include <map>
#include <set>

namespace repose::frame {
namespace {

// Which segments each block of b[0] x b[1] x b[2] input voxels holds, and in which body part (S's
// value there): (index into `keys`, the (layer, value)s met in increasing order; part), as
// offsets into one array.
struct LabelBlocks {
  struct Entry {
    std::uint16_t label;  // (at most 65535 segments: the check below says so)
    std::int32_t part;
  };
  std::array<std::int64_t, 3> b{}, count{};
  std::vector<std::pair<int, int>> keys;
  std::vector<std::uint32_t> offsets;  // per block, then the end
  std::vector<Entry> entries;

  LabelBlocks(const Volume& map, const Volume& parts,
              const std::array<std::int64_t, 3>& blockVoxels)
      : b(blockVoxels) {
    const auto& d = map.dims();
    for (std::size_t a = 0; a < 3; ++a) count[a] = (d[a] + b[a] - 1) / b[a];
    std::map<std::pair<int, int>, int> indexOf;
    std::vector<std::pair<int, std::int32_t>> inBlock;  // (index met, part)
    offsets.assign(std::size_t(count[0] * count[1] * count[2] + 1), 0);
    std::size_t block = 0;
    for (std::int64_t bz = 0; bz < count[2]; ++bz)
      for (std::int64_t by = 0; by < count[1]; ++by)
        for (std::int64_t bx = 0; bx < count[0]; ++bx, ++block) {
          inBlock.clear();
          for (int layer = 0; layer < map.layers(); ++layer)
            dispatchScalar(map.scalarType(), [&](auto* tag) {
              using T = std::remove_pointer_t<decltype(tag)>;
              dispatchScalar(parts.scalarType(), [&](auto* partTag) {
                using P = std::remove_pointer_t<decltype(partTag)>;
                const T* v = map.data<T>(layer);
                const P* s = parts.data<P>();
                T lastValue = T(0);
                P lastPart = P(0);
                for (std::int64_t k = bz * b[2]; k < std::min(d[2], (bz + 1) * b[2]); ++k)
                  for (std::int64_t j = by * b[1]; j < std::min(d[1], (by + 1) * b[1]); ++j)
                    for (std::int64_t i = bx * b[0]; i < std::min(d[0], (bx + 1) * b[0]); ++i) {
                      const std::int64_t at = (k * d[1] + j) * d[0] + i;
                      if (v[at] == T(0) || (v[at] == lastValue && s[at] == lastPart)) continue;
                      lastValue = v[at], lastPart = s[at];
                      const std::pair<int, int> key{layer, int(std::lround(double(lastValue)))};
                      auto it = indexOf.find(key);
                      if (it == indexOf.end()) it = indexOf.emplace(key, int(indexOf.size())).first;
                      const std::pair<int, std::int32_t> entry{
                          it->second, std::int32_t(std::lround(double(lastPart)))};
                      if (std::find(inBlock.begin(), inBlock.end(), entry) == inBlock.end())
                        inBlock.push_back(entry);
                    }
              });
            });
          offsets[block] = std::uint32_t(entries.size());
          for (const auto& [index, part] : inBlock) entries.push_back({std::uint16_t(index), part});
          if (indexOf.size() > 65535) throw Error("more than 65535 labels for a DICOM SEG");
        }
    offsets.back() = std::uint32_t(entries.size());
    // Indices in (layer, value) order.
    std::vector<std::uint16_t> rank(indexOf.size());
    for (const auto& [key, index] : indexOf) {
      rank[std::size_t(index)] = std::uint16_t(keys.size());
      keys.push_back(key);
    }
    for (Entry& e : entries) e.label = rank[e.label];
  }
};

}  // namespace

std::int64_t dicomSegFramesEstimate(const FrameStart& start, const TransferMesh& mesh,
                                    const Volume& map, const Volume& parts) {
  const VolumeGeometry& input = parts.geometry();
  const VolumeGeometry& grid = start.grid;
  const std::int64_t nz = grid.dims[2];
  // How far beyond its tet a voxel takes the tet's map: the shell (outer tets), a piece's rim or
  // ghost, as the frame's rasterizer has them (its options leave the shell at its default).
  const double pieceMm = raster::pieceReachMm(mesh, input);
  const double shellMm = raster::shellWidthMm(mesh, input, RasterOptions());
  // Blocks about as wide as a piece's reach along each axis, and at least 8 mm (a fine input's
  // blocks stay few: 1G voxels of 0.5 mm are 244K blocks); finer would cost memory and time and
  // tighten little.
  std::array<std::int64_t, 3> blockVoxels{};
  for (int a = 0; a < 3; ++a)
    blockVoxels[std::size_t(a)] =
        std::max<std::int64_t>(1, std::lround(std::max(pieceMm, 8.0) / input.spacing()[a]));
  const LabelBlocks blocks(map, parts, blockVoxels);
  const std::size_t labels = blocks.keys.size();
  const Eigen::Matrix3d toIjk = grid.ijkToRas.block<3, 3>(0, 0).inverse();
  const Eigen::Vector3d origin = grid.ijkToRas.block<3, 1>(0, 3);
  const double slicesPerMm = toIjk.row(2).norm();
  const Eigen::Matrix4d restToIjk = input.ijkToRas.inverse();
  std::vector<std::int64_t> from(labels, nz), to(labels, -1);
  const Eigen::MatrixX3d& rest = mesh.vertices;
  const Eigen::MatrixX3d& posed = start.frame.deformed;
  // Tets of a piece or touching one: their voxels' map may reach a piece's voxel size beyond
  // them (a rim, a ghost); other soft tets write only the voxels inside them.
  std::vector<std::uint8_t> nearPiece(std::size_t(rest.rows()), 0);
  for (Eigen::Index t = 0; t < mesh.tets.rows(); ++t)
    if (std::size_t(t) < mesh.rigid.size() && mesh.rigid[std::size_t(t)] != 0)
      for (int c = 0; c < 4; ++c) nearPiece[std::size_t(mesh.tets(t, c))] = 1;
  for (Eigen::Index t = 0; t < mesh.tets.rows(); ++t) {
    Eigen::Vector3d lo = Eigen::Vector3d::Constant(1e300), hi = -lo;
    double kLo = 1e300, kHi = -1e300;
    Eigen::Matrix3d restEdges, posedEdges;
    for (int c = 0; c < 4; ++c) {
      const Eigen::Vector3d r = rest.row(mesh.tets(t, c)).transpose();
      const Eigen::Vector3d p = posed.row(mesh.tets(t, c)).transpose();
      lo = lo.cwiseMin(r), hi = hi.cwiseMax(r);
      const double k = toIjk.row(2).dot(p - origin);
      kLo = std::min(kLo, k), kHi = std::max(kHi, k);
      if (c > 0) {
        restEdges.col(c - 1) = r - rest.row(mesh.tets(t, 0)).transpose();
        posedEdges.col(c - 1) = p - posed.row(mesh.tets(t, 0)).transpose();
      }
    }
    // The map's inverse stretch (a bound on its largest singular value), at most 4: a flat or
    // folded tet's shell is taken as reaching four times as far at rest.
    const bool outer = start.outer.size() > std::size_t(t) && start.outer[std::size_t(t)] != 0;
    bool piece = false;
    for (int c = 0; c < 4; ++c) piece = piece || nearPiece[std::size_t(mesh.tets(t, c))];
    const double reachMm = outer ? shellMm : piece ? pieceMm : 0;
    double stretch = 4;
    if (std::fabs(posedEdges.determinant()) > 1e-12)
      stretch = std::clamp((restEdges * posedEdges.inverse()).norm(), 1.0, 4.0);
    const double grow = reachMm * stretch;
    // Voxel centres within reach of the posed tet, one more each side for the rounding's and the
    // pockets' relabelling of border voxels.
    const std::int64_t k0 =
        std::max<std::int64_t>(0, std::int64_t(std::ceil(kLo - reachMm * slicesPerMm - 1e-9)) - 1);
    const std::int64_t k1 = std::min<std::int64_t>(
        nz - 1, std::int64_t(std::floor(kHi + reachMm * slicesPerMm + 1e-9)) + 1);
    if (k0 > k1) continue;
    // The input voxels nearest to a point of the rest tet's box (any segment: the tet's own
    // voxels), and of that box grown by the reach (a segment in the tet's own body part: the
    // shell does not take another part's tissue that the rest mesh carries), by block.
    auto blockRange = [&](double by, std::array<std::int64_t, 3>& b0,
                          std::array<std::int64_t, 3>& b1) {
      Eigen::Vector3d ijkLo = Eigen::Vector3d::Constant(1e300), ijkHi = -ijkLo;
      for (int c = 0; c < 8; ++c) {
        const Eigen::Vector4d corner(c & 1 ? hi.x() + by : lo.x() - by,
                                     c & 2 ? hi.y() + by : lo.y() - by,
                                     c & 4 ? hi.z() + by : lo.z() - by, 1);
        const Eigen::Vector3d ijk = (restToIjk * corner).head<3>();
        ijkLo = ijkLo.cwiseMin(ijk), ijkHi = ijkHi.cwiseMax(ijk);
      }
      bool inside = true;
      for (int a = 0; a < 3; ++a) {
        const std::int64_t n = input.dims[std::size_t(a)];
        const std::int64_t i0 = std::max<std::int64_t>(0, std::int64_t(std::floor(ijkLo[a])));
        const std::int64_t i1 = std::min<std::int64_t>(n - 1, std::int64_t(std::ceil(ijkHi[a])));
        inside = inside && i0 <= i1;
        b0[std::size_t(a)] = i0 / blocks.b[std::size_t(a)],
        b1[std::size_t(a)] = i1 / blocks.b[std::size_t(a)];
      }
      return inside;
    };
    std::array<std::int64_t, 3> own0{}, own1{}, b0{}, b1{};
    const bool own = blockRange(0, own0, own1);
    if (!blockRange(grow, b0, b1)) continue;
    const std::int32_t part = mesh.labels.size() > t ? std::int32_t(mesh.labels[t]) : 0;
    for (std::int64_t bz = b0[2]; bz <= b1[2]; ++bz)
      for (std::int64_t by = b0[1]; by <= b1[1]; ++by)
        for (std::int64_t bx = b0[0]; bx <= b1[0]; ++bx) {
          const bool inOwn = own && bx >= own0[0] && bx <= own1[0] && by >= own0[1] &&
                             by <= own1[1] && bz >= own0[2] && bz <= own1[2];
          const std::size_t block = std::size_t((bz * blocks.count[1] + by) * blocks.count[0] + bx);
          for (std::uint32_t at = blocks.offsets[block]; at < blocks.offsets[block + 1]; ++at) {
            const LabelBlocks::Entry& e = blocks.entries[at];
            if (!inOwn && e.part != part) continue;
            from[e.label] = std::min(from[e.label], k0), to[e.label] = std::max(to[e.label], k1);
          }
        }
  }
  // Per slice, the segments whose extent holds it (at least one frame: an empty one); a segment
  // with no slice (of the table, or out of reach) one empty frame.
  std::vector<std::int64_t> starts(std::size_t(nz + 1), 0);
  std::int64_t frames = 0;
  for (std::size_t l = 0; l < labels; ++l)
    if (from[l] <= to[l])
      ++starts[std::size_t(from[l])], --starts[std::size_t(to[l] + 1)];
    else
      ++frames;
  std::set<std::pair<int, int>> segments(blocks.keys.begin(), blocks.keys.end());
  for (const Label& l : map.labels().labels())
    if (l.value != 0) segments.insert({l.layer, l.value});
  frames += std::int64_t(segments.size() - labels);
  std::int64_t open = 0;
  for (std::int64_t k = 0; k < nz; ++k) {
    open += starts[std::size_t(k)];
    frames += std::max<std::int64_t>(1, open);
  }
  return frames;
}

nlohmann::json checkDicomSegFits(const FrameStart& start, const TransferMesh& mesh,
                                 const Volume& organs, const Volume& parts,
                                 const std::string& folder) {
  const std::int64_t pixels = start.grid.dims[0] * start.grid.dims[1];
  nlohmann::json bounds = {{"pixel_data_limit_bytes", kDicomSegPixelDataBytes}};
  for (const auto& [map, name] : {std::pair{&organs, "posed_G.dcm"}, {&parts, "posed_S.dcm"}}) {
    const std::int64_t frames = dicomSegFramesEstimate(start, mesh, *map, parts);
    const double bytes = std::ceil(double(frames) * double(pixels) / 8);
    if (bytes > double(kDicomSegPixelDataBytes))
      throw Error((std::filesystem::path(folder) / name).string() + ": frame " + start.frame.name +
                  " as DICOM SEG would hold up to " + std::to_string(frames) + " frames of " +
                  std::to_string(start.grid.dims[0]) + "x" + std::to_string(start.grid.dims[1]) +
                  " (" + gib(bytes) +
                  "), more than the 4 GiB a DICOM object's pixel data can hold; write nii.gz or "
                  "seg.nrrd (--output-format), or a coarser grid (--spacing-mm)");
    bounds[name] = {{"frames_bound", frames}, {"pixel_data_bound_bytes", std::int64_t(bytes)}};
  }
  return bounds;
}

}  // namespace repose::frame
