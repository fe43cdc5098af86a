#include "repose/raster/Rasterizer.h"

#include "LabelVolumeRounding.h"
#include "RasterScan.h"
#include "repose/util/Error.h"
#include "repose/util/Parallel.h"

#include <Eigen/LU>
#include <algorithm>
#include <memory>
#include <array>
#include <atomic>
#include <map>
#include <unordered_map>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <limits>
#include <mutex>
#include <set>
#include <sstream>
#include <type_traits>

namespace repose {
using namespace raster;

// Per voxel of `input`: the tet of a whole piece that writes it at rest (its tets and rims),
// or -1.
static std::vector<std::int32_t> pieceOwnerTets(const TransferMesh& mesh,
                                                const VolumeGeometry& input,
                                                const RasterOptions& options) {
  std::vector<std::int32_t> owner(std::size_t(input.numVoxels()), -1);
  if (mesh.rigid.empty() || !options.pieceLabels) return owner;
  RasterOptions rest;
  rest.threads = options.threads;
  rest.shellMm = 0;  // only the pieces' rims
  rest.pieceLabels = options.pieceLabels;
  rest.bonePieces = options.bonePieces;
  rest.restParts = options.restParts;
  const ScanInput in = raster::makeScanInput(mesh, mesh.vertices, input, input);
  const std::int64_t nx = input.dims[0], plane = nx * input.dims[1];
  runScan(in, makeShell(mesh, input, input, rest), rest, "pieces at rest", nullptr,
          frameSign(input),
          [&](std::int64_t k, std::int64_t j, std::int64_t i0, std::int64_t i1,
              const Eigen::Vector3d&, const Eigen::Vector3d&, std::int32_t tet) {
            if (mesh.rigid[std::size_t(tet)])
              std::fill_n(owner.begin() + (k * plane + j * nx + i0), i1 - i0 + 1, tet);
          });
  return owner;
}

std::vector<std::uint8_t> outerFaces(const TransferMesh& mesh) {
  // Each face (t, f) by its vertices sorted (a < b < c), bucketed by a with a counting sort: a
  // face two tets share meets its twin among the few dozen faces of a's bucket. (A hash map of
  // all 4 x #tets faces had cost half a second of a 0.85 mm warp.)
  const Eigen::Index nt = mesh.tets.rows();
  struct Face {
    int b, c;
    std::int32_t t;
    std::int32_t f;
    bool operator<(const Face& o) const { return b != o.b ? b < o.b : c < o.c; }
  };
  int largest = -1;
  for (Eigen::Index t = 0; t < nt; ++t)
    for (int c = 0; c < 4; ++c) {
      if (mesh.tets(t, c) < 0)
        throw Error("outer faces: tet " + std::to_string(t) + " has a negative vertex index");
      largest = std::max(largest, mesh.tets(t, c));
    }
  std::vector<std::int64_t> first(std::size_t(largest) + 2, 0);
  for (Eigen::Index t = 0; t < nt; ++t)
    for (int f = 0; f < 4; ++f) ++first[std::size_t(sortedFace(mesh, t, f)[0]) + 1];
  for (std::size_t a = 1; a < first.size(); ++a) first[a] += first[a - 1];
  std::vector<Face> faces(std::size_t(4 * nt));
  {
    std::vector<std::int64_t> next(first.begin(), first.end() - 1);
    for (Eigen::Index t = 0; t < nt; ++t)
      for (int f = 0; f < 4; ++f) {
        const std::array<int, 3> k = sortedFace(mesh, t, f);
        faces[std::size_t(next[std::size_t(k[0])]++)] = Face{k[1], k[2], std::int32_t(t), f};
      }
  }
  // Boundary faces (used once), with where they lie at rest: a face whose rest place another
  // boundary face also occupies is a cut (two sides of a separation), not the body's surface.
  std::vector<std::uint8_t> outer(static_cast<std::size_t>(nt), 0);
  struct Place {
    std::array<double, 9> corners;  // the three vertices' rest positions, sorted
    std::int32_t t, f;
    bool operator<(const Place& o) const { return corners < o.corners; }
  };
  std::vector<Place> places;
  for (std::size_t a = 0; a + 1 < first.size(); ++a) {
    const auto begin = faces.begin() + first[a], end = faces.begin() + first[a + 1];
    std::sort(begin, end);
    for (auto run = begin; run != end;) {
      auto last = run + 1;
      while (last != end && last->b == run->b && last->c == run->c) ++last;
      if (last - run == 1) {
        outer[std::size_t(run->t)] |= std::uint8_t(1u << run->f);
        std::array<std::array<double, 3>, 3> p;
        const int v[3] = {int(a), run->b, run->c};
        for (int c = 0; c < 3; ++c)
          for (int x = 0; x < 3; ++x) p[std::size_t(c)][std::size_t(x)] = mesh.vertices(v[c], x);
        std::sort(p.begin(), p.end());
        Place place{{}, run->t, run->f};
        for (int c = 0; c < 3; ++c)
          for (int x = 0; x < 3; ++x) place.corners[std::size_t(3 * c + x)] = p[c][x];
        places.push_back(place);
      }
      run = last;
    }
  }
  std::sort(places.begin(), places.end());
  for (std::size_t i = 0; i < places.size();) {
    std::size_t j = i + 1;
    while (j < places.size() && places[j].corners == places[i].corners) ++j;
    if (j - i > 1)
      for (std::size_t m = i; m < j; ++m)
        outer[std::size_t(places[m].t)] &= std::uint8_t(~(1u << places[m].f));
    i = j;
  }
  return outer;
}

VolumeGeometry slicePlaneGrid(SliceOrientation orientation, double positionMm,
                              const Eigen::Vector3d& lo, const Eigen::Vector3d& hi, int pixels) {
  if (pixels < 1) throw Error("a slice needs at least one pixel");
  // In-plane RAS axes (u, v) and the normal n of each orientation.
  int u = 0, v = 1, n = 2;
  if (orientation == SliceOrientation::Coronal) u = 0, v = 2, n = 1;
  if (orientation == SliceOrientation::Sagittal) u = 1, v = 2, n = 0;
  const double pixel = std::max(hi[u] - lo[u], hi[v] - lo[v]) / pixels;
  if (!(pixel > 0) || !std::isfinite(pixel)) throw Error("a slice needs a box with an extent");
  VolumeGeometry g;
  g.dims = {pixels, pixels, 1};
  g.ijkToRas = Eigen::Matrix4d::Zero();
  g.ijkToRas(u, 0) = pixel, g.ijkToRas(v, 1) = pixel, g.ijkToRas(n, 2) = 1, g.ijkToRas(3, 3) = 1;
  g.ijkToRas(u, 3) = lo[u] + pixel / 2, g.ijkToRas(v, 3) = lo[v] + pixel / 2;
  g.ijkToRas(n, 3) = positionMm;
  return g;
}

VolumeGeometry deformedGrid(const VolumeGeometry& input, const Eigen::MatrixX3d& deformed,
                            double spacingMm, int marginVoxels) {
  input.validate("rasterizer input grid");
  if (deformed.rows() == 0 || !deformed.allFinite())
    throw Error("rasterizer: no finite deformed vertex to size the output grid");
  Eigen::Matrix3d M = input.ijkToRas.block<3, 3>(0, 0);
  // Output voxel k's centre lies at input.origin() + M (k + offset): with the input's spacing on
  // its centres (offset 0), with another spacing s as far from the input's faces as the two
  // spacings allow. Along an axis of input spacing r = (p/q) s (p/q in lowest terms), the
  // output's centres lie at one distance from the lattice of step s/q that holds every input
  // face: half a step puts them s/(2q) clear of every face (a whole ratio, q = 1: the output's
  // corners on the input's, each input voxel subdivided). The input's first face is r/2 before
  // its origin. Spacings without a small ratio (2.137 mm at 1 mm) are taken as q = 1.
  Eigen::Vector3d offset = Eigen::Vector3d::Zero();
  if (spacingMm > 0) {
    M = input.directions() * spacingMm;
    const Eigen::Vector3d inputSpacing = input.spacing();
    for (int c = 0; c < 3; ++c) {
      const double ratio = inputSpacing[c] / spacingMm;
      int q = 1;
      // Spacings come from files as single precision: a ratio within 1e-6 is taken as exact.
      while (q < 64 && std::fabs(q * ratio - std::round(q * ratio)) > 1e-6 * q * ratio) ++q;
      if (q == 64) q = 1;
      offset[c] = 1 / (2.0 * q) - ratio / 2;
    }
  }
  const Eigen::Matrix3d Minv = M.inverse();
  Eigen::Vector3d lo = Eigen::Vector3d::Constant(std::numeric_limits<double>::infinity()), hi = -lo;
  for (Eigen::Index v = 0; v < deformed.rows(); ++v) {
    const Eigen::Vector3d u = Minv * (deformed.row(v).transpose() - input.origin()) - offset;
    lo = lo.cwiseMin(u), hi = hi.cwiseMax(u);
  }
  VolumeGeometry g;
  Eigen::Vector3d start;
  double voxels = 1;
  for (int c = 0; c < 3; ++c) {
    start[c] = std::floor(lo[c]) - marginVoxels;
    const double extent = std::ceil(hi[c]) + marginVoxels - start[c] + 1;
    voxels *= extent;
    // A handle dragged far away makes a body kilometres long: refuse the grid with its size
    // before its dimensions overflow (a budget check refuses far smaller grids with its numbers).
    if (!(extent < double(std::int64_t(1) << 31)) || !(voxels <= kMaxGridVoxels)) {
      std::ostringstream m;
      m.precision(3);
      m << "the posed body spans "
        << (hi - lo).cwiseProduct(M.colwise().norm().transpose()).maxCoeff()
        << " mm: its grid would need more than " << kMaxGridVoxels
        << " voxels (a handle moved very far?)";
      throw Error(m.str());
    }
    g.dims[c] = static_cast<std::int64_t>(extent);
  }
  g.ijkToRas = Eigen::Matrix4d::Identity();
  g.ijkToRas.block<3, 3>(0, 0) = M;
  g.ijkToRas.block<3, 1>(0, 3) = input.origin() + M * (start + offset);
  return g;
}

namespace {

// What the label scan of one map, mesh, frame and grid sets up once: the scan's input, the shell
// and the pieces' rims, and for a map that holds the pieces (RasterOptions::pieceLabels) each rest
// voxel's piece tet and each piece tet's map back from output IJK to rest (input IJK).
struct LabelScanSetup {
  ScanInput in;
  Shell shell;
  std::vector<std::int32_t> owner;
  std::vector<Eigen::Matrix<double, 3, 4>> pieceBack;

