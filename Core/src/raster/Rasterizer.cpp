#include "repose/raster/Rasterizer.h"

#include "TetScan.h"
#include "repose/io/NiftiIO.h"
#include "repose/util/Error.h"
#include "repose/util/Parallel.h"

#include <Eigen/LU>
#include <algorithm>
#include <array>
#include <atomic>
#include <map>
#include <unordered_map>
#include <cmath>
#include <limits>
#include <mutex>
#include <sstream>
#include <type_traits>

namespace repose {
namespace {

using raster::ScanInput;
using raster::ScanTet;

void checkDeformation(const TransferMesh& mesh, const Eigen::MatrixX3d& deformed) {
  if (deformed.rows() != mesh.vertices.rows())
    throw Error("rasterizer: " + std::to_string(deformed.rows()) + " deformed positions for " +
                std::to_string(mesh.vertices.rows()) + " mesh vertices");
  if (!deformed.allFinite()) throw Error("rasterizer: deformed positions are not finite");
}

// Inverted and flat deformed tets, for the report. Rest tets are positive in RAS; the output
// grid's handedness is taken out.
void countBadTets(const ScanInput& in, double frameSign, RasterReport& r) {
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
struct Shell {
  std::vector<std::uint8_t> outer;  // empty: no shell
  double mm = 0;
  Eigen::Matrix3d normalToMm = Eigen::Matrix3d::Identity();
  std::array<double, 3> boxGrowth{0, 0, 0};
};

Shell makeShell(const TransferMesh& mesh, const VolumeGeometry& input, const VolumeGeometry& output,
                const RasterOptions& options) {
  Shell sh;
  sh.mm = options.shellMm < 0 ? 2 * std::max(input.spacing().maxCoeff(), mesh.sourceSpacingMm)
                              : options.shellMm;
  if (sh.mm <= 0) return sh;
  sh.outer = options.outerFaces ? *options.outerFaces : outerFaces(mesh);
  if (sh.outer.size() != static_cast<std::size_t>(mesh.tets.rows()))
    throw Error("rasterizer: outer-face flags do not match the mesh");
  const Eigen::Matrix3d M = output.ijkToRas.block<3, 3>(0, 0);
  sh.normalToMm = M.inverse().transpose();
  const Eigen::Matrix3d Minv = M.inverse();
  for (int c = 0; c < 3; ++c) sh.boxGrowth[c] = sh.mm * Minv.row(c).norm();
  return sh;
}

// Runs the scan over slabs of output slices on all cores. Each slab is written by one thread,
// tets in index order, so overlapping (folded) tets resolve the same way on every run; then the
// shell pass writes the voxels of the slab still uncovered.
template <class Write>
void runScan(const ScanInput& in, const Shell& shell, const RasterOptions& options,
             const std::string& stage, RasterReport* report, double frameSign, Write&& write,
             std::int64_t kBegin = 0, std::int64_t kEnd = -1) {
  // Only slices [kBegin, kEnd) are scanned (the out-of-core path's slab), in the full grid's
  // coordinates, so a slab's voxels get exactly the values the whole grid would.
  if (kEnd < 0) kEnd = in.dims[2];
  const Eigen::MatrixX4i& T = *in.tets;
  const Eigen::Index nt = T.rows();
  // Each tet's box in j and k (grown for the shell if it has an outer face), to skip it cheaply
  // outside a work item. Only tets whose box meets the grid are kept: for a live slice, the few
  // crossing it, found with plain comparisons first since every tet is looked at.
  const bool withShell = !shell.outer.empty();
  // Selected in parallel chunks, then joined in tet order (the order folds are resolved in).
  struct Candidates {
    std::vector<std::int32_t> tet, jmin, jmax, kmin, kmax;
  };
  const int selectThreads = resolveThreads(options.threads);
  std::vector<Candidates> parts(static_cast<std::size_t>(selectThreads));
  parallelFor(
      selectThreads, selectThreads,
      [&](std::int64_t pb, std::int64_t pe) {
        for (std::int64_t part = pb; part < pe; ++part) {
          Candidates& c = parts[static_cast<std::size_t>(part)];
          for (Eigen::Index t = nt * part / selectThreads; t < nt * (part + 1) / selectThreads;
               ++t) {
            const double growth = withShell && shell.outer[t] ? 1.0 : 0.0;
            const Eigen::Vector3d &p0 = in.out[T(t, 0)], &p1 = in.out[T(t, 1)],
                                  &p2 = in.out[T(t, 2)], &p3 = in.out[T(t, 3)];
            const double zlo = std::min(std::min(p0.z(), p1.z()), std::min(p2.z(), p3.z())) -
                               growth * shell.boxGrowth[2];
            const double zhi = std::max(std::max(p0.z(), p1.z()), std::max(p2.z(), p3.z())) +
                               growth * shell.boxGrowth[2];
            if (zhi < double(kBegin) || zlo > double(kEnd - 1)) continue;
            const double ylo = std::min(std::min(p0.y(), p1.y()), std::min(p2.y(), p3.y())) -
                               growth * shell.boxGrowth[1];
            const double yhi = std::max(std::max(p0.y(), p1.y()), std::max(p2.y(), p3.y())) +
                               growth * shell.boxGrowth[1];
            if (yhi < 0 || ylo > double(in.dims[1] - 1)) continue;
            c.tet.push_back(static_cast<std::int32_t>(t));
            c.kmin.push_back(static_cast<std::int32_t>(std::max(double(kBegin), std::ceil(zlo))));
            c.kmax.push_back(
                static_cast<std::int32_t>(std::min(double(kEnd - 1), std::floor(zhi))));
            c.jmin.push_back(static_cast<std::int32_t>(std::max(0.0, std::ceil(ylo))));
            c.jmax.push_back(
                static_cast<std::int32_t>(std::min(double(in.dims[1] - 1), std::floor(yhi))));
          }
        }
      },
      1);
  // Tets of whole pieces (bones, organs) go last, so where a fold of soft tissue overlaps a bone
  // the bone keeps its voxels: soft tissue is what a bend squeezes.
  std::vector<std::int32_t> candidates, jmin, jmax, kmin, kmax;
  const bool withPieces = in.pieces && !in.pieces->empty();
  for (const int pass : {0, 1}) {
    if (pass == 1 && !withPieces) break;
    for (const Candidates& c : parts)
      for (std::size_t n = 0; n < c.tet.size(); ++n) {
        if (withPieces && ((*in.pieces)[std::size_t(c.tet[n])] != 0) != (pass == 1)) continue;
        candidates.push_back(c.tet[n]);
        jmin.push_back(c.jmin[n]), jmax.push_back(c.jmax[n]);
        kmin.push_back(c.kmin[n]), kmax.push_back(c.kmax[n]);
      }
  }
  // Work items: slabs of whole k-slices, or for thin grids (a live slice is one voxel thick)
  // bands of j-rows across all slices, so every core has work either way.
  const int threads = resolveThreads(options.threads);
  const std::int64_t depth = kEnd - kBegin;
  const bool bands = depth < 2 * threads;
  const std::int64_t split = bands ? in.dims[1] : depth;
  const std::int64_t slabs = std::max<std::int64_t>(1, std::min<std::int64_t>(split, 8 * threads));
  const std::int64_t nx = in.dims[0];
  std::atomic<std::int64_t> writes{0}, shellWrites{0}, done{0};
  std::atomic<bool> stop{false};
  std::mutex progressMutex;
  parallelFor(
      slabs, threads,
      [&](std::int64_t sb, std::int64_t se) {
        std::int64_t localWrites = 0, localShell = 0;
        std::vector<std::uint8_t> covered;
        for (std::int64_t slab = sb; slab < se && !stop; ++slab) {
          const std::int64_t s0 = split * slab / slabs, s1 = split * (slab + 1) / slabs;
          const std::int64_t k0 = kBegin + (bands ? 0 : s0), k1 = bands ? kEnd : kBegin + s1;
          const std::int64_t j0 = bands ? s0 : 0, j1 = bands ? s1 : in.dims[1];
          // Voxels of this work item already written, row by row (rows j0..j1 of slices k0..k1).
          const std::int64_t rows = j1 - j0;
          if (!shell.outer.empty())
            covered.assign(static_cast<std::size_t>(nx * rows * (k1 - k0)), 0);
          ScanTet s;
          for (std::size_t c = 0; c < candidates.size(); ++c) {
            const std::int32_t t = candidates[c];
            if (kmax[c] < k0 || kmin[c] >= k1 || jmax[c] < j0 || jmin[c] >= j1 ||
                !raster::prepareTet(in, t, s))
              continue;
            raster::scanTet(s, k0, k1, j0, j1,
                            [&](std::int64_t k, std::int64_t j, std::int64_t i0, std::int64_t i1,
                                const Eigen::Vector3d& rest0, const Eigen::Vector3d& step) {
                              localWrites += i1 - i0 + 1;
                              if (!covered.empty())
                                std::fill_n(
                                    covered.begin() + (((k - k0) * rows + (j - j0)) * nx + i0),
                                    i1 - i0 + 1, std::uint8_t(1));
                              write(k, j, i0, i1, rest0, step);
                            });
          }
          for (std::size_t c = 0; c < candidates.size() && !shell.outer.empty(); ++c) {
            const std::int32_t t = candidates[c];
            if (!shell.outer[t] || kmax[c] < k0 || kmin[c] >= k1 || jmax[c] < j0 || jmin[c] >= j1 ||
                !raster::prepareShell(in, t, shell.outer[t], shell.mm, shell.normalToMm,
                                      shell.boxGrowth, s))
              continue;
            raster::scanTet(s, k0, k1, j0, j1,
                            [&](std::int64_t k, std::int64_t j, std::int64_t i0, std::int64_t i1,
                                const Eigen::Vector3d& rest0, const Eigen::Vector3d& step) {
                              std::uint8_t* c = covered.data() + ((k - k0) * rows + (j - j0)) * nx;
                              for (std::int64_t a = i0; a <= i1;) {
                                if (c[a]) {
                                  ++a;
                                  continue;
                                }
                                std::int64_t b = a;
                                while (b + 1 <= i1 && !c[b + 1]) ++b;
                                std::fill(c + a, c + b + 1, std::uint8_t(1));
                                localShell += b - a + 1;
                                write(k, j, a, b, Eigen::Vector3d(rest0 + double(a - i0) * step),
                                      step);
                                a = b + 1;
                              }
                            });
          }
          const double fraction = double(++done) / double(slabs);
          std::lock_guard<std::mutex> lock(progressMutex);
          try {
            reportProgress(options.progress, fraction, stage);
          } catch (...) {
            stop = true;
            throw;
          }
        }
        writes += localWrites;
        shellWrites += localShell;
      },
      1);
  if (report) {
    *report = RasterReport();
    report->voxelWrites = writes;
    report->shellVoxels = shellWrites;
    countBadTets(in, frameSign, *report);
  }
}

double frameSign(const VolumeGeometry& output) {
  return output.ijkToRas.block<3, 3>(0, 0).determinant() < 0 ? -1.0 : 1.0;
}

// Index of the input voxel nearest to the rest position p (input IJK), or -1 beyond the grid.
inline std::int64_t nearestVoxel(const Eigen::Vector3d& p, const std::array<std::int64_t, 3>& d) {
  const std::int64_t x = static_cast<std::int64_t>(std::floor(p.x() + 0.5)),
                     y = static_cast<std::int64_t>(std::floor(p.y() + 0.5)),
                     z = static_cast<std::int64_t>(std::floor(p.z() + 0.5));
  if (x < 0 || y < 0 || z < 0 || x >= d[0] || y >= d[1] || z >= d[2]) return -1;
  return x + d[0] * (y + d[1] * z);
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

}  // namespace

std::vector<std::uint8_t> outerFaces(const TransferMesh& mesh) {
  using Key = std::array<int, 3>;
  struct KeyHash {
    std::size_t operator()(const Key& k) const {
      return (std::size_t(k[0]) * 73856093u) ^ (std::size_t(k[1]) * 19349663u) ^
             (std::size_t(k[2]) * 83492791u);
    }
  };
  const Eigen::Index nt = mesh.tets.rows();
  std::unordered_map<Key, int, KeyHash> uses;
  uses.reserve(static_cast<std::size_t>(2 * nt + 16));
  auto faceKey = [&](Eigen::Index t, int f) {
    Key k;
    for (int c = 0, n = 0; c < 4; ++c)
      if (c != f) k[n++] = mesh.tets(t, c);
    std::sort(k.begin(), k.end());
    return k;
  };
  for (Eigen::Index t = 0; t < nt; ++t)
    for (int f = 0; f < 4; ++f) ++uses[faceKey(t, f)];
  // Boundary faces, then drop those whose rest place another boundary face also occupies (cuts).
  std::vector<std::uint8_t> outer(static_cast<std::size_t>(nt), 0);
  std::map<std::array<double, 9>, int> places;
  auto place = [&](const Key& k) {
    std::array<std::array<double, 3>, 3> p;
    for (int c = 0; c < 3; ++c)
      for (int a = 0; a < 3; ++a) p[c][a] = mesh.vertices(k[c], a);
    std::sort(p.begin(), p.end());
    std::array<double, 9> flat;
    for (int c = 0; c < 3; ++c)
      for (int a = 0; a < 3; ++a) flat[3 * c + a] = p[c][a];
    return flat;
  };
  for (Eigen::Index t = 0; t < nt; ++t)
    for (int f = 0; f < 4; ++f) {
      const Key k = faceKey(t, f);
      if (uses[k] == 1) {
        outer[t] |= std::uint8_t(1u << f);
        ++places[place(k)];
      }
    }
  for (Eigen::Index t = 0; t < nt; ++t)
    for (int f = 0; f < 4; ++f)
      if ((outer[t] & (1u << f)) && places[place(faceKey(t, f))] > 1)
        outer[t] &= std::uint8_t(~(1u << f));
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
  if (spacingMm > 0) M = input.directions() * spacingMm;
  const Eigen::Matrix3d Minv = M.inverse();
  Eigen::Vector3d lo = Eigen::Vector3d::Constant(std::numeric_limits<double>::infinity()), hi = -lo;
  for (Eigen::Index v = 0; v < deformed.rows(); ++v) {
    const Eigen::Vector3d u = Minv * (deformed.row(v).transpose() - input.origin());
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
  g.ijkToRas.block<3, 1>(0, 3) = input.origin() + M * start;
  return g;
}

Volume rasterizeLabels(const Volume& labels, const TransferMesh& mesh,
                       const Eigen::MatrixX3d& deformed, const VolumeGeometry& output,
                       const RasterOptions& options, RasterReport* report) {
  checkDeformation(mesh, deformed);
  output.validate("rasterizer output grid");
  const ScanInput in = raster::makeScanInput(mesh, deformed, labels.geometry(), output);
  Volume out(output, labels.scalarType(), labels.layers());
  out.setLabelMap(true);
  out.labels() = labels.labels();
  const auto d = labels.dims();
  const std::int64_t nx = output.dims[0], ny = output.dims[1], plane = nx * ny;
  dispatchScalar(labels.scalarType(), [&](auto* tag) {
    using T = std::remove_pointer_t<decltype(tag)>;
    const int layers = labels.layers();
    std::vector<const T*> src(layers);
    std::vector<T*> dst(layers);
    for (int l = 0; l < layers; ++l) src[l] = labels.data<T>(l), dst[l] = out.data<T>(l);
    runScan(in, makeShell(mesh, labels.geometry(), output, options), options, "rasterize labels",
            report, frameSign(output),
            [&](std::int64_t k, std::int64_t j, std::int64_t i0, std::int64_t i1, Eigen::Vector3d p,
                const Eigen::Vector3d& step) {
              const std::int64_t row = k * plane + j * nx;
              for (std::int64_t i = i0; i <= i1; ++i, p += step) {
                const std::int64_t at = nearestVoxel(p, d);
                for (int l = 0; l < layers; ++l) dst[l][row + i] = at >= 0 ? src[l][at] : T(0);
              }
            });
  });
  return out;
}

void rasterizeLabelsToFile(SliceCache& input, const TransferMesh& mesh,
                           const Eigen::MatrixX3d& deformed, const VolumeGeometry& output,
                           const std::string& path, std::size_t slabBytes,
                           const RasterOptions& options, RasterReport* report) {
  checkDeformation(mesh, deformed);
  output.validate(path);
  const NiftiLayout& layout = input.layout();
  const ScanInput in = raster::makeScanInput(mesh, deformed, layout.geometry, output);
  const Shell shell = makeShell(mesh, layout.geometry, output, options);
  const auto d = layout.geometry.dims;
  const std::int64_t nx = output.dims[0], plane = nx * output.dims[1];
  const std::int64_t slab = std::max<std::int64_t>(
      1, std::int64_t(slabBytes / (std::size_t(plane) * scalarSize(layout.type))));
  NiftiSlabWriter writer(path, output, layout.type, layout.labels, true);
  RasterOptions one = options;
  one.threads = 1;
  RasterReport total;
  dispatchScalar(layout.type, [&](auto* tag) {
    using T = std::remove_pointer_t<decltype(tag)>;
    std::vector<T> buffer;
    for (std::int64_t k0 = 0; k0 < output.dims[2]; k0 += slab) {
      const std::int64_t k1 = std::min(output.dims[2], k0 + slab);
      buffer.assign(static_cast<std::size_t>(plane * (k1 - k0)), T(0));
      one.progress = [&](double f, const std::string& stage) {
        return !options.progress ||
               options.progress((double(k0) + f * double(k1 - k0)) / double(output.dims[2]), stage);
      };
      RasterReport part;
      runScan(
          in, shell, one, "rasterize labels (out of core)", &part, frameSign(output),
          [&](std::int64_t k, std::int64_t j, std::int64_t i0, std::int64_t i1, Eigen::Vector3d p,
              const Eigen::Vector3d& step) {
            T* row = buffer.data() + (k - k0) * plane + j * nx;
            for (std::int64_t i = i0; i <= i1; ++i, p += step) {
              const std::int64_t at = nearestVoxel(p, d), inPlane = d[0] * d[1];
              row[i] =
                  at >= 0 ? static_cast<const T*>(input.slice(at / inPlane))[at % inPlane] : T(0);
            }
          },
          k0, k1);
      total.voxelWrites += part.voxelWrites;
      total.shellVoxels += part.shellVoxels;
      total.invertedTets = part.invertedTets;
      total.flatTets = part.flatTets;
      for (const T v : buffer)
        if (v != T(0)) ++total.labelVoxels[static_cast<int>(v)];
      writer.writeSlices(buffer.data(), k1 - k0);
    }
  });
  writer.finish();
  if (report) *report = total;
}

Volume rasterizeImage(const Volume& image, const TransferMesh& mesh,
                      const Eigen::MatrixX3d& deformed, const VolumeGeometry& output,
                      double background, const RasterOptions& options, RasterReport* report) {
  checkDeformation(mesh, deformed);
  output.validate("rasterizer output grid");
  if (image.layers() != 1) throw Error("rasterizer: an intensity image must have one layer");
  const ScanInput in = raster::makeScanInput(mesh, deformed, image.geometry(), output);
  Volume out(output, image.scalarType());
  const auto d = image.dims();
  const std::int64_t nx = output.dims[0], ny = output.dims[1], plane = nx * ny;
  dispatchScalar(image.scalarType(), [&](auto* tag) {
    using T = std::remove_pointer_t<decltype(tag)>;
    const T fill = fromDouble<T>(background);
    T* dst = out.data<T>();
    std::fill(dst, dst + out.numVoxels(), fill);
    const T* src = image.data<T>();
    runScan(in, makeShell(mesh, image.geometry(), output, options), options, "rasterize image",
            report, frameSign(output),
            [&](std::int64_t k, std::int64_t j, std::int64_t i0, std::int64_t i1, Eigen::Vector3d p,
                const Eigen::Vector3d& step) {
              const std::int64_t row = k * plane + j * nx;
              for (std::int64_t i = i0; i <= i1; ++i, p += step) {
                // Trilinear over the 8 voxel centres around p, clamped at the grid's edge;
                // background beyond half a voxel outside it.
                if (!(p.x() >= -0.5 && p.y() >= -0.5 && p.z() >= -0.5 && p.x() <= d[0] - 0.5 &&
                      p.y() <= d[1] - 0.5 && p.z() <= d[2] - 0.5)) {
                  dst[row + i] = fill;
                  continue;
                }
                const double fx = std::floor(p.x()), fy = std::floor(p.y()), fz = std::floor(p.z());
                const double tx = p.x() - fx, ty = p.y() - fy, tz = p.z() - fz;
                auto clampTo = [](double f, std::int64_t n) {
                  return std::clamp<std::int64_t>(std::int64_t(f), 0, n - 1);
                };
                const std::int64_t x = clampTo(fx, d[0]), y = clampTo(fy, d[1]),
                                   z = clampTo(fz, d[2]);
                const std::int64_t x1 = clampTo(fx + 1, d[0]), y1 = clampTo(fy + 1, d[1]),
                                   z1 = clampTo(fz + 1, d[2]);
                auto v = [&](std::int64_t a, std::int64_t b, std::int64_t c) {
                  return double(src[a + d[0] * (b + d[1] * c)]);
                };
                const double c00 = v(x, y, z) * (1 - tx) + v(x1, y, z) * tx;
                const double c10 = v(x, y1, z) * (1 - tx) + v(x1, y1, z) * tx;
                const double c01 = v(x, y, z1) * (1 - tx) + v(x1, y, z1) * tx;
                const double c11 = v(x, y1, z1) * (1 - tx) + v(x1, y1, z1) * tx;
                const double c0 = c00 * (1 - ty) + c10 * ty, c1 = c01 * (1 - ty) + c11 * ty;
                dst[row + i] = fromDouble<T>(c0 * (1 - tz) + c1 * tz);
              }
            });
  });
  return out;
}

std::vector<float> rasterizeDisplacement(const TransferMesh& mesh, const Eigen::MatrixX3d& deformed,
                                         const VolumeGeometry& input, const VolumeGeometry& output,
                                         const RasterOptions& options) {
  checkDeformation(mesh, deformed);
  output.validate("rasterizer output grid");
  input.validate("rasterizer input grid");
  const ScanInput in = raster::makeScanInput(mesh, deformed, input, output);
  const std::int64_t n = output.numVoxels();
  std::vector<float> field(static_cast<std::size_t>(3 * n));
  // Uncovered voxels aim at one point ten diagonals below the input grid's lower corner.
  const auto [lo, hi] = input.rasBounds();
  const Eigen::Vector3d outside = lo - 10 * (hi - lo) - Eigen::Vector3d::Constant(1000);
  const Eigen::Matrix3d O = output.ijkToRas.block<3, 3>(0, 0), I = input.ijkToRas.block<3, 3>(0, 0);
  const Eigen::Vector3d oo = output.origin(), io = input.origin();
  parallelFor(
      output.dims[2], options.threads,
      [&](std::int64_t k0, std::int64_t k1) {
        for (std::int64_t k = k0; k < k1; ++k)
          for (std::int64_t j = 0; j < output.dims[1]; ++j)
            for (std::int64_t i = 0; i < output.dims[0]; ++i) {
              const Eigen::Vector3d d =
                  outside - (O * Eigen::Vector3d(double(i), double(j), double(k)) + oo);
              float* f = &field[static_cast<std::size_t>(
                  3 * (i + output.dims[0] * (j + output.dims[1] * k)))];
              f[0] = float(d.x()), f[1] = float(d.y()), f[2] = float(d.z());
            }
      },
      1);
  const std::int64_t nx = output.dims[0], plane = nx * output.dims[1];
  runScan(in, makeShell(mesh, input, output, options), options, "displacement field", nullptr,
          frameSign(output),
          [&](std::int64_t k, std::int64_t j, std::int64_t i0, std::int64_t i1, Eigen::Vector3d p,
              const Eigen::Vector3d& step) {
            for (std::int64_t i = i0; i <= i1; ++i, p += step) {
              const Eigen::Vector3d d =
                  (I * p + io) - (O * Eigen::Vector3d(double(i), double(j), double(k)) + oo);
              float* f = &field[static_cast<std::size_t>(3 * (k * plane + j * nx + i))];
              f[0] = float(d.x()), f[1] = float(d.y()), f[2] = float(d.z());
            }
          });
  return field;
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
              const Eigen::Vector3d&, const Eigen::Vector3d&) {
            std::uint8_t* row = dst + k * plane + j * nx;
            for (std::int64_t i = i0; i <= i1; ++i)
              if (row[i] < 255) ++row[i];
          });
  return out;
}

}  // namespace repose
