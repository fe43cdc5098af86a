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
          // 1: written by soft tissue, 2: by a whole piece's tets, 3: by a rim or a ghost.
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
          // `overPieces`: a ghost of a piece tet that held another part's bone (PieceGhosts.h)
          // also writes over the voxels piece tets wrote (3 marks a rim's or a ghost's voxel):
          // the piece tet that held the bone did not copy it, and may still cover its place.
          auto scanRim = [&](std::int32_t t, bool overPieces) {
            raster::scanTet(
                s, k0, k1, j0, j1,
                [&](std::int64_t k, std::int64_t j, std::int64_t i0, std::int64_t i1,
                    const Eigen::Vector3d& rest0, const Eigen::Vector3d& step) {
                  std::uint8_t* cv = covered.data() + ((k - k0) * rows + (j - j0)) * nx;
                  for (std::int64_t a = i0; a <= i1; ++a) {
                    const Eigen::Vector3d p = rest0 + double(a - i0) * step;
                    if (cv[a] >= (overPieces ? 3 : 2) || !shell.rimTakes(t, p, *shell.tetParts))
                      continue;
                    cv[a] = 3;
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
            scanRim(t, false);
          }
          // The ghosts: piece tissue in soft tets (a bone end a joint demoted), where the piece
          // puts it.
          for (std::size_t g = 0; g < shell.ghosts.size() && withRims; ++g) {
            const std::int32_t t = shell.ghosts[g].host;
            if (!raster::prepareShell(ghostIn, Eigen::Index(g), 0xF, shell.pieceMm,
                                      shell.normalToMm, shell.pieceGrowth, s) ||
                s.hi[2] < k0 || s.lo[2] >= k1 || s.hi[1] < j0 || s.lo[1] >= j1)
              continue;
            const std::int32_t soft = shell.ghosts[g].soft;
            scanRim(t, withPieces && (*in.pieces)[std::size_t(soft)] != 0);
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