  LabelScanSetup(const Volume& labels, const TransferMesh& mesh, const Eigen::MatrixX3d& deformed,
                 const VolumeGeometry& output, const RasterOptions& options)
      : in(raster::makeScanInput(mesh, deformed, labels.geometry(), output)),
        shell(makeShell(mesh, labels.geometry(), output, options)) {
    shell.claimsBackground = false;
    // The voxels the pieces carry (this map holds the pieces' labels). Soft tissue that samples
    // one of them (a piece's rim lying in a soft tet) where it has moved away from that piece
    // (a bend beside the piece) would copy the piece beside the place the piece itself puts it,
    // so it takes the tissue around instead; where it moves with the piece it keeps it.
    if (options.pieceLabels == &labels && !mesh.rigid.empty())
      owner = pieceOwnerTets(mesh, labels.geometry(), options);
    if (owner.empty()) return;
    pieceBack.resize(std::size_t(mesh.tets.rows()));
    for (Eigen::Index t = 0; t < mesh.tets.rows(); ++t) {
      if (!mesh.rigid[std::size_t(t)]) continue;
      Eigen::Matrix3d R, O;
      for (int c = 0; c < 3; ++c) {
        R.col(c) =
            in.rest[std::size_t(mesh.tets(t, c + 1))] - in.rest[std::size_t(mesh.tets(t, 0))];
        O.col(c) = in.out[std::size_t(mesh.tets(t, c + 1))] - in.out[std::size_t(mesh.tets(t, 0))];
      }
      const Eigen::Matrix3d B = R * O.inverse();
      pieceBack[std::size_t(t)].leftCols<3>() = B;
      pieceBack[std::size_t(t)].col(3) =
          in.rest[std::size_t(mesh.tets(t, 0))] - B * in.out[std::size_t(mesh.tets(t, 0))];
    }
  }
};

// The rest voxel output voxel (i,j,k) samples, at rest position p in tet `tet`: the nearest one,
// or, where soft tissue would copy a piece's voxel the piece has moved away from, the most common
// value around it that no piece owns.
template <class T>
struct LabelSource {
  const LabelScanSetup& setup;
  const TransferMesh& mesh;
  const T* src;  // layer 0: what the votes count
  std::array<std::int64_t, 3> d;

