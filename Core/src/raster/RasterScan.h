// The scan's engine shared by the rasterizers (labels, image, field, coverage): the shell outside
// the mesh's outer faces and the pieces' rims (Shell), and runScan, which writes every output
// voxel centre a deformed tet (or its shell) covers, slab by slab on all cores. Internal to
// raster/; the public faces are Rasterizer.h's functions and slab classes.
#pragma once

#include "PieceGhosts.h"
#include "TetScan.h"
#include "repose/raster/RasterReach.h"
#include "repose/raster/Rasterizer.h"
#include "repose/util/Error.h"
#include "repose/util/Parallel.h"

#include <Eigen/LU>
#include <algorithm>
#include <array>
#include <atomic>
#include <cmath>
#include <cstdint>
#include <functional>
#include <memory>
#include <limits>
#include <map>
#include <mutex>
#include <string>
#include <type_traits>
#include <vector>

namespace repose::raster {
inline void checkDeformation(const TransferMesh& mesh, const Eigen::MatrixX3d& deformed) {
  if (deformed.rows() != mesh.vertices.rows())
    throw Error("rasterizer: " + std::to_string(deformed.rows()) + " deformed positions for " +
                std::to_string(mesh.vertices.rows()) + " mesh vertices");
  if (!deformed.allFinite()) throw Error("rasterizer: deformed positions are not finite");
}

// Inverted and flat deformed tets, for the report. Rest tets are positive in RAS; the output
// grid's handedness is taken out.
inline void countBadTets(const ScanInput& in, double frameSign, RasterReport& r) {
  const Eigen::MatrixX4i& T = *in.tets;
  for (Eigen::Index t = 0; t < T.rows(); ++t) {
    Eigen::Matrix3d D;
    for (int c = 0; c < 3; ++c) D.col(c) = in.out[T(t, c + 1)] - in.out[T(t, 0)];
    const double v = frameSign * D.determinant();
    if (v == 0 || !std::isfinite(v))
      ++r.flatTets;
    else if (v < 0)
      ++r.invertedTets;
  }
}

// How the shell around the outer faces is scanned (RasterOptions::shellMm).
// Index of the input voxel nearest to the rest position p (input IJK), or -1 beyond the grid.
inline std::int64_t nearestVoxel(const Eigen::Vector3d& p, const std::array<std::int64_t, 3>& d) {
  const std::int64_t x = raster::floorToInt(p.x() + 0.5), y = raster::floorToInt(p.y() + 0.5),
                     z = raster::floorToInt(p.z() + 0.5);
  if (x < 0 || y < 0 || z < 0 || x >= d[0] || y >= d[1] || z >= d[2]) return -1;
  return x + d[0] * (y + d[1] * z);
}

struct Shell {
  std::vector<std::uint8_t> outer;  // empty: no shell
  double mm = 0;
  Eigen::Matrix3d normalToMm = Eigen::Matrix3d::Identity();
  std::array<double, 3> boxGrowth{0, 0, 0};
  // The pieces' rims (RasterOptions::pieceLabels): per piece tet, its faces on tissue that is
  // not the same piece, grown by pieceMm and written after the soft tissue where the rest
  // position holds the piece's own label.
  std::vector<std::uint8_t> pieceFaces;
  const Volume* pieceLabels = nullptr;
  double pieceMm = 0;
  std::array<double, 3> pieceGrowth{0, 0, 0};
  std::vector<char> boneLabel;  // per label value: some tet is a piece of it
  std::vector<int> pieceOf;     // per label value: the piece it is meshed in (0: none)
  // Soft tets holding a piece's tissue, written like rims through their piece's map
  // (raster/PieceGhosts.h): a bone end a joint demoted to soft tissue still moves rigidly.
  std::vector<raster::PieceGhost> ghosts;
  const Volume* rimParts = nullptr;  // RasterOptions::restParts, for the rims
  // A rim voxel is taken when its rest label is bone of the tet's own body part: a thin cortex
  // that Mesh_3 merged into its marrow's tets still moves with the bone.
  bool rimTakes(std::int32_t t, const Eigen::Vector3d& p, const Eigen::VectorXi& tetParts) const {
    const std::int64_t at = nearestVoxel(p, pieceLabels->dims());
    if (at < 0) return false;
    const double v = pieceLabels->valueAsDouble(at);
    if (!(v >= 0 && v < double(boneLabel.size())) || !boneLabel[std::size_t(v)]) return false;
    return !rimParts || rimParts->valueAsDouble(at) == tetParts[t];
  }
  const Volume* restParts = nullptr;  // RasterOptions::restParts
  const Eigen::VectorXi* tetParts = nullptr;
  // Per input voxel: a rest tet covers its centre, or the shell of a rest tet of its own part.
  std::vector<std::uint8_t> restCovered;
  // Whether tet t's shell writes the voxel whose rest position is p (input IJK): not where p is
  // another part's tissue that a rest tet already carries (wherever that tissue is now): a limb
  // that moved away from the trunk it rested on must not copy the trunk's side into the gap.
  bool takes(std::int32_t t, const Eigen::Vector3d& p) const {
    if (!restParts) return true;
    const std::int64_t at = nearestVoxel(p, restParts->dims());
    if (at < 0) return claimsBackground;
    const double part = restParts->valueAsDouble(at);
    if (part == 0) return claimsBackground;
    return part == (*tetParts)[t] || !restCovered[std::size_t(at)];
  }
  // Whether a shell voxel whose rest position is outside the body is written (and so closed to
  // the other shells). Labels: no, since writing background there only hides the voxel from
  // another tet's shell that reaches the skin (the torso's shell, first in tet order, took the
  // voxels beside a swung arm's skin and the arm lost 3 % of it on 8 mm slices). The field and
  // the image: yes, they continue smoothly past the skin.
  bool claimsBackground = true;
};

// Per piece tet, bit f for face f (opposite vertex f) when the tet across it is not a tet of the
// same piece label (soft tissue, another piece, or nothing).
std::vector<std::uint8_t> pieceRimFaces(const TransferMesh& mesh);

// The shell and rims of one scan (RasterOptions: shellMm, outerFaces, restParts, pieceLabels,
// bonePieces) for a mesh posed from `input` onto `output`.
Shell makeShell(const TransferMesh& mesh, const VolumeGeometry& input, const VolumeGeometry& output,
                const RasterOptions& options);

// Runs the scan over slabs of output slices on all cores (RasterScanRun.cpp). Each slab is
// written by one thread, tets in index order, so overlapping (folded) tets resolve the same way on
// every run; then the shell pass writes the voxels of the slab still uncovered.
//
// Where it writes: a sink per thread, each written in order, row interval by row interval
// (`write(k, j, i0, i1, rest0, step, tet)`), and flushed when its thread's work items are done
// (every voxel is in one work item, so a sink's late writes race with no other thread).
class ScanSink {
 public:
  virtual ~ScanSink() = default;
  virtual void write(std::int64_t k, std::int64_t j, std::int64_t i0, std::int64_t i1,
                     const Eigen::Vector3d& rest0, const Eigen::Vector3d& step,
                     std::int32_t tet) = 0;
  virtual void flush() {}
};
using ScanSinks = std::function<std::unique_ptr<ScanSink>()>;  // called once per thread

// Only slices [kBegin, kEnd) are scanned (the out-of-core path's slab; kEnd < 0: to the last), in
// the full grid's coordinates, so a slab's voxels get exactly the values the whole grid would.
void runScanWith(const ScanInput& in, const Shell& shell, const RasterOptions& options,
                 const std::string& stage, RasterReport* report, double frameSign,
                 const ScanSinks& sinks, std::int64_t kBegin = 0, std::int64_t kEnd = -1);

// runScan with a writer: a callable `write(k, j, i0, i1, rest0, step, tet)`, or one that batches
// its writes and gives each thread its own worker() (a callable with flush()).
template <class W, class = void>
struct HasWorker : std::false_type {};
template <class W>
struct HasWorker<W, std::void_t<decltype(std::declval<W&>().worker())>> : std::true_type {};

template <class Write>
struct DirectWorker {
  Write& write;
  template <class... Args>
  void operator()(Args&&... args) {
    write(std::forward<Args>(args)...);
  }
  void flush() {}
};

template <class Write>
auto workerOf(Write& write) {
  if constexpr (HasWorker<Write>::value)
    return write.worker();
  else
    return DirectWorker<Write>{write};
}

template <class Worker>
class ScanSinkOf final : public ScanSink {
 public:
  explicit ScanSinkOf(Worker worker) : worker_(std::move(worker)) {}
  void write(std::int64_t k, std::int64_t j, std::int64_t i0, std::int64_t i1,
             const Eigen::Vector3d& rest0, const Eigen::Vector3d& step, std::int32_t tet) override {
    worker_(k, j, i0, i1, rest0, step, tet);
  }
  void flush() override { worker_.flush(); }

