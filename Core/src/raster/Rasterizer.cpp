#include "repose/raster/Rasterizer.h"

#include "LabelVolumeRounding.h"
#include "PieceGhosts.h"
#include "TetScan.h"
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
#include <cstdlib>
#include <limits>
#include <mutex>
#include <set>
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
std::vector<std::uint8_t> pieceRimFaces(const TransferMesh& mesh) {
  const Eigen::Index nt = mesh.tets.rows();
  std::vector<std::uint8_t> out(std::size_t(nt), 0);
  if (mesh.rigid.empty()) return out;
  std::map<std::array<int, 3>, std::vector<std::int32_t>> faces;
  auto key = [&](Eigen::Index t, int f) {
    std::array<int, 3> k;
    for (int c = 0, n = 0; c < 4; ++c)
      if (c != f) k[std::size_t(n++)] = mesh.tets(t, c);
    std::sort(k.begin(), k.end());
    return k;
  };
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
void markOwnPartShells(const TransferMesh& mesh, const VolumeGeometry& input,
                       const std::vector<std::uint8_t>& outer, double mm, const Volume& parts,
                       std::vector<std::uint8_t>& covered) {
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
    // RigSettings::bonePieces, the other labels of a bone.
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
        if (label > 0 && ids.count(piece)) assign(label, piece);
    sh.boneLabel.resize(pieceOf.size());
    for (std::size_t v = 0; v < pieceOf.size(); ++v) sh.boneLabel[v] = pieceOf[v] != 0;
    sh.ghosts = raster::pieceGhosts(mesh, *options.pieceLabels, pieceOf);
    sh.pieceMm = std::max(input.spacing().maxCoeff(), mesh.sourceSpacingMm);
    const Eigen::Matrix3d Minv = output.ijkToRas.block<3, 3>(0, 0).inverse();
    for (int c = 0; c < 3; ++c) sh.pieceGrowth[c] = sh.pieceMm * Minv.row(c).norm();
    sh.normalToMm = output.ijkToRas.block<3, 3>(0, 0).inverse().transpose();
  }
  sh.mm = options.shellMm < 0 ? 2 * std::max(input.spacing().maxCoeff(), mesh.sourceSpacingMm)
                              : options.shellMm;
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

// Runs the scan over slabs of output slices on all cores. Each slab is written by one thread,
// tets in index order, so overlapping (folded) tets resolve the same way on every run; then the
// shell pass writes the voxels of the slab still uncovered.
//
// `write(k, j, i0, i1, rest0, step, tet)` writes a row interval. A writer that batches its
// writes has worker(): each thread then writes through its own worker object, in order, and
// calls its flush() when its work items are done (every voxel is in one work item, so a worker's
// late writes race with no other thread).
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

template <class Write>
void runScan(const ScanInput& in, const Shell& shell, const RasterOptions& options,
             const std::string& stage, RasterReport* report, double frameSign, Write&& write,
             std::int64_t kBegin = 0, std::int64_t kEnd = -1) {
  // Only slices [kBegin, kEnd) are scanned (the out-of-core path's slab), in the full grid's
  // coordinates, so a slab's voxels get exactly the values the whole grid would.
  if (kEnd < 0) kEnd = in.dims[2];
  const Eigen::Index nt = in.tets->rows();
  const std::int64_t nx = in.dims[0];
  // Each tet's box in j and k (grown for the shell if it has an outer face), to skip it cheaply
  // outside a work item. Only tets whose box meets the grid are kept: for a live slice, the few
  // crossing it, found with plain comparisons first since every tet is looked at.
  const bool withShell = !shell.outer.empty();
  const bool withRims = !shell.pieceFaces.empty();
  Eigen::MatrixX4i ghostTets;
  const ScanInput ghostIn =
      withRims ? raster::ghostScanInput(in, shell.ghosts, ghostTets) : ScanInput();
  // Outcodes (Cohen-Sutherland) of the vertices against the scanned rows and slices: a tet whose
  // four vertices share a bit lies wholly on one side, found from four bytes. Bits 0-3 use the
  // bounds grown by the largest box growth and one voxel more (so rounding cannot reject a tet the
  // box test below keeps), for tets that grow (an outer face's shell, a piece's rim); bits 4-7 the
  // exact bounds, for the rest. A live slice keeps a few thousand of 200K tets.
  double gyMax = 0, gzMax = 0;
  if (withShell) gyMax = shell.boxGrowth[1], gzMax = shell.boxGrowth[2];
  if (withRims)
    gyMax = std::max(gyMax, shell.pieceGrowth[1]), gzMax = std::max(gzMax, shell.pieceGrowth[2]);
  const double zBelow = double(kBegin) - gzMax - 1, zAbove = double(kEnd - 1) + gzMax + 1;
  const double yBelow = -gyMax - 1, yAbove = double(in.dims[1] - 1) + gyMax + 1;
  const double zFirst = double(kBegin), zLast = double(kEnd - 1), yLast = double(in.dims[1] - 1);
  std::vector<std::uint8_t> outcode(in.out.size());
  for (std::size_t v = 0; v < in.out.size(); ++v) {
    const double y = in.out[v].y(), z = in.out[v].z();
    outcode[v] =
        std::uint8_t((z < zBelow) | (z > zAbove) << 1 | (y < yBelow) << 2 | (y > yAbove) << 3 |
                     (z < zFirst) << 4 | (z > zLast) << 5 | (y < 0) << 6 | (y > yLast) << 7);
  }
  // On a grid one slice thick (a live slice) a tet that does not grow holds voxels only where
  // its cross-section with the slice's plane does: its rows are those the section spans, and it
  // is dropped when the section holds no voxel centre. The section's corners are rounded, so the
  // bounds are widened by kSectionSlack voxels (the scan decides the voxels themselves exactly).
  const bool onePlane = kEnd - kBegin == 1;
  constexpr double kSectionSlack = 1e-6;
  // Selected in parallel chunks, then joined in tet order (the order folds are resolved in).
  // Per candidate: its box's rows and slices (grown for a growing tet), and the rows the tet
  // itself is scanned over (mjmin > mjmax: none, a growing tet that only its shell brings to
  // the scanned region).
  struct Candidate {
    std::int32_t tet;
    raster::TetVertices v;
    std::int32_t jmin, jmax, kmin, kmax, mjmin, mjmax;
  };
  const int selectThreads = resolveThreads(options.threads);
  std::vector<std::vector<Candidate>> parts(static_cast<std::size_t>(selectThreads));
  const std::uint8_t* outerFaces = withShell ? shell.outer.data() : nullptr;
  const std::uint8_t* rimFaces = withRims ? shell.pieceFaces.data() : nullptr;
  auto growsAt = [outerFaces, rimFaces](Eigen::Index t) {
    return (outerFaces && outerFaces[t]) || (rimFaces && rimFaces[t]);
  };
  parallelFor(
      selectThreads, selectThreads,
      [&](std::int64_t pb, std::int64_t pe) {
        for (std::int64_t part = pb; part < pe; ++part) {
          std::vector<Candidate>& c = parts[static_cast<std::size_t>(part)];
          const Eigen::Index tBegin = nt * part / selectThreads,
                             tEnd = nt * (part + 1) / selectThreads;
          // First the outcodes alone, in a loop that does nothing else and has no branch: all
          // but one in ten tets of a live slice stop here, scattered over the mesh. The vertex
          // indices of those kept are copied here: read again below, each was a cache miss.
          const std::size_t span = static_cast<std::size_t>(tEnd - tBegin) + 1;
          // Not zeroed: only the first `kept` entries are ever read.
          const std::unique_ptr<std::int32_t[]> hits(new std::int32_t[span]);
          const std::unique_ptr<raster::TetVertices[]> hitVertices(new raster::TetVertices[span]);
          std::size_t kept = 0;
          {
            const std::uint8_t* oc = outcode.data();
            const int *T0 = in.tets->col(0).data(), *T1 = in.tets->col(1).data(),
                      *T2 = in.tets->col(2).data(), *T3 = in.tets->col(3).data();
            for (Eigen::Index t = tBegin; t < tEnd; ++t) {
              const raster::TetVertices v{T0[t], T1[t], T2[t], T3[t]};
              const unsigned shared = oc[v[0]] & oc[v[1]] & oc[v[2]] & oc[v[3]];
              hits[kept] = std::int32_t(t), hitVertices[kept] = v;
              kept += !(shared & (growsAt(t) ? 0x0Fu : 0xF0u));
            }
          }
          // Sized for all those kept and cut to those taken: filled by index, the appends had
          // been out-of-line calls, visible in a profile of the live slice.
          c.resize(kept);
          std::size_t taken = 0;
          for (std::size_t h = 0; h < kept; ++h) {
            // The vertices of the tets a few ahead are fetched while this one is worked on.
            constexpr std::size_t kAhead = 8;
            if (h + kAhead < kept)
              for (const int u : hitVertices[h + kAhead])
                __builtin_prefetch(&in.out[std::size_t(u)]);
            const std::int32_t t = hits[h];
            const raster::TetVertices& v = hitVertices[h];
            const bool grows = growsAt(t);
            double gy = 0, gz = 0;  // box growth for the shell and the piece's rim
            if (withShell && shell.outer[t]) gy = shell.boxGrowth[1], gz = shell.boxGrowth[2];
            if (withRims && shell.pieceFaces[std::size_t(t)])
              gy = std::max(gy, shell.pieceGrowth[1]), gz = std::max(gz, shell.pieceGrowth[2]);
            const Eigen::Vector3d &p0 = in.out[v[0]], &p1 = in.out[v[1]], &p2 = in.out[v[2]],
                                  &p3 = in.out[v[3]];
            const double zlo = std::min(std::min(p0.z(), p1.z()), std::min(p2.z(), p3.z())) - gz;
            const double zhi = std::max(std::max(p0.z(), p1.z()), std::max(p2.z(), p3.z())) + gz;
            if (zhi < double(kBegin) || zlo > double(kEnd - 1)) continue;
            const double ymin = std::min(std::min(p0.y(), p1.y()), std::min(p2.y(), p3.y()));
            const double ymax = std::max(std::max(p0.y(), p1.y()), std::max(p2.y(), p3.y()));
            const double ylo = ymin - gy, yhi = ymax + gy;
            if (yhi < 0 || ylo > yLast || raster::ceilToInt(ylo) > raster::floorToInt(yhi))
              continue;
            // The rows of the tet itself: none when its four vertices share an exact bound
            // (only a growing tet gets this far then).
            double mylo = ymin, myhi = ymax;
            const bool reaches = !(outcode[std::size_t(v[0])] & outcode[std::size_t(v[1])] &
                                   outcode[std::size_t(v[2])] & outcode[std::size_t(v[3])] & 0xF0);
            if (!reaches) mylo = 1, myhi = 0;
            if (onePlane && reaches) {
              // The section of the tet with the plane z = kBegin: its vertices on the plane and
              // the crossings of its edges.
              const Eigen::Vector3d* p[4] = {&p0, &p1, &p2, &p3};
              double xlo = std::numeric_limits<double>::infinity(), xhi = -xlo;
              mylo = xlo, myhi = -xlo;
              for (int a = 0; a < 4; ++a) {
                const double za = p[a]->z() - zFirst;
                if (za == 0) {
                  xlo = std::min(xlo, p[a]->x()), xhi = std::max(xhi, p[a]->x());
                  mylo = std::min(mylo, p[a]->y()), myhi = std::max(myhi, p[a]->y());
                }
                for (int b = a + 1; b < 4; ++b) {
                  const double zb = p[b]->z() - zFirst;
                  if (!((za < 0 && zb > 0) || (za > 0 && zb < 0))) continue;
                  const double u = za / (za - zb);
                  const double x = p[a]->x() + u * (p[b]->x() - p[a]->x());
                  const double y = p[a]->y() + u * (p[b]->y() - p[a]->y());
                  xlo = std::min(xlo, x), xhi = std::max(xhi, x);
                  mylo = std::min(mylo, y), myhi = std::max(myhi, y);
                }
              }
              const double slack = kSectionSlack * (1 + std::max(std::abs(xlo), std::abs(xhi)));
              xlo = std::max(xlo - slack, 0.0), xhi = std::min(xhi + slack, double(nx - 1));
              const double ySlack = kSectionSlack * (1 + std::max(std::abs(mylo), std::abs(myhi)));
              mylo -= ySlack, myhi += ySlack;
              if (!(raster::ceilToInt(xlo) <= raster::floorToInt(xhi))) mylo = 1, myhi = 0;
            }
            const std::int64_t mj0 = std::max<std::int64_t>(0, raster::ceilToInt(mylo)),
                               mj1 = std::min(in.dims[1] - 1, raster::floorToInt(myhi));
            if (!grows && mj0 > mj1) continue;
            // A tet that does not grow is handed to the work items by its own rows.
            c[taken++] = Candidate{
                t,
                v,
                std::int32_t(grows ? std::max<std::int64_t>(0, raster::ceilToInt(ylo)) : mj0),
                std::int32_t(grows ? std::min(in.dims[1] - 1, raster::floorToInt(yhi)) : mj1),
                std::int32_t(std::max(kBegin, raster::ceilToInt(zlo))),
                std::int32_t(std::min(kEnd - 1, raster::floorToInt(zhi))),
                std::int32_t(mj0),
                std::int32_t(mj1)};
          }
          c.resize(taken);
        }
      },
      1);
  // Tets of whole pieces (bones, organs) go last, so where a fold of soft tissue overlaps a bone
  // the bone keeps its voxels: soft tissue is what a bend squeezes.
  std::vector<Candidate> candidates;
  std::size_t total = 0;
  for (const std::vector<Candidate>& c : parts) total += c.size();
  candidates.reserve(total);
  const bool withPieces = in.pieces && !in.pieces->empty();
  for (const int pass : {0, 1}) {
    if (pass == 1 && !withPieces) break;
    for (const std::vector<Candidate>& c : parts) {
      if (!withPieces) {
        candidates.insert(candidates.end(), c.begin(), c.end());
        continue;
      }
      for (const Candidate& n : c)
        if (((*in.pieces)[std::size_t(n.tet)] != 0) == (pass == 1)) candidates.push_back(n);
    }
  }
  // Work items: slabs of whole k-slices, or for thin grids (a live slice is one voxel thick)
  // bands of j-rows across all slices, so every core has work either way.
  const int threads = resolveThreads(options.threads);
  const std::int64_t depth = kEnd - kBegin;
  const bool bands = depth < 2 * threads;
  const std::int64_t split = bands ? in.dims[1] : depth;
  const std::int64_t slabs = std::max<std::int64_t>(1, std::min<std::int64_t>(split, 8 * threads));
  // Each work item's candidates, in candidate order: a live slice's bands each meet a few
  // hundred of the thousands of tets it keeps.
  std::vector<std::vector<std::int32_t>> itemCandidates(static_cast<std::size_t>(slabs));
  {
    // The work item of each row or slice, as a table: two 64-bit divisions per candidate had
    // cost a millisecond per slice.
    std::vector<std::int32_t> itemOf(static_cast<std::size_t>(split));
    for (std::int64_t item = 0; item < slabs; ++item)
      std::fill(itemOf.begin() + split * item / slabs, itemOf.begin() + split * (item + 1) / slabs,
                std::int32_t(item));
    for (std::size_t c = 0; c < candidates.size(); ++c) {
      const Candidate& n = candidates[c];
      const std::int64_t lo = bands ? n.jmin : n.kmin - kBegin,
                         hi = bands ? n.jmax : n.kmax - kBegin;
      if (lo > hi) continue;
      for (std::int32_t item = itemOf[std::size_t(lo)], last = itemOf[std::size_t(hi)];
           item <= last; ++item)
        itemCandidates[std::size_t(item)].push_back(std::int32_t(c));
    }
  }
  std::atomic<std::int64_t> writes{0}, shellWrites{0}, done{0}, nextSlab{0};
  std::atomic<bool> stop{false};
  std::mutex progressMutex;
  // Work items are handed out one at a time: the body fills some bands of a slice and not others
  // (a sagittal slice's trunk and head against its legs), so fixed halves would leave a core idle.
  parallelFor(
      std::min<std::int64_t>(slabs, threads), threads,
      [&](std::int64_t, std::int64_t) {
        std::int64_t localWrites = 0, localShell = 0;
        HugePageVector<std::uint8_t> covered;  // tens of MB a slab of a full grid
        auto sink = workerOf(write);
        for (std::int64_t slab; !stop && (slab = nextSlab++) < slabs;) {
          const std::int64_t s0 = split * slab / slabs, s1 = split * (slab + 1) / slabs;
          const std::int64_t k0 = kBegin + (bands ? 0 : s0), k1 = bands ? kEnd : kBegin + s1;
          const std::int64_t j0 = bands ? s0 : 0, j1 = bands ? s1 : in.dims[1];
          // Voxels of this work item already written, row by row (rows j0..j1 of slices k0..k1).
          const std::int64_t rows = j1 - j0;
          // 1: written by soft tissue, 2: by a whole piece (its tets or its rim).
          if (withShell || withRims)
            covered.assign(static_cast<std::size_t>(nx * rows * (k1 - k0)), 0);
          ScanTet s;
          const std::vector<std::int32_t>& mine = itemCandidates[std::size_t(slab)];
          // The vertices of the candidates a few ahead, deformed and at rest, are fetched while
          // this one is scanned: a slice's tets lie scattered over the vertex arrays.
          auto fetchAhead = [&](std::size_t m) {
            constexpr std::size_t kAhead = 6;
            if (m + kAhead >= mine.size()) return;
            for (const int u : candidates[std::size_t(mine[m + kAhead])].v) {
              __builtin_prefetch(&in.out[std::size_t(u)]);
              __builtin_prefetch(&in.rest[std::size_t(u)]);
            }
          };
          for (std::size_t m = 0; m < mine.size(); ++m) {
            fetchAhead(m);
            const Candidate& n = candidates[std::size_t(mine[m])];
            const std::int32_t t = n.tet;
            if (n.kmax < k0 || n.kmin >= k1 || n.mjmax < j0 || n.mjmin >= j1 || n.mjmin > n.mjmax ||
                !raster::prepareTet(in, n.v, s))
              continue;
            const std::uint8_t mark = withPieces && (*in.pieces)[std::size_t(t)] != 0 ? 2 : 1;
            raster::scanTet(s, k0, k1, std::max<std::int64_t>(j0, n.mjmin),
                            std::min<std::int64_t>(j1, n.mjmax + 1),
                            [&](std::int64_t k, std::int64_t j, std::int64_t i0, std::int64_t i1,
                                const Eigen::Vector3d& rest0, const Eigen::Vector3d& step) {
                              localWrites += i1 - i0 + 1;
                              if (!covered.empty())
                                std::fill_n(
                                    covered.begin() + (((k - k0) * rows + (j - j0)) * nx + i0),
                                    i1 - i0 + 1, mark);
                              sink(k, j, i0, i1, rest0, step, t);
                            });
          }
          // Writes, over soft tissue, the voxels of the prepared region `s` whose rest label is
          // bone of piece tet t's body part, through t's map (a rim, or a ghost hosted by t).
          auto scanRim = [&](std::int32_t t) {
            raster::scanTet(s, k0, k1, j0, j1,
                            [&](std::int64_t k, std::int64_t j, std::int64_t i0, std::int64_t i1,
                                const Eigen::Vector3d& rest0, const Eigen::Vector3d& step) {
                              std::uint8_t* cv = covered.data() + ((k - k0) * rows + (j - j0)) * nx;
                              for (std::int64_t a = i0; a <= i1; ++a) {
                                const Eigen::Vector3d p = rest0 + double(a - i0) * step;
                                if (cv[a] == 2 || !shell.rimTakes(t, p, *shell.tetParts)) continue;
                                cv[a] = 2;
                                sink(k, j, a, a, p, step, t);
                              }
                            });
          };
          // The pieces' rims: the voxels of a piece's own label just beyond its tets (Mesh_3
          // follows its surface to within a voxel) move with the piece, over the soft tissue
          // that covered them.
          for (std::size_t m = 0; m < mine.size() && withRims; ++m) {
            const Candidate& n = candidates[std::size_t(mine[m])];
            const std::int32_t t = n.tet;
            const unsigned rim = shell.pieceFaces[std::size_t(t)];
            if (!rim || n.kmax < k0 || n.kmin >= k1 || n.jmax < j0 || n.jmin >= j1 ||
                !raster::prepareShell(in, n.v, rim, shell.pieceMm, shell.normalToMm,
                                      shell.pieceGrowth, s))
              continue;
            scanRim(t);
          }
          // The ghosts: piece tissue in soft tets (a bone end a joint demoted), where the piece
          // puts it.
          for (std::size_t g = 0; g < shell.ghosts.size() && withRims; ++g) {
            const std::int32_t t = shell.ghosts[g].host;
            if (!raster::prepareShell(ghostIn, Eigen::Index(g), 0xF, shell.pieceMm,
                                      shell.normalToMm, shell.pieceGrowth, s) ||
                s.hi[2] < k0 || s.lo[2] >= k1 || s.hi[1] < j0 || s.lo[1] >= j1)
              continue;
            scanRim(t);
          }
          for (std::size_t m = 0; m < mine.size() && withShell; ++m) {
            if (shell.outer[candidates[std::size_t(mine[m])].tet]) fetchAhead(m);
            const Candidate& n = candidates[std::size_t(mine[m])];
            const std::int32_t t = n.tet;
            if (!shell.outer[t] || n.kmax < k0 || n.kmin >= k1 || n.jmax < j0 || n.jmin >= j1 ||
                !raster::prepareShell(in, n.v, shell.outer[t], shell.mm, shell.normalToMm,
                                      shell.boxGrowth, s))
              continue;
            raster::scanTet(s, k0, k1, j0, j1,
                            [&](std::int64_t k, std::int64_t j, std::int64_t i0, std::int64_t i1,
                                const Eigen::Vector3d& rest0, const Eigen::Vector3d& step) {
                              std::uint8_t* c = covered.data() + ((k - k0) * rows + (j - j0)) * nx;
                              auto free = [&](std::int64_t x) {
                                return !c[x] && shell.takes(t, rest0 + double(x - i0) * step);
                              };
                              for (std::int64_t a = i0; a <= i1;) {
                                if (!free(a)) {
                                  ++a;
                                  continue;
                                }
                                std::int64_t b = a;
                                while (b + 1 <= i1 && free(b + 1)) ++b;
                                std::fill(c + a, c + b + 1, std::uint8_t(1));
                                localShell += b - a + 1;
                                sink(k, j, a, b, Eigen::Vector3d(rest0 + double(a - i0) * step),
                                     step, t);
                                a = b + 1;
                              }
                            });
          }
          // Counted under the lock: counted before it, a thread could report 15/16 after
          // another reported 16/16, and the last progress a user sees would not be the end.
          std::lock_guard<std::mutex> lock(progressMutex);
          const double fraction = double(++done) / double(slabs);
          try {
            reportProgress(options.progress, fraction, stage);
          } catch (...) {
            stop = true;
            throw;
          }
        }
        sink.flush();
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

// RasterOptions::preserveLabelVolumes, after the nearest-neighbour pass has filled `dst`:
// per soft label the volume the deformation gives it (a scan of the rest mesh on the input's
// grid summing each tet's volume ratio over the voxels it carries), then the voxels on borders
// between soft labels scanned again in the same order, so each keeps the rest position of the
// write that decided it, and relabelled where that brings the counts to those volumes
// (LabelVolumeRounding.h). `sourceOf(i, j, k, p, tet)` is the rest voxel the pass sampled.
template <class T, class Source>
void roundLabelVolumes(const Volume& labels, const TransferMesh& mesh,
                       const Eigen::MatrixX3d& deformed, const ScanInput& in, const Shell& shell,
                       const RasterOptions& options, const VolumeGeometry& output, T* dst,
                       Source&& sourceOf, RasterReport* report) {
  const T* src = labels.data<T>();
  const auto d = labels.dims();
  const std::int64_t nIn = labels.numVoxels(), nOut = output.numVoxels();
  // Soft labels: non-zero, not negative, not a piece's; dense up to the largest value.
  std::int64_t maxLabel = 0;
  for (std::int64_t v = 0; v < nIn; ++v) maxLabel = std::max<std::int64_t>(maxLabel, src[v]);
  if (maxLabel > (1 << 24)) {
    if (report) report->roundingSkipped = "labels beyond 2^24";
    return;
  }
  if (maxLabel <= 0) return;  // no label to round
  std::vector<char> soft(std::size_t(maxLabel) + 1, 1);
  soft[0] = 0;
  for (std::size_t v = 0; v < shell.boneLabel.size() && v < soft.size(); ++v)
    if (shell.boneLabel[v]) soft[v] = 0;
  auto isSoft = [&](std::int64_t v) { return v > 0 && v <= maxLabel && soft[std::size_t(v)]; };

  // Volume ratio (deformed over rest) of every tet.
  const Eigen::Index nt = mesh.tets.rows();
  std::vector<double> ratio(std::size_t(nt), 1.0);
  for (Eigen::Index t = 0; t < nt; ++t) {
    Eigen::Matrix3d R, D;
    for (int c = 0; c < 3; ++c) {
      R.col(c) =
          (mesh.vertices.row(mesh.tets(t, c + 1)) - mesh.vertices.row(mesh.tets(t, 0))).transpose();
      D.col(c) = (deformed.row(mesh.tets(t, c + 1)) - deformed.row(mesh.tets(t, 0))).transpose();
    }
    const double rest = R.determinant();
    ratio[std::size_t(t)] = rest != 0 ? D.determinant() / rest : 0.0;
  }
  // Per label, the sum of the ratios over its rest voxels, in 2^-20 voxels (fixed point, so the
  // threads' sums add up the same on every run).
  constexpr double kUnit = 1 << 20;
  std::vector<std::atomic<std::int64_t>> sums(std::size_t(maxLabel) + 1);
  for (auto& a : sums) a = 0;
  {
    RasterOptions rest;
    rest.threads = options.threads;
    rest.shellMm = options.shellMm;
    rest.outerFaces = options.outerFaces;
    const VolumeGeometry& g = labels.geometry();
    const ScanInput restIn = raster::makeScanInput(mesh, mesh.vertices, g, g);
    Shell restShell = makeShell(mesh, g, g, rest);
    // The posed shell's rule for whose tissue a shell voxel is, on the same input grid: its
    // coverage of the rest mesh is shared, not scanned again.
    restShell.restParts = shell.restParts;
    restShell.tetParts = shell.tetParts;
    restShell.restCovered = shell.restCovered;
    restShell.claimsBackground = shell.claimsBackground;
    const std::int64_t nx = d[0], plane = d[0] * d[1];
    runScan(restIn, restShell, rest, "label volumes at rest", nullptr, 1.0,
            [&](std::int64_t k, std::int64_t j, std::int64_t i0, std::int64_t i1,
                const Eigen::Vector3d&, const Eigen::Vector3d&, std::int32_t tet) {
              const T* row = src + k * plane + j * nx;
              std::int64_t run = 0;
              T value = row[i0];
              auto flush = [&] {
                if (run > 0 && isSoft(std::int64_t(value)))
                  sums[std::size_t(value)] +=
                      std::llround(double(run) * ratio[std::size_t(tet)] * kUnit);
              };
              for (std::int64_t i = i0; i <= i1; ++i) {
                if (row[i] != value) flush(), run = 0, value = row[i];
                ++run;
              }
              flush();
            });
  }
  const double voxelRatio = std::fabs(labels.geometry().ijkToRas.block<3, 3>(0, 0).determinant()) /
                            std::fabs(output.ijkToRas.block<3, 3>(0, 0).determinant());
  std::vector<double> target(std::size_t(maxLabel) + 1, 0.0), count(target.size(), 0.0);
  for (std::size_t v = 1; v < target.size(); ++v)
    if (soft[v]) target[v] = std::max(0.0, double(sums[v].load()) / kUnit * voxelRatio);
  for (std::int64_t v = 0; v < nOut; ++v)
    if (isSoft(std::int64_t(dst[v]))) count[std::size_t(dst[v])] += 1;

  // The voxels on a border between two soft labels (6-neighbours), one bit each.
  const std::int64_t nx = output.dims[0], ny = output.dims[1], nz = output.dims[2], plane = nx * ny;
  const std::int64_t words = (nOut + 63) / 64;
  std::vector<std::uint64_t> border(std::size_t(words), 0);
  parallelFor(words, options.threads, [&](std::int64_t w0, std::int64_t w1) {
    for (std::int64_t w = w0; w < w1; ++w)
      for (std::int64_t v = 64 * w; v < std::min(nOut, 64 * (w + 1)); ++v) {
        const T a = dst[v];
        if (!isSoft(std::int64_t(a))) continue;
        const std::int64_t i = v % nx, j = (v / nx) % ny, k = v / plane;
        auto other = [&](std::int64_t u) { return dst[u] != a && isSoft(std::int64_t(dst[u])); };
        if ((i > 0 && other(v - 1)) || (i + 1 < nx && other(v + 1)) || (j > 0 && other(v - nx)) ||
            (j + 1 < ny && other(v + nx)) || (k > 0 && other(v - plane)) ||
            (k + 1 < nz && other(v + plane)))
          border[std::size_t(w)] |= std::uint64_t(1) << (v - 64 * w);
      }
  });
  std::vector<std::int64_t> rank(std::size_t(words) + 1, 0);
  for (std::int64_t w = 0; w < words; ++w)
    rank[std::size_t(w) + 1] = rank[std::size_t(w)] + __builtin_popcountll(border[std::size_t(w)]);
  std::vector<raster::RoundingCandidate> candidates(std::size_t(rank.back()));
  // Each border voxel: its sampled label and the soft label of most trilinear weight among the
  // other labels of the 8 rest voxels around its rest position, with the weights' difference.
  RasterOptions again = options;
  again.progress = {};
  runScan(in, shell, again, "label borders", nullptr, frameSign(output),
          [&](std::int64_t k, std::int64_t j, std::int64_t i0, std::int64_t i1, Eigen::Vector3d p,
              const Eigen::Vector3d& step, std::int32_t tet) {
            for (std::int64_t i = i0; i <= i1; ++i, p += step) {
              const std::int64_t v = k * plane + j * nx + i;
              const std::uint64_t word = border[std::size_t(v / 64)];
              if (!(word >> (v % 64) & 1)) continue;
              raster::RoundingCandidate& c = candidates[std::size_t(
                  rank[std::size_t(v / 64)] +
                  __builtin_popcountll(word & ((std::uint64_t(1) << (v % 64)) - 1)))];
              c.voxel = v;
              c.to = -1;
              const std::int64_t at = sourceOf(i, j, k, p, tet);
              // Only a voxel sampled where its rest position is (not redirected off a piece).
              if (at < 0 || at != nearestVoxel(p, d)) {
                c.from = -1;
                continue;
              }
              c.from = std::int32_t(src[at]);
              std::array<std::int32_t, 8> value;
              std::array<double, 8> weight;
              int n = 0;
              const double fx = std::floor(p.x()), fy = std::floor(p.y()), fz = std::floor(p.z());
              const double tx = p.x() - fx, ty = p.y() - fy, tz = p.z() - fz;
              for (int corner = 0; corner < 8; ++corner) {
                const std::int64_t x = std::int64_t(fx) + (corner & 1),
                                   y = std::int64_t(fy) + (corner >> 1 & 1),
                                   z = std::int64_t(fz) + (corner >> 2 & 1);
                const double w = ((corner & 1) ? tx : 1 - tx) * ((corner >> 1 & 1) ? ty : 1 - ty) *
                                 ((corner >> 2 & 1) ? tz : 1 - tz);
                const std::int32_t l =
                    x < 0 || y < 0 || z < 0 || x >= d[0] || y >= d[1] || z >= d[2]
                        ? 0
                        : std::int32_t(src[x + d[0] * (y + d[1] * z)]);
                int m = 0;
                while (m < n && value[std::size_t(m)] != l) ++m;
                if (m == n) value[std::size_t(n)] = l, weight[std::size_t(n++)] = 0;
                weight[std::size_t(m)] += w;
              }
              double own = 0, best = -1;
              for (int m = 0; m < n; ++m)
                if (value[std::size_t(m)] == c.from)
                  own = weight[std::size_t(m)];
                else if (isSoft(value[std::size_t(m)]) && weight[std::size_t(m)] > best)
                  best = weight[std::size_t(m)], c.to = value[std::size_t(m)];
              c.score = float(best - own);
            }
          });
  std::vector<raster::RoundingCandidate> usable;
  usable.reserve(candidates.size());
  for (const raster::RoundingCandidate& c : candidates)
    if (c.to >= 0 && c.from >= 0 && std::int64_t(dst[c.voxel]) == c.from && isSoft(c.from))
      usable.push_back(c);
  const std::vector<std::size_t> taken = raster::chooseVolumeRounding(usable, target, count);
  for (const std::size_t c : taken) dst[usable[c].voxel] = T(usable[c].to);
  if (report) {
    report->roundedVoxels = std::int64_t(taken.size());
    for (std::size_t v = 1; v < target.size(); ++v)
      if (soft[v] && target[v] > 0) report->labelTargets[int(v)] = target[v];
  }
}

}  // namespace

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
  auto sortedFace = [&](Eigen::Index t, int f) {
    std::array<int, 3> k;
    for (int c = 0, n = 0; c < 4; ++c)
      if (c != f) k[std::size_t(n++)] = mesh.tets(t, c);
    std::sort(k.begin(), k.end());
    return k;
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
    for (int f = 0; f < 4; ++f) ++first[std::size_t(sortedFace(t, f)[0]) + 1];
  for (std::size_t a = 1; a < first.size(); ++a) first[a] += first[a - 1];
  std::vector<Face> faces(std::size_t(4 * nt));
  {
    std::vector<std::int64_t> next(first.begin(), first.end() - 1);
    for (Eigen::Index t = 0; t < nt; ++t)
      for (int f = 0; f < 4; ++f) {
        const std::array<int, 3> k = sortedFace(t, f);
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
  // The most common value around `at` that no piece owns (`at` itself if there is none), looking
  // one voxel around first, then two.
  std::int64_t aroundPiece(std::int64_t at) const {
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
            if (setup.owner[std::size_t(n)] >= 0) continue;
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
  std::int64_t operator()(std::int64_t i, std::int64_t j, std::int64_t k, const Eigen::Vector3d& p,
                          std::int32_t tet) const {
    std::int64_t at = nearestVoxel(p, d);
    if (at >= 0 && !setup.owner.empty() && !mesh.rigid[std::size_t(tet)] && movedAway(at, i, j, k))
      at = aroundPiece(at);
    return at;
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
          roundLabelVolumes<T>(labels, mesh, deformed, setup.in, setup.shell, options, output,
                               dst[0], source, report);
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
  VolumeGeometry output;
  RasterOptions options;
  LabelScanSetup setup;
  Impl(const Volume& l, const TransferMesh& m, const Eigen::MatrixX3d& deformed,
       const VolumeGeometry& grid, const RasterOptions& o)
      : labels(l), mesh(m), output(grid), options(o), setup(l, m, deformed, grid, o) {
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
  if (k0 < 0 || k1 > r.output.dims[2] || k0 >= k1)
    throw Error("rasterizer: slab [" + std::to_string(k0) + ", " + std::to_string(k1) +
                ") is not within the output's " + std::to_string(r.output.dims[2]) + " slices");
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
  if (k0 < 0 || k1 > r.output.dims[2] || k0 >= k1)
    throw Error("rasterizer: slab [" + std::to_string(k0) + ", " + std::to_string(k1) +
                ") is not within the output's " + std::to_string(r.output.dims[2]) + " slices");
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
                const Eigen::Vector3d& step, std::int32_t) {
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
  const Eigen::Matrix3d O = output.ijkToRas.block<3, 3>(0, 0), I = input.ijkToRas.block<3, 3>(0, 0);
  const Eigen::Vector3d oo = output.origin(), io = input.origin();
  const Eigen::Matrix3d Iinv = I.inverse();
  // Uncovered voxels aim just past the input grid (one voxel centre beyond its nearest face, or
  // nowhere when they already lie a voxel beyond it), so nearest-neighbour resampling gives them
  // background and the field stays within the grid's size: 3D Slicer interpolates a grid
  // transform with a cubic kernel, and a jump of metres beside the skin threw tissue far away.
  auto outside = [&](const Eigen::Vector3d& y) {
    Eigen::Vector3d u = Iinv * (y - io);
    int axis = -1;
    double target = 0, cost = std::numeric_limits<double>::infinity();
    for (int c = 0; c < 3; ++c) {
      const double n = double(input.dims[std::size_t(c)]);
      if (u[c] <= -1 || u[c] >= n) return y;
      const double spacing = I.col(c).norm();
      if ((u[c] + 1) * spacing < cost) cost = (u[c] + 1) * spacing, axis = c, target = -1;
      if ((n - u[c]) * spacing < cost) cost = (n - u[c]) * spacing, axis = c, target = n;
    }
    u[axis] = target;
    return Eigen::Vector3d(I * u + io);
  };
  parallelFor(
      output.dims[2], options.threads,
      [&](std::int64_t k0, std::int64_t k1) {
        for (std::int64_t k = k0; k < k1; ++k)
          for (std::int64_t j = 0; j < output.dims[1]; ++j)
            for (std::int64_t i = 0; i < output.dims[0]; ++i) {
              const Eigen::Vector3d y = O * Eigen::Vector3d(double(i), double(j), double(k)) + oo;
              const Eigen::Vector3d d = outside(y) - y;
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
              const Eigen::Vector3d& step, std::int32_t) {
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
              const Eigen::Vector3d&, const Eigen::Vector3d&, std::int32_t) {
            std::uint8_t* row = dst + k * plane + j * nx;
            for (std::int64_t i = i0; i <= i1; ++i)
              if (row[i] < 255) ++row[i];
          });
  return out;
}

}  // namespace repose