  // Whether the piece owning rest voxel `at` would sample another rest voxel at output voxel
  // (i,j,k): then the piece does not put `at` here (its own tets and rim put it where it does),
  // and a soft tet that samples `at` here would copy the piece beside itself. Decided in the
  // input's voxels, whatever the output grid (a thick-slice map posed onto 1 mm).
  bool movedAway(std::int64_t at, std::int64_t i, std::int64_t j, std::int64_t k) const {
    const std::int32_t p = setup.owner[std::size_t(at)];
    if (p < 0) return false;
    const Eigen::Vector3d x(double(at % d[0]), double((at / d[0]) % d[1]),
                            double(at / (d[0] * d[1])));
    const Eigen::Matrix<double, 3, 4>& back = setup.pieceBack[std::size_t(p)];
    const Eigen::Vector3d r =
        back.leftCols<3>() * Eigen::Vector3d(double(i), double(j), double(k)) + back.col(3);
    return (r - x).cwiseAbs().maxCoeff() > 0.5;
  }
  // The most common value around `at` among the voxels `skip` does not skip (`at` itself if
  // there is none), looking one voxel around first, then two.
  template <class Skip>
  std::int64_t mostCommonAround(std::int64_t at, Skip&& skip) const {
    const std::int64_t x = at % d[0], y = (at / d[0]) % d[1], z = at / (d[0] * d[1]);
    for (int r = 1; r <= 2; ++r) {
      std::map<double, int> votes;
      std::map<double, std::int64_t> where;
      for (int c = -r; c <= r; ++c)
        for (int b = -r; b <= r; ++b)
          for (int a = -r; a <= r; ++a) {
            const std::int64_t u = x + a, v = y + b, w = z + c;
            if (u < 0 || v < 0 || w < 0 || u >= d[0] || v >= d[1] || w >= d[2]) continue;
            const std::int64_t n = u + d[0] * (v + d[1] * w);
            if (skip(n)) continue;
            const double value = double(src[n]);
            if (++votes[value] == 1) where[value] = n;
          }
      std::int64_t best = -1;
      int most = 0;
      for (const auto& [value, n] : votes)
        if (n > most) most = n, best = where[value];
      if (best >= 0) return best;
    }
    return at;
  }
  // The most common value around `at` that no piece owns.
  std::int64_t aroundPiece(std::int64_t at) const {
    return mostCommonAround(at, [&](std::int64_t n) { return setup.owner[std::size_t(n)] >= 0; });
  }
  // Whether rest voxel `at`, written through piece tet `tet` (its own volume, a rim or a ghost it
  // hosts), is a piece's tissue of another body part: a bone that Mesh_3 let into the tet (a
  // scapula's tets lying on the ribs of an 8 mm grid). Its own part's pieces put it where it goes
  // (their tets, rims or ghosts); copied here, it would move with this part too (the ribs +1.6 %
  // under both arms raised, issue 64). A piece of the same part moves with the same group, and
  // rims and ghosts write only their own part's bone (Shell::rimTakes).
  bool foreignPiece(std::int64_t at, std::int32_t tet) const {
    const Volume* restParts = setup.shell.rimParts;
    const std::vector<int>& pieceOf = setup.shell.pieceOf;
    const T value = src[at];
    if (!restParts || !(value > T(0)) || double(value) >= double(pieceOf.size())) return false;
    return pieceOf[std::size_t(value)] != 0 && restParts->valueAsDouble(at) != mesh.labels[tet];
  }
  // The most common tissue around `at` that is no piece's label (`at` itself if there is none),
  // one voxel around first, then two: what a piece tet writes in place of another part's bone.
  // (Piece tets own every voxel they cover at rest, soft ones too, so aroundPiece would find
  // nothing inside them.)
  std::int64_t aroundBone(std::int64_t at) const {
    const std::vector<int>& pieceOf = setup.shell.pieceOf;
    return mostCommonAround(at, [&](std::int64_t n) {
      const T value = src[n];
      return !(value > T(0)) ||
             (double(value) < double(pieceOf.size()) && pieceOf[std::size_t(value)] != 0);
    });
  }
  std::int64_t operator()(std::int64_t i, std::int64_t j, std::int64_t k, const Eigen::Vector3d& p,
                          std::int32_t tet) const {
    std::int64_t at = nearestVoxel(p, d);
    if (at < 0 || setup.owner.empty()) return at;
    if (mesh.rigid[std::size_t(tet)]) return foreignPiece(at, tet) ? aroundBone(at) : at;
    return movedAway(at, i, j, k) ? aroundPiece(at) : at;
  }
};

// Output slices [k0, k1) of the labels into `dst` (per layer, (k1 - k0) slices from slice k0).
// Each thread notes (output voxel, input voxel) pairs and copies them in batches, the input
// voxels prefetched a few copies ahead: the voxels a slice or a slab samples lie scattered over
// G, and copying each as it is found waits on memory once per voxel.
template <class T>
void scanLabels(const LabelScanSetup& setup, const RasterOptions& options,
                const LabelSource<T>& source, const std::vector<const T*>& src,
                const std::vector<T*>& dst, const VolumeGeometry& output, std::int64_t k0,
                std::int64_t k1, RasterReport* report) {
  constexpr std::size_t kBatch = 4096;
  const std::int64_t nx = output.dims[0], plane = nx * output.dims[1];
  struct Copies {
    const LabelSource<T>& source;
    const std::vector<const T*>& src;
    const std::vector<T*>& dst;
    std::int64_t plane, nx, k0;
    std::vector<std::int64_t> to, from;
    void operator()(std::int64_t k, std::int64_t j, std::int64_t i0, std::int64_t i1,
                    Eigen::Vector3d p, const Eigen::Vector3d& step, std::int32_t tet) {
      const std::int64_t row = (k - k0) * plane + j * nx;
      for (std::int64_t i = i0; i <= i1; ++i, p += step) {
        to.push_back(row + i);
        from.push_back(source(i, j, k, p, tet));
      }
      if (to.size() >= kBatch) flush();
    }
    void flush() {
      constexpr std::size_t kAhead = 16;
      const std::size_t n = to.size();
      for (std::size_t c = 0; c < std::min(n, kAhead); ++c)
        if (from[c] >= 0) __builtin_prefetch(src[0] + from[c]);
      for (std::size_t c = 0; c < n; ++c) {
        if (c + kAhead < n && from[c + kAhead] >= 0) __builtin_prefetch(src[0] + from[c + kAhead]);
        for (std::size_t l = 0; l < src.size(); ++l)
          dst[l][to[c]] = from[c] >= 0 ? src[l][from[c]] : T(0);
      }
      to.clear(), from.clear();
    }
  };
  struct LabelWriter {
    const LabelSource<T>& source;
    const std::vector<const T*>& src;
    const std::vector<T*>& dst;
    std::int64_t plane, nx, k0;
    Copies worker() const {
      Copies c{source, src, dst, plane, nx, k0, {}, {}};
      c.to.reserve(kBatch + 1024), c.from.reserve(kBatch + 1024);
      return c;
    }
  };
  runScan(setup.in, setup.shell, options, "rasterize labels", report, frameSign(output),
          LabelWriter{source, src, dst, plane, nx, k0}, k0, k1);
}

// RasterOptions::preserveLabelVolumes over the whole grid, after the label scan has filled
// `dst`: one slab of every slice (LabelVolumeRounding.h), so the whole grid and a frame made
// slab by slab (LabelSlabRounding) choose the same voxels.
template <class T>
void roundLabelVolumes(const LabelScanSetup& setup, const Volume& labels, const TransferMesh& mesh,
                       const Eigen::MatrixX3d& deformed, const LabelSource<T>& source,
                       const RasterOptions& options, const VolumeGeometry& output, T* dst,
                       RasterReport* report) {
  const RoundingTargets t = roundingTargets(labels, mesh, deformed, setup.shell, options, output);
  if (report) report->roundingSkipped = t.skipped;
  if (!t.active()) return;
  std::vector<double> count(t.target.size(), 0.0);
  std::vector<RoundingCandidate> candidates;
  slabRoundingCandidates<T>(setup.in, setup.shell, options, output, t, labels.data<T>(),
                            labels.dims(), source, 0, output.dims[2], nullptr, dst, nullptr, count,
                            candidates);
  RoundingChooser chooser(t.target, count);
  std::int64_t taken = 0;
  for (const RoundingCandidate& c : candidates)
    if (chooser.offer(c)) dst[c.voxel] = T(c.to), ++taken;
  if (report) {
    report->roundedVoxels = taken;
    for (std::size_t v = 1; v < t.target.size(); ++v)
      if (t.soft[v] && t.target[v] > 0) report->labelTargets[int(v)] = t.target[v];
  }
}

}  // namespace

Volume rasterizeLabels(const Volume& labels, const TransferMesh& mesh,
                       const Eigen::MatrixX3d& deformed, const VolumeGeometry& output,
                       const RasterOptions& options, RasterReport* report) {
  checkDeformation(mesh, deformed);
  output.validate("rasterizer output grid");
  const LabelScanSetup setup(labels, mesh, deformed, output, options);
  Volume out(output, labels.scalarType(), labels.layers());
  out.setLabelMap(true);
  out.labels() = labels.labels();
  dispatchScalar(labels.scalarType(), [&](auto* tag) {
    using T = std::remove_pointer_t<decltype(tag)>;
    const int layers = labels.layers();
    std::vector<const T*> src(layers);
    std::vector<T*> dst(layers);
    for (int l = 0; l < layers; ++l) src[l] = labels.data<T>(l), dst[l] = out.data<T>(l);
    const LabelSource<T> source{setup, mesh, src[0], labels.dims()};
    scanLabels<T>(setup, options, source, src, dst, output, 0, output.dims[2], report);
    if (options.preserveLabelVolumes) {
      if constexpr (std::is_integral_v<T>) {
        if (layers == 1)
          roundLabelVolumes<T>(setup, labels, mesh, deformed, source, options, output, dst[0],
                               report);
        else if (report)
          report->roundingSkipped = "a map of " + std::to_string(layers) + " layers";
      } else if (report) {
        report->roundingSkipped = "a map of non-integer values";
      }
    }
  });
  return out;
}

struct LabelSlabs::Impl {
  const Volume& labels;
  const TransferMesh& mesh;
  Eigen::MatrixX3d deformed;
  VolumeGeometry output;
  RasterOptions options;
  LabelScanSetup setup;
  Impl(const Volume& l, const TransferMesh& m, const Eigen::MatrixX3d& d,
       const VolumeGeometry& grid, const RasterOptions& o)
      : labels(l), mesh(m), deformed(d), output(grid), options(o), setup(l, m, d, grid, o) {
    options.progress = nullptr;  // per slab (rasterize)
  }
};

LabelSlabs::LabelSlabs(const Volume& labels, const TransferMesh& mesh,
                       const Eigen::MatrixX3d& deformed, const VolumeGeometry& output,
                       const RasterOptions& options) {
  checkDeformation(mesh, deformed);
  output.validate("rasterizer output grid");
  impl_ = std::make_unique<Impl>(labels, mesh, deformed, output, options);
}

LabelSlabs::~LabelSlabs() = default;

std::int64_t LabelSlabs::sliceBytes() const {
  return impl_->output.dims[0] * impl_->output.dims[1] * impl_->labels.layers() *
         static_cast<std::int64_t>(scalarSize(impl_->labels.scalarType()));
}

void LabelSlabs::rasterize(std::int64_t k0, std::int64_t k1, void* slab, RasterReport& report,
                           const ProgressFn& progress) const {
  const Impl& r = *impl_;
  checkSlab(k0, k1, r.output);
  const std::int64_t plane = r.output.dims[0] * r.output.dims[1], values = plane * (k1 - k0);
  RasterOptions options = r.options;
  options.progress = progress;
  dispatchScalar(r.labels.scalarType(), [&](auto* tag) {
    using T = std::remove_pointer_t<decltype(tag)>;
    const int layers = r.labels.layers();
    std::vector<const T*> src(layers);
    std::vector<T*> dst(layers);
    for (int l = 0; l < layers; ++l)
      src[l] = r.labels.data<T>(l), dst[l] = static_cast<T*>(slab) + l * values;
    std::fill(dst[0], dst[0] + layers * values, T(0));
    const LabelSource<T> source{r.setup, r.mesh, src[0], r.labels.dims()};
    RasterReport part;
    scanLabels<T>(r.setup, options, source, src, dst, r.output, k0, k1, &part);
    report.voxelWrites += part.voxelWrites;
    report.shellVoxels += part.shellVoxels;
    report.invertedTets = part.invertedTets;
    report.flatTets = part.flatTets;
    for (std::int64_t v = 0; v < values; ++v)
      if (dst[0][v] != T(0)) ++report.labelVoxels[static_cast<int>(dst[0][v])];
  });
}

// The slabs' candidates are sorted runs, one per slab, in memory or (beyond the budget) in a
// temporary file; choose() merges them into one order, which is the order one sort of them all
// gives (roundingOrder is a total order), so the choice is the whole grid's.
struct LabelSlabRounding::Impl {
  const LabelSlabs::Impl& slabs;
  std::size_t memoryBytes;
  RoundingTargets targets;
  std::string skipped;
  std::vector<double> count;
  std::int64_t next = 0;
  struct Run {
    std::size_t first = 0, size = 0;  // in `held`, or in the file (candidates)
    bool onDisk = false;
  };
  std::vector<Run> runs;
  std::vector<RoundingCandidate> held;
  std::FILE* file = nullptr;
  std::size_t inFile = 0;                                     // candidates
  std::vector<std::pair<std::int64_t, std::int32_t>> chosen;  // (voxel, label), by voxel
  bool chosenYet = false;