 private:
  Worker worker_;
};

template <class Write>
void runScan(const ScanInput& in, const Shell& shell, const RasterOptions& options,
             const std::string& stage, RasterReport* report, double frameSign, Write&& write,
             std::int64_t kBegin = 0, std::int64_t kEnd = -1) {
  runScanWith(
      in, shell, options, stage, report, frameSign,
      [&write]() -> std::unique_ptr<ScanSink> {
        auto worker = workerOf(write);
        return std::make_unique<ScanSinkOf<decltype(worker)>>(std::move(worker));
      },
      kBegin, kEnd);
}

// Face f of tet t (the face opposite vertex f) as its three vertex indices, sorted: the key two
// tets sharing the face agree on.
inline std::array<int, 3> sortedFace(const TransferMesh& mesh, Eigen::Index t, int f) {
  std::array<int, 3> k;
  for (int c = 0, n = 0; c < 4; ++c)
    if (c != f) k[std::size_t(n++)] = mesh.tets(t, c);
  std::sort(k.begin(), k.end());
  return k;
}

// A slab [k0, k1) of output slices within the grid, or one line saying it is not.
inline void checkSlab(std::int64_t k0, std::int64_t k1, const VolumeGeometry& output) {
  if (k0 < 0 || k1 > output.dims[2] || k0 >= k1)
    throw Error("rasterizer: slab [" + std::to_string(k0) + ", " + std::to_string(k1) +
                ") is not within the output's " + std::to_string(output.dims[2]) + " slices");
}

inline double frameSign(const VolumeGeometry& output) {
  return output.ijkToRas.block<3, 3>(0, 0).determinant() < 0 ? -1.0 : 1.0;
}

template <class T>
T fromDouble(double v) {
  if constexpr (std::is_integral_v<T>) {
    const double r = std::round(v);
    return static_cast<T>(std::clamp(r, double(std::numeric_limits<T>::lowest()),
                                     double(std::numeric_limits<T>::max())));
  } else {
    return static_cast<T>(v);
  }
}

}  // namespace repose::raster
