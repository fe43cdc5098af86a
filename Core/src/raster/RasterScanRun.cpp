// runScanWith: the scan's run in its named steps (RasterScan.h).
//   1. vertexOutcodes: each deformed vertex against the scanned rows and slices;
//   2. selectCandidates: the tets that can write a voxel of the scan, with their boxes;
//   3. inFoldOrder: soft tissue first, whole pieces last (where a fold overlaps, bone wins);
//   4. planWorkItems: slabs of slices, or bands of rows on a thin grid, and each one's tets;
//   5. per work item (WorkItemScan): the tets themselves, the pieces' rims, the ghosts, the shell.
#include "RasterScan.h"

namespace repose::raster {
namespace {

// A tet that can write a voxel of the scan: its box's rows and slices (grown for a growing tet),
// and the rows the tet itself is scanned over (mjmin > mjmax: none, a growing tet that only its
// shell brings to the scanned region).
struct Candidate {
  std::int32_t tet;
  raster::TetVertices v;
  std::int32_t jmin, jmax, kmin, kmax, mjmin, mjmax;
};

// The scan's extent and what grows beyond the tets (an outer face's shell, a piece's rim).
struct ScanExtent {
  std::int64_t kBegin = 0, kEnd = 0;
  bool withShell = false, withRims = false, withPieces = false;
};

// Outcodes (Cohen-Sutherland) of the vertices against the scanned rows and slices: a tet whose
// four vertices share a bit lies wholly on one side, found from four bytes. Bits 0-3 use the
// bounds grown by the largest box growth and one voxel more (so rounding cannot reject a tet the
// box test keeps), for tets that grow (an outer face's shell, a piece's rim); bits 4-7 the exact
// bounds, for the rest. A live slice keeps a few thousand of 200K tets.
std::vector<std::uint8_t> vertexOutcodes(const ScanInput& in, const Shell& shell,
                                         const ScanExtent& e) {
  double gyMax = 0, gzMax = 0;
  if (e.withShell) gyMax = shell.boxGrowth[1], gzMax = shell.boxGrowth[2];
  if (e.withRims)
    gyMax = std::max(gyMax, shell.pieceGrowth[1]), gzMax = std::max(gzMax, shell.pieceGrowth[2]);
  const double zBelow = double(e.kBegin) - gzMax - 1, zAbove = double(e.kEnd - 1) + gzMax + 1;
  const double yBelow = -gyMax - 1, yAbove = double(in.dims[1] - 1) + gyMax + 1;
  const double zFirst = double(e.kBegin), zLast = double(e.kEnd - 1),
               yLast = double(in.dims[1] - 1);
  std::vector<std::uint8_t> outcode(in.out.size());
  for (std::size_t v = 0; v < in.out.size(); ++v) {
    const double y = in.out[v].y(), z = in.out[v].z();
    outcode[v] =
        std::uint8_t((z < zBelow) | (z > zAbove) << 1 | (y < yBelow) << 2 | (y > yAbove) << 3 |
                     (z < zFirst) << 4 | (z > zLast) << 5 | (y < 0) << 6 | (y > yLast) << 7);
  }
  return outcode;
}

// The candidates of tets [tBegin, tEnd), in tet order.
std::vector<Candidate> selectCandidates(const ScanInput& in, const Shell& shell,
                                        const ScanExtent& e,
                                        const std::vector<std::uint8_t>& outcode,
                                        Eigen::Index tBegin, Eigen::Index tEnd) {
  const std::int64_t nx = in.dims[0], kBegin = e.kBegin, kEnd = e.kEnd;
  const double zFirst = double(kBegin), yLast = double(in.dims[1] - 1);
  // On a grid one slice thick (a live slice) a tet that does not grow holds voxels only where
  // its cross-section with the slice's plane does: its rows are those the section spans, and it
  // is dropped when the section holds no voxel centre. The section's corners are rounded, so the
  // bounds are widened by kSectionSlack voxels (the scan decides the voxels themselves exactly).
  const bool onePlane = kEnd - kBegin == 1;
  constexpr double kSectionSlack = 1e-6;
  const std::uint8_t* outerFaces = e.withShell ? shell.outer.data() : nullptr;
  const std::uint8_t* rimFaces = e.withRims ? shell.pieceFaces.data() : nullptr;
  auto growsAt = [outerFaces, rimFaces](Eigen::Index t) {
    return (outerFaces && outerFaces[t]) || (rimFaces && rimFaces[t]);
  };
  // First the outcodes alone, in a loop that does nothing else and has no branch: all but one in
  // ten tets of a live slice stop here, scattered over the mesh. The vertex indices of those kept
  // are copied here: read again below, each was a cache miss.
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
  // Sized for all those kept and cut to those taken: filled by index, the appends had been
  // out-of-line calls, visible in a profile of the live slice.
  std::vector<Candidate> c(kept);
  std::size_t taken = 0;
  for (std::size_t h = 0; h < kept; ++h) {
    // The vertices of the tets a few ahead are fetched while this one is worked on.
    constexpr std::size_t kAhead = 8;
    if (h + kAhead < kept)
      for (const int u : hitVertices[h + kAhead]) __builtin_prefetch(&in.out[std::size_t(u)]);
    const std::int32_t t = hits[h];
    const raster::TetVertices& v = hitVertices[h];
    const bool grows = growsAt(t);
    double gy = 0, gz = 0;  // box growth for the shell and the piece's rim
    if (e.withShell && shell.outer[t]) gy = shell.boxGrowth[1], gz = shell.boxGrowth[2];
    if (e.withRims && shell.pieceFaces[std::size_t(t)])
      gy = std::max(gy, shell.pieceGrowth[1]), gz = std::max(gz, shell.pieceGrowth[2]);
    const Eigen::Vector3d &p0 = in.out[v[0]], &p1 = in.out[v[1]], &p2 = in.out[v[2]],
                          &p3 = in.out[v[3]];
    const double zlo = std::min(std::min(p0.z(), p1.z()), std::min(p2.z(), p3.z())) - gz;
    const double zhi = std::max(std::max(p0.z(), p1.z()), std::max(p2.z(), p3.z())) + gz;
    if (zhi < double(kBegin) || zlo > double(kEnd - 1)) continue;
    const double ymin = std::min(std::min(p0.y(), p1.y()), std::min(p2.y(), p3.y()));
    const double ymax = std::max(std::max(p0.y(), p1.y()), std::max(p2.y(), p3.y()));
    const double ylo = ymin - gy, yhi = ymax + gy;
    if (yhi < 0 || ylo > yLast || raster::ceilToInt(ylo) > raster::floorToInt(yhi)) continue;
    // The rows of the tet itself: none when its four vertices share an exact bound (only a
    // growing tet gets this far then).
    double mylo = ymin, myhi = ymax;
    const bool reaches = !(outcode[std::size_t(v[0])] & outcode[std::size_t(v[1])] &
                           outcode[std::size_t(v[2])] & outcode[std::size_t(v[3])] & 0xF0);
    if (!reaches) mylo = 1, myhi = 0;
    if (onePlane && reaches) {
      // The section of the tet with the plane z = kBegin: its vertices on the plane and the
      // crossings of its edges.
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
    c[taken++] =
        Candidate{t,
                  v,
                  std::int32_t(grows ? std::max<std::int64_t>(0, raster::ceilToInt(ylo)) : mj0),
                  std::int32_t(grows ? std::min(in.dims[1] - 1, raster::floorToInt(yhi)) : mj1),
                  std::int32_t(std::max(kBegin, raster::ceilToInt(zlo))),
                  std::int32_t(std::min(kEnd - 1, raster::floorToInt(zhi))),
                  std::int32_t(mj0),
                  std::int32_t(mj1)};
  }
  c.resize(taken);
  return c;
}

// Tets of whole pieces (bones, organs) go last, so where a fold of soft tissue overlaps a bone
// the bone keeps its voxels: soft tissue is what a bend squeezes.
std::vector<Candidate> inFoldOrder(const std::vector<std::vector<Candidate>>& parts,
                                   const ScanInput& in, bool withPieces) {
  std::vector<Candidate> candidates;
  std::size_t total = 0;
  for (const std::vector<Candidate>& c : parts) total += c.size();
  candidates.reserve(total);
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
  return candidates;
}

// Work items: slabs of whole k-slices, or for thin grids (a live slice is one voxel thick) bands
// of j-rows across all slices, so every core has work either way.
struct WorkItems {
  bool bands = false;
  std::int64_t split = 0, count = 0;
  // Each work item's candidates, in candidate order: a live slice's bands each meet a few
  // hundred of the thousands of tets it keeps.
  std::vector<std::vector<std::int32_t>> candidates;
};

WorkItems planWorkItems(const std::vector<Candidate>& candidates, const ScanInput& in,
                        const ScanExtent& e, int threads) {
  WorkItems w;
  const std::int64_t depth = e.kEnd - e.kBegin;
  w.bands = depth < 2 * threads;
  w.split = w.bands ? in.dims[1] : depth;
  w.count = std::max<std::int64_t>(1, std::min<std::int64_t>(w.split, 8 * threads));
  w.candidates.resize(static_cast<std::size_t>(w.count));
  // The work item of each row or slice, as a table: two 64-bit divisions per candidate had cost a
  // millisecond per slice.
  std::vector<std::int32_t> itemOf(static_cast<std::size_t>(w.split));
  for (std::int64_t item = 0; item < w.count; ++item)
    std::fill(itemOf.begin() + w.split * item / w.count,
              itemOf.begin() + w.split * (item + 1) / w.count, std::int32_t(item));
  for (std::size_t c = 0; c < candidates.size(); ++c) {
    const Candidate& n = candidates[c];
    const std::int64_t lo = w.bands ? n.jmin : n.kmin - e.kBegin,
                       hi = w.bands ? n.jmax : n.kmax - e.kBegin;
    if (lo > hi) continue;
    for (std::int32_t item = itemOf[std::size_t(lo)], last = itemOf[std::size_t(hi)]; item <= last;
         ++item)
      w.candidates[std::size_t(item)].push_back(std::int32_t(c));
  }
  return w;
}

// One work item's voxels (rows j0..j1 of slices k0..k1), written by one thread through its sink.
class WorkItemScan {
 public:
  WorkItemScan(const ScanInput& in, const ScanInput& ghostIn, const Shell& shell,
               const ScanExtent& e, const std::vector<Candidate>& candidates,
               const std::vector<std::int32_t>& mine, ScanSink& sink,
               HugePageVector<std::uint8_t>& covered, std::int64_t k0, std::int64_t k1,
               std::int64_t j0, std::int64_t j1)
      : in_(in),
        ghostIn_(ghostIn),
        shell_(shell),
        e_(e),
        candidates_(candidates),
        mine_(mine),
        sink_(sink),
        covered_(covered),
        nx_(in.dims[0]),
        k0_(k0),
        k1_(k1),
        j0_(j0),
        j1_(j1),
        rows_(j1 - j0) {
    // Voxels of this work item already written, row by row. 1: written by soft tissue, 2: by a
    // whole piece's tets, 3: by a rim or a ghost.
    if (e.withShell || e.withRims)
      covered_.assign(static_cast<std::size_t>(nx_ * rows_ * (k1 - k0)), 0);
  }

  std::int64_t writes = 0, shellWrites = 0;

  // The tets themselves, in fold order.
  void scanTets() {
    for (std::size_t m = 0; m < mine_.size(); ++m) {
      fetchAhead(m);
      const Candidate& n = candidate(m);
      const std::int32_t t = n.tet;
      if (n.kmax < k0_ || n.kmin >= k1_ || n.mjmax < j0_ || n.mjmin >= j1_ || n.mjmin > n.mjmax ||
          !raster::prepareTet(in_, n.v, s_))
        continue;
      const std::uint8_t mark = e_.withPieces && (*in_.pieces)[std::size_t(t)] != 0 ? 2 : 1;
      raster::scanTet(s_, k0_, k1_, std::max<std::int64_t>(j0_, n.mjmin),
                      std::min<std::int64_t>(j1_, n.mjmax + 1),
                      [&](std::int64_t k, std::int64_t j, std::int64_t i0, std::int64_t i1,
                          const Eigen::Vector3d& rest0, const Eigen::Vector3d& step) {
                        writes += i1 - i0 + 1;
                        if (!covered_.empty())
                          std::fill_n(
                              covered_.begin() + (((k - k0_) * rows_ + (j - j0_)) * nx_ + i0),
                              i1 - i0 + 1, mark);
                        sink_.write(k, j, i0, i1, rest0, step, t);
                      });
    }
  }

  // The pieces' rims: the voxels of a piece's own label just beyond its tets (Mesh_3 follows its
  // surface to within a voxel) move with the piece, over the soft tissue that covered them.
  void scanRims() {
    if (!e_.withRims) return;
    for (std::size_t m = 0; m < mine_.size(); ++m) {
      const Candidate& n = candidate(m);
      const std::int32_t t = n.tet;
      const unsigned rim = shell_.pieceFaces[std::size_t(t)];
      if (!rim || n.kmax < k0_ || n.kmin >= k1_ || n.jmax < j0_ || n.jmin >= j1_ ||
          !raster::prepareShell(in_, n.v, rim, shell_.pieceMm, shell_.normalToMm,
                                shell_.pieceGrowth, s_))
        continue;
      scanRim(t, false);
    }
  }

  // The ghosts: piece tissue in soft tets (a bone end a joint demoted), where the piece puts it.
  void scanGhosts() {
    if (!e_.withRims) return;
    for (std::size_t g = 0; g < shell_.ghosts.size(); ++g) {
      const std::int32_t t = shell_.ghosts[g].host;
      if (!raster::prepareShell(ghostIn_, Eigen::Index(g), 0xF, shell_.pieceMm, shell_.normalToMm,
                                shell_.pieceGrowth, s_) ||
          s_.hi[2] < k0_ || s_.lo[2] >= k1_ || s_.hi[1] < j0_ || s_.lo[1] >= j1_)
        continue;
      const std::int32_t soft = shell_.ghosts[g].soft;
      scanRim(t, e_.withPieces && (*in_.pieces)[std::size_t(soft)] != 0);
    }
  }

  // The shell beyond the outer faces: the voxels still uncovered that it takes.
  void scanShell() {
    if (!e_.withShell) return;
    for (std::size_t m = 0; m < mine_.size(); ++m) {
      if (shell_.outer[candidate(m).tet]) fetchAhead(m);
      const Candidate& n = candidate(m);
      const std::int32_t t = n.tet;
      if (!shell_.outer[t] || n.kmax < k0_ || n.kmin >= k1_ || n.jmax < j0_ || n.jmin >= j1_ ||
          !raster::prepareShell(in_, n.v, shell_.outer[t], shell_.mm, shell_.normalToMm,
                                shell_.boxGrowth, s_))
        continue;
      raster::scanTet(s_, k0_, k1_, j0_, j1_,
                      [&](std::int64_t k, std::int64_t j, std::int64_t i0, std::int64_t i1,
                          const Eigen::Vector3d& rest0, const Eigen::Vector3d& step) {
                        std::uint8_t* c = covered_.data() + ((k - k0_) * rows_ + (j - j0_)) * nx_;
                        auto free = [&](std::int64_t x) {
                          return !c[x] && shell_.takes(t, rest0 + double(x - i0) * step);
                        };
                        for (std::int64_t a = i0; a <= i1;) {
                          if (!free(a)) {
                            ++a;
                            continue;
                          }
                          std::int64_t b = a;
                          while (b + 1 <= i1 && free(b + 1)) ++b;
                          std::fill(c + a, c + b + 1, std::uint8_t(1));
                          shellWrites += b - a + 1;
                          sink_.write(k, j, a, b, Eigen::Vector3d(rest0 + double(a - i0) * step),
                                      step, t);
                          a = b + 1;
                        }
                      });
    }
  }

 private:
  const Candidate& candidate(std::size_t m) const { return candidates_[std::size_t(mine_[m])]; }

  // The vertices of the candidates a few ahead, deformed and at rest, are fetched while this one
  // is scanned: a slice's tets lie scattered over the vertex arrays.
  void fetchAhead(std::size_t m) const {
    constexpr std::size_t kAhead = 6;
    if (m + kAhead >= mine_.size()) return;
    for (const int u : candidates_[std::size_t(mine_[m + kAhead])].v) {
      __builtin_prefetch(&in_.out[std::size_t(u)]);
      __builtin_prefetch(&in_.rest[std::size_t(u)]);
    }
  }

  // Writes, over soft tissue, the voxels of the prepared region whose rest label is bone of piece
  // tet t's body part, through t's map (a rim, or a ghost hosted by t). `overPieces`: a ghost of
  // a piece tet that held another part's bone (PieceGhosts.h) also writes over the voxels piece
  // tets wrote (3 marks a rim's or a ghost's voxel): the piece tet that held the bone did not
  // copy it, and may still cover its place.
  void scanRim(std::int32_t t, bool overPieces) {
    raster::scanTet(
        s_, k0_, k1_, j0_, j1_,
        [&](std::int64_t k, std::int64_t j, std::int64_t i0, std::int64_t i1,
            const Eigen::Vector3d& rest0, const Eigen::Vector3d& step) {
          std::uint8_t* cv = covered_.data() + ((k - k0_) * rows_ + (j - j0_)) * nx_;
          for (std::int64_t a = i0; a <= i1; ++a) {
            const Eigen::Vector3d p = rest0 + double(a - i0) * step;
            if (cv[a] >= (overPieces ? 3 : 2) || !shell_.rimTakes(t, p, *shell_.tetParts)) continue;
            cv[a] = 3;
            sink_.write(k, j, a, a, p, step, t);
          }
        });
  }

  const ScanInput& in_;
  const ScanInput& ghostIn_;
  const Shell& shell_;
  const ScanExtent& e_;
  const std::vector<Candidate>& candidates_;
  const std::vector<std::int32_t>& mine_;
  ScanSink& sink_;
  HugePageVector<std::uint8_t>& covered_;
  const std::int64_t nx_, k0_, k1_, j0_, j1_, rows_;
  ScanTet s_;
};

}  // namespace

void runScanWith(const ScanInput& in, const Shell& shell, const RasterOptions& options,
                 const std::string& stage, RasterReport* report, double frameSign,
                 const ScanSinks& sinks, std::int64_t kBegin, std::int64_t kEnd) {
  ScanExtent e;
  e.kBegin = kBegin;
  e.kEnd = kEnd < 0 ? in.dims[2] : kEnd;
  e.withShell = !shell.outer.empty();
  e.withRims = !shell.pieceFaces.empty();
  e.withPieces = in.pieces && !in.pieces->empty();
  Eigen::MatrixX4i ghostTets;
  const ScanInput ghostIn =
      e.withRims ? raster::ghostScanInput(in, shell.ghosts, ghostTets) : ScanInput();
  const std::vector<std::uint8_t> outcode = vertexOutcodes(in, shell, e);

  // Selected in parallel chunks, then joined in tet order (the order folds are resolved in).
  const Eigen::Index nt = in.tets->rows();
  const int selectThreads = resolveThreads(options.threads);
  std::vector<std::vector<Candidate>> parts(static_cast<std::size_t>(selectThreads));
  parallelFor(
      selectThreads, selectThreads,
      [&](std::int64_t pb, std::int64_t pe) {
        for (std::int64_t part = pb; part < pe; ++part)
          parts[static_cast<std::size_t>(part)] = selectCandidates(
              in, shell, e, outcode, nt * part / selectThreads, nt * (part + 1) / selectThreads);
      },
      1);
  const std::vector<Candidate> candidates = inFoldOrder(parts, in, e.withPieces);

  const int threads = resolveThreads(options.threads);
  const WorkItems items = planWorkItems(candidates, in, e, threads);
  std::atomic<std::int64_t> writes{0}, shellWrites{0}, done{0}, nextItem{0};
  std::atomic<bool> stop{false};
  std::mutex progressMutex;
  // Work items are handed out one at a time: the body fills some bands of a slice and not others
  // (a sagittal slice's trunk and head against its legs), so fixed halves would leave a core idle.
  parallelFor(
      std::min<std::int64_t>(items.count, threads), threads,
      [&](std::int64_t, std::int64_t) {
        std::int64_t localWrites = 0, localShell = 0;
        HugePageVector<std::uint8_t> covered;  // tens of MB a slab of a full grid
        const std::unique_ptr<ScanSink> sink = sinks();
        for (std::int64_t item; !stop && (item = nextItem++) < items.count;) {
          const std::int64_t s0 = items.split * item / items.count,
                             s1 = items.split * (item + 1) / items.count;
          const std::int64_t k0 = e.kBegin + (items.bands ? 0 : s0),
                             k1 = items.bands ? e.kEnd : e.kBegin + s1;
          const std::int64_t j0 = items.bands ? s0 : 0, j1 = items.bands ? s1 : in.dims[1];
          WorkItemScan scan(in, ghostIn, shell, e, candidates, items.candidates[std::size_t(item)],
                            *sink, covered, k0, k1, j0, j1);
          scan.scanTets();
          scan.scanRims();
          scan.scanGhosts();
          scan.scanShell();
          localWrites += scan.writes;
          localShell += scan.shellWrites;
          // Counted under the lock: counted before it, a thread could report 15/16 after another
          // reported 16/16, and the last progress a user sees would not be the end.
          std::lock_guard<std::mutex> lock(progressMutex);
          const double fraction = double(++done) / double(items.count);
          try {
            reportProgress(options.progress, fraction, stage);
          } catch (...) {
            stop = true;
            throw;
          }
        }
        sink->flush();
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

}  // namespace repose::raster