  explicit Impl(const LabelSlabs::Impl& s, std::size_t budget) : slabs(s), memoryBytes(budget) {}
  ~Impl() {
    if (file) std::fclose(file);
  }
  void spill(std::vector<RoundingCandidate>& run) {
    if (!file && !(file = std::tmpfile()))
      throw Error("label-volume rounding: cannot make a temporary file for " +
                  std::to_string(run.size()) + " candidates");
    if (std::fseek(file, 0, SEEK_END) != 0 ||
        std::fwrite(run.data(), sizeof(RoundingCandidate), run.size(), file) != run.size())
      throw Error("label-volume rounding: cannot write its temporary file (disk full?)");
    runs.push_back({inFile, run.size(), true});
    inFile += run.size();
  }
};

LabelSlabRounding::LabelSlabRounding(const LabelSlabs& slabs, std::size_t memoryBytes)
    : impl_(std::make_unique<Impl>(*slabs.impl_, memoryBytes)) {
  Impl& r = *impl_;
  const LabelSlabs::Impl& s = r.slabs;
  if (s.labels.layers() != 1)
    r.skipped = "a map of " + std::to_string(s.labels.layers()) + " layers";
  else if (!isIntegerType(s.labels.scalarType()))
    r.skipped = "a map of non-integer values";
  if (!r.skipped.empty()) return;
  r.targets = roundingTargets(s.labels, s.mesh, s.deformed, s.setup.shell, s.options, s.output);
  r.skipped = r.targets.skipped;
  r.count.assign(r.targets.target.size(), 0.0);
}

LabelSlabRounding::~LabelSlabRounding() = default;

const std::string& LabelSlabRounding::skipped() const {
  return impl_->skipped;
}

std::size_t LabelSlabRounding::candidatesInMemory() const {
  return impl_->held.size() * sizeof(RoundingCandidate);
}
std::size_t LabelSlabRounding::candidatesOnDisk() const {
  return impl_->inFile * sizeof(RoundingCandidate);
}

void LabelSlabRounding::addSlab(std::int64_t k0, std::int64_t k1, const void* below,
                                const void* slab, const void* above) {
  Impl& r = *impl_;
  const LabelSlabs::Impl& s = r.slabs;
  if (r.chosenYet || k0 != r.next || k1 <= k0 || k1 > s.output.dims[2])
    throw Error("label-volume rounding: slab [" + std::to_string(k0) + ", " + std::to_string(k1) +
                ") out of order (expected from slice " + std::to_string(r.next) + ")");
  r.next = k1;
  if (!r.targets.active()) return;
  dispatchScalar(s.labels.scalarType(), [&](auto* tag) {
    using T = std::remove_pointer_t<decltype(tag)>;
    if constexpr (std::is_integral_v<T>) {
      const LabelSource<T> source{s.setup, s.mesh, s.labels.data<T>(), s.labels.dims()};
      std::vector<RoundingCandidate> run;
      slabRoundingCandidates<T>(s.setup.in, s.setup.shell, s.options, s.output, r.targets,
                                s.labels.data<T>(), s.labels.dims(), source, k0, k1,
                                static_cast<const T*>(below), static_cast<const T*>(slab),
                                static_cast<const T*>(above), r.count, run);
      if ((r.held.size() + run.size()) * sizeof(RoundingCandidate) > r.memoryBytes) {
        r.spill(run);
      } else {
        r.runs.push_back({r.held.size(), run.size(), false});
        r.held.insert(r.held.end(), run.begin(), run.end());
      }
    }
  });
}

void LabelSlabRounding::choose(RasterReport& report) {
  Impl& r = *impl_;
  if (r.chosenYet) throw Error("label-volume rounding: chosen twice");
  if (r.next != r.slabs.output.dims[2])
    throw Error("label-volume rounding: chosen before its last slab (slice " +
                std::to_string(r.next) + " of " + std::to_string(r.slabs.output.dims[2]) + ")");
  r.chosenYet = true;
  report.roundingSkipped = r.skipped;
  if (!r.targets.active()) return;
  // One cursor per run, a buffer each for the runs on disk; a heap of the runs' heads.
  struct Cursor {
    std::size_t at = 0, end = 0;
    std::vector<RoundingCandidate> buffer;
    std::size_t inBuffer = 0;  // next in buffer
    bool onDisk = false;
  };
  constexpr std::size_t kBuffer = 1 << 14;
  std::vector<Cursor> cursors(r.runs.size());
  auto head = [&](const Cursor& c) -> const RoundingCandidate& {
    return c.onDisk ? c.buffer[c.inBuffer] : r.held[c.at];
  };
  auto refill = [&](Cursor& c) {
    const std::size_t n = std::min(kBuffer, c.end - c.at);
    c.buffer.resize(n);
    if (std::fseek(r.file, long(c.at * sizeof(RoundingCandidate)), SEEK_SET) != 0 ||
        std::fread(c.buffer.data(), sizeof(RoundingCandidate), n, r.file) != n)
      throw Error("label-volume rounding: cannot read its temporary file");
    c.inBuffer = 0;
  };
  auto later = [&](std::size_t a, std::size_t b) {
    return roundingOrder(head(cursors[b]), head(cursors[a]));
  };
  std::vector<std::size_t> heap;
  for (std::size_t i = 0; i < r.runs.size(); ++i) {
    Cursor& c = cursors[i];
    c.at = r.runs[i].first, c.end = r.runs[i].first + r.runs[i].size, c.onDisk = r.runs[i].onDisk;
    if (c.at == c.end) continue;
    if (c.onDisk) refill(c);
    heap.push_back(i);
  }
  std::make_heap(heap.begin(), heap.end(), later);
  RoundingChooser chooser(r.targets.target, r.count);
  while (!heap.empty()) {
    std::pop_heap(heap.begin(), heap.end(), later);
    Cursor& c = cursors[heap.back()];
    const RoundingCandidate& best = head(c);
    if (chooser.offer(best)) r.chosen.emplace_back(best.voxel, best.to);
    ++c.at;
    if (c.onDisk && ++c.inBuffer == c.buffer.size() && c.at < c.end) refill(c);
    if (c.at == c.end)
      heap.pop_back();
    else
      std::push_heap(heap.begin(), heap.end(), later);
  }
  std::sort(r.chosen.begin(), r.chosen.end());
  r.held.clear(), r.held.shrink_to_fit();
  report.roundedVoxels = std::int64_t(r.chosen.size());
  for (std::size_t v = 1; v < r.targets.target.size(); ++v)
    if (r.targets.soft[v] && r.targets.target[v] > 0)
      report.labelTargets[int(v)] = r.targets.target[v];
}

std::int64_t LabelSlabRounding::finalLabel(std::int64_t voxel, std::int64_t sampled) const {
  const Impl& r = *impl_;
  if (!r.chosenYet) throw Error("label-volume rounding: asked before the choice");
  const auto it = std::lower_bound(r.chosen.begin(), r.chosen.end(),
                                   std::pair<std::int64_t, std::int32_t>(voxel, INT32_MIN));
  return it != r.chosen.end() && it->first == voxel ? std::int64_t(it->second) : sampled;
}

void LabelSlabRounding::apply(std::int64_t k0, std::int64_t k1, void* slab) const {
  const Impl& r = *impl_;
  if (!r.chosenYet) throw Error("label-volume rounding: applied before the choice");
  const std::int64_t plane = r.slabs.output.dims[0] * r.slabs.output.dims[1];
  auto it = std::lower_bound(r.chosen.begin(), r.chosen.end(),
                             std::pair<std::int64_t, std::int32_t>(k0 * plane, INT32_MIN));
  dispatchScalar(r.slabs.labels.scalarType(), [&](auto* tag) {
    using T = std::remove_pointer_t<decltype(tag)>;
    T* v = static_cast<T*>(slab);
    for (; it != r.chosen.end() && it->first < k1 * plane; ++it)
      v[it->first - k0 * plane] = T(it->second);
  });
}

struct LabelSlabRasterizer::Impl {
  SliceCache& input;
  VolumeGeometry output;
  RasterOptions options;
  raster::ScanInput in;
  Shell shell;
  Impl(SliceCache& cache, const TransferMesh& mesh, const Eigen::MatrixX3d& deformed,
       const VolumeGeometry& grid, const RasterOptions& o)
      : input(cache),
        output(grid),
        options(o),
        in(raster::makeScanInput(mesh, deformed, cache.layout().geometry, grid)),
        shell(makeShell(mesh, cache.layout().geometry, grid, o)) {
    options.threads = 1;  // the slice cache is not shared between threads
  }
};

LabelSlabRasterizer::LabelSlabRasterizer(SliceCache& input, const TransferMesh& mesh,
                                         const Eigen::MatrixX3d& deformed,
                                         const VolumeGeometry& output,
                                         const RasterOptions& options) {
  checkDeformation(mesh, deformed);
  output.validate("rasterizer output grid");
  impl_ = std::make_unique<Impl>(input, mesh, deformed, output, options);
}

LabelSlabRasterizer::~LabelSlabRasterizer() = default;

std::int64_t LabelSlabRasterizer::sliceBytes() const {
  return impl_->output.dims[0] * impl_->output.dims[1] *
         static_cast<std::int64_t>(scalarSize(impl_->input.layout().type));
}

void LabelSlabRasterizer::rasterize(std::int64_t k0, std::int64_t k1, void* slab,
                                    RasterReport& report, const ProgressFn& progress) {
  Impl& r = *impl_;
  checkSlab(k0, k1, r.output);
  const NiftiLayout& layout = r.input.layout();
  const auto d = layout.geometry.dims;
  const std::int64_t nx = r.output.dims[0], plane = nx * r.output.dims[1];
  RasterOptions one = r.options;
  one.progress = progress;
  dispatchScalar(layout.type, [&](auto* tag) {
    using T = std::remove_pointer_t<decltype(tag)>;
    T* buffer = static_cast<T*>(slab);
    std::fill(buffer, buffer + plane * (k1 - k0), T(0));
    RasterReport part;
    runScan(
        r.in, r.shell, one, "rasterize labels (out of core)", &part, frameSign(r.output),
        [&](std::int64_t k, std::int64_t j, std::int64_t i0, std::int64_t i1, Eigen::Vector3d p,
            const Eigen::Vector3d& step, std::int32_t) {
          T* row = buffer + (k - k0) * plane + j * nx;
          for (std::int64_t i = i0; i <= i1; ++i, p += step) {
            const std::int64_t at = nearestVoxel(p, d), inPlane = d[0] * d[1];
            row[i] =
                at >= 0 ? static_cast<const T*>(r.input.slice(at / inPlane))[at % inPlane] : T(0);
          }
        },
        k0, k1);
    report.voxelWrites += part.voxelWrites;
    report.shellVoxels += part.shellVoxels;
    report.invertedTets = part.invertedTets;
    report.flatTets = part.flatTets;
    for (std::int64_t v = 0; v < plane * (k1 - k0); ++v)
      if (buffer[v] != T(0)) ++report.labelVoxels[static_cast<int>(buffer[v])];
  });
}

Volume rasterizeCoverage(const TransferMesh& mesh, const Eigen::MatrixX3d& deformed,
                         const VolumeGeometry& output, const RasterOptions& options) {
  checkDeformation(mesh, deformed);
  output.validate("rasterizer output grid");
  const ScanInput in = raster::makeScanInput(mesh, deformed, output, output);
  Volume out(output, ScalarType::UInt8);
  std::uint8_t* dst = out.data<std::uint8_t>();
  const std::int64_t nx = output.dims[0], plane = nx * output.dims[1];
  runScan(in, Shell(), options, "coverage", nullptr, frameSign(output),
          [&](std::int64_t k, std::int64_t j, std::int64_t i0, std::int64_t i1,
              const Eigen::Vector3d&, const Eigen::Vector3d&, std::int32_t) {
            std::uint8_t* row = dst + k * plane + j * nx;
            for (std::int64_t i = i0; i <= i1; ++i)
              if (row[i] < 255) ++row[i];
          });
  return out;
}

}  // namespace repose
