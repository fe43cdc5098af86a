// The skeleton's pieces (SkeletonPieces.h): components, the erosion that parts touching bones,
// the contacts between pieces, and their cuts and merges.
#include "SkeletonPieces.h"

#include <Eigen/Eigenvalues>

#include <algorithm>
#include <cmath>
#include <limits>
#include <queue>

namespace repose::rig {

SkeletonPieces::SkeletonPieces(const std::vector<std::int64_t>& voxels, const Grid& grid)
    : grid_(grid) {
  const auto& d = grid.dims;
  lo_ = {d[0], d[1], d[2]};
  hi_ = {-1, -1, -1};
  for (const std::int64_t v : voxels) {
    const std::int64_t ijk[3] = {v % d[0], (v / d[0]) % d[1], v / (d[0] * d[1])};
    for (int a = 0; a < 3; ++a)
      lo_[a] = std::min(lo_[a], ijk[a]), hi_[a] = std::max(hi_[a], ijk[a]);
  }
  // The box grown by the contacts' reach, so the fronts between pieces have room.
  for (int a = 0; a < 3; ++a) {
    const std::int64_t grow = std::int64_t(std::ceil(kNearMm / grid.spacing[a])) + 1;
    lo_[a] = std::max<std::int64_t>(0, lo_[a] - grow);
    hi_[a] = std::min<std::int64_t>(d[a] - 1, hi_[a] + grow);
    box_[a] = hi_[a] - lo_[a] + 1;
  }
  mask_.assign(std::size_t(box_[0] * box_[1] * box_[2]), 0);
  for (const std::int64_t v : voxels) mask_[std::size_t(local(v))] = 1;
}

std::vector<std::int64_t> SkeletonPieces::floodFrom(std::int64_t start,
                                                    const std::vector<std::uint8_t>& in, int id,
                                                    std::vector<int>& own) const {
  own[std::size_t(start)] = id;
  std::vector<std::int64_t> got{start};
  for (std::size_t q = 0; q < got.size(); ++q)
    neighbours(got[q], [&](std::int64_t m, int, int, int) {
      if (in[std::size_t(m)] && own[std::size_t(m)] == -1) {
        own[std::size_t(m)] = id;
        got.push_back(m);
      }
    });
  return got;
}

void SkeletonPieces::findPieces(double midX, double height) {
  const std::int64_t n = std::int64_t(mask_.size());
  owner_.assign(mask_.size(), -1);
  std::vector<std::int64_t> got;
  int next = 0;
  std::vector<std::pair<int, std::size_t>> across;  // components across the midline, sizes
  std::size_t total = 0;
  for (std::int64_t l = 0; l < n; ++l) {
    if (!mask_[std::size_t(l)] || owner_[std::size_t(l)] != -1) continue;
    got = floodFrom(l, mask_, next, owner_);
    total += got.size();
    double lo = 1e300, hi = -1e300;
    for (const std::int64_t m : got) {
      const double x = grid_.ras(global(m)).x();
      lo = std::min(lo, x), hi = std::max(hi, x);
    }
    if (lo <= midX && hi >= midX) across.push_back({next, got.size()});
    ++next;
  }
  // Each large one (the trunk's bones, the pelvis apart from a spine the discs part).
  for (const auto& [id, size] : across)
    if (size >= total / 20) partAxial(id, midX, height, next);
  pieces_.assign(std::size_t(next), Piece());
  for (std::int64_t l = 0; l < n; ++l)
    if (owner_[std::size_t(l)] >= 0)
      pieces_[std::size_t(owner_[std::size_t(l)])].voxels.push_back(global(l));
  // Ids the axial piece's parting left unused.
  pieces_.erase(std::remove_if(pieces_.begin(), pieces_.end(),
                               [](const Piece& p) { return p.voxels.empty(); }),
                pieces_.end());
  for (std::size_t i = 0; i < pieces_.size(); ++i) {
    describe(pieces_[i]);
    for (const std::int64_t v : pieces_[i].voxels) owner_[std::size_t(local(v))] = int(i);
  }
}

void SkeletonPieces::partAxial(int axial, double midX, double height, int& next) {
  const std::int64_t n = std::int64_t(mask_.size());
  const std::int64_t step[3] = {1, box_[0], box_[0] * box_[1]};
  std::vector<std::uint8_t> eroded(mask_.size(), 0);
  for (std::int64_t l = 0; l < n; ++l) {
    if (owner_[std::size_t(l)] != axial) continue;
    const std::int64_t ijk[3] = {l % box_[0], (l / box_[0]) % box_[1], l / (box_[0] * box_[1])};
    bool inner = true;
    for (int a = 0; a < 3 && inner; ++a)
      for (int s : {-1, 1}) {
        const std::int64_t m = ijk[a] + s;
        if (m < 0 || m >= box_[a] || !mask_[std::size_t(l + s * step[a])]) inner = false;
      }
    eroded[std::size_t(l)] = inner;
  }
  std::vector<int> part(mask_.size(), -1);
  std::vector<std::int64_t> seeds;
  std::vector<int> limbs;
  int id = 0;
  for (std::int64_t l = 0; l < n; ++l) {
    if (!eroded[std::size_t(l)] || part[std::size_t(l)] != -1) continue;
    const std::vector<std::int64_t> got = floodFrom(l, eroded, id, part);
    Piece p;
    for (const std::int64_t m : got) p.voxels.push_back(global(m));
    describe(p);
    const bool lateral = p.xMax < midX || p.xMin > midX;
    if (lateral && p.length >= 0.1 * height) limbs.push_back(id);
    seeds.insert(seeds.end(), got.begin(), got.end());
    ++id;
  }
  if (limbs.empty()) return;
  // Seeds: each limb part its own piece, everything else the axial piece.
  std::vector<int> as(std::size_t(id), axial);
  for (const int c : limbs) as[std::size_t(c)] = next++;
  for (std::int64_t l = 0; l < n; ++l)
    if (owner_[std::size_t(l)] == axial) owner_[std::size_t(l)] = -1;
  for (const std::int64_t l : seeds) owner_[std::size_t(l)] = as[std::size_t(part[std::size_t(l)])];
  std::vector<std::int64_t> frontier = seeds;
  while (!frontier.empty()) {
    std::vector<std::int64_t> ring;
    for (const std::int64_t l : frontier)
      neighbours(l, [&](std::int64_t m, int, int, int) {
        if (mask_[std::size_t(m)] && owner_[std::size_t(m)] == -1) {
          owner_[std::size_t(m)] = owner_[std::size_t(l)];
          ring.push_back(m);
        }
      });
    frontier.swap(ring);
  }
  // Voxels of the axial component no seed reached (none survived the erosion nearby).
  for (std::int64_t l = 0; l < n; ++l)
    if (mask_[std::size_t(l)] && owner_[std::size_t(l)] == -1) owner_[std::size_t(l)] = axial;
}

void SkeletonPieces::describe(Piece& p) const {
  p.centroid = V::Zero();
  for (const std::int64_t v : p.voxels) p.centroid += grid_.ras(v);
  p.centroid /= double(p.voxels.size());
  Eigen::Matrix3d cov = Eigen::Matrix3d::Zero();
  p.top = -1e300, p.bottom = 1e300, p.xMin = 1e300, p.xMax = -1e300;
  for (const std::int64_t v : p.voxels) {
    const V r = grid_.ras(v), d = r - p.centroid;
    cov += d * d.transpose();
    p.top = std::max(p.top, r.z()), p.bottom = std::min(p.bottom, r.z());
    p.xMin = std::min(p.xMin, r.x()), p.xMax = std::max(p.xMax, r.x());
  }
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eig(cov);
  p.axis = eig.eigenvectors().col(2).normalized();
  const Eigen::Vector3d l = eig.eigenvalues();  // ascending
  p.spread = l[2] > 0 ? std::sqrt(std::max(0.0, l[1]) / l[2]) : 1;
  double a = 1e300, b = -1e300;
  for (const std::int64_t v : p.voxels) {
    const double t = (grid_.ras(v) - p.centroid).dot(p.axis);
    a = std::min(a, t), b = std::max(b, t);
  }
  p.length = b - a + grid_.spacing.minCoeff();
}

void SkeletonPieces::findContacts() {
  contacts_.clear();
  const std::int64_t n = std::int64_t(mask_.size());
  std::vector<float> dist(mask_.size(), std::numeric_limits<float>::infinity());
  using Item = std::pair<float, std::int64_t>;
  std::priority_queue<Item, std::vector<Item>, std::greater<>> queue;
  for (std::int64_t l = 0; l < n; ++l)
    if (owner_[std::size_t(l)] >= 0) dist[std::size_t(l)] = 0, queue.push({0.f, l});
  const V sp = grid_.spacing;
  auto meet = [&](std::int64_t a, std::int64_t b, double d) {
    const int pa = owner_[std::size_t(a)], pb = owner_[std::size_t(b)];
    if (pa == pb || pa < 0 || pb < 0) return;
    const auto key = std::minmax(pa, pb);
    Contact& c = contacts_[{key.first, key.second}];
    if (d < c.distance) c.distance = d, c.at = 0.5 * (grid_.ras(global(a)) + grid_.ras(global(b)));
  };
  while (!queue.empty()) {
    const float d = queue.top().first;
    const std::int64_t l = queue.top().second;
    queue.pop();
    if (d > dist[std::size_t(l)]) continue;
    neighbours(l, [&](std::int64_t m, int di, int dj, int dk) {
      const double edge =
          std::sqrt(di * di * sp[0] * sp[0] + dj * dj * sp[1] * sp[1] + dk * dk * sp[2] * sp[2]);
      if (owner_[std::size_t(m)] >= 0 && owner_[std::size_t(m)] != owner_[std::size_t(l)]) {
        meet(l, m, double(d) + double(dist[std::size_t(m)]) + edge);
        return;
      }
      const double nd = double(d) + edge;
      if (nd > 0.5 * kNearMm || nd >= double(dist[std::size_t(m)])) return;
      if (mask_[std::size_t(m)]) return;  // a voxel of the same piece
      dist[std::size_t(m)] = float(nd);
      owner_[std::size_t(m)] = owner_[std::size_t(l)];
      queue.push({float(nd), m});
    });
  }
  // The fronts' owners were written over the space between the pieces: back to the mask's.
  for (std::int64_t l = 0; l < n; ++l)
    if (!mask_[std::size_t(l)]) owner_[std::size_t(l)] = -1;
}

const Contact* SkeletonPieces::contact(int a, int b) const {
  const auto key = std::minmax(a, b);
  const auto it = contacts_.find({key.first, key.second});
  return it == contacts_.end() || it->second.distance > kNearMm ? nullptr : &it->second;
}

std::vector<int> SkeletonPieces::partPiece(int from, double minShare) {
  const Piece& p = pieces_[std::size_t(from)];
  const auto& d = grid_.dims;
  std::array<std::int64_t, 3> lo{d[0], d[1], d[2]}, hi{-1, -1, -1}, box{};
  for (const std::int64_t v : p.voxels) {
    const std::int64_t ijk[3] = {v % d[0], (v / d[0]) % d[1], v / (d[0] * d[1])};
    for (int a = 0; a < 3; ++a)
      lo[a] = std::min(lo[a], ijk[a] - 1), hi[a] = std::max(hi[a], ijk[a] + 1);
  }
  for (int a = 0; a < 3; ++a) box[a] = hi[a] - lo[a] + 1;
  auto at = [&](std::int64_t v) {
    return (v % d[0] - lo[0]) +
           box[0] * (((v / d[0]) % d[1] - lo[1]) + box[1] * (v / (d[0] * d[1]) - lo[2]));
  };
  const std::size_t n = std::size_t(box[0] * box[1] * box[2]);
  std::vector<std::uint8_t> in(n, 0);
  for (const std::int64_t v : p.voxels) in[std::size_t(at(v))] = 1;
  const std::int64_t step[3] = {1, box[0], box[0] * box[1]};
  std::vector<int> part(n, -1);
  std::vector<std::int64_t> sizes;
  for (const std::int64_t v : p.voxels) {
    const std::int64_t l = at(v);
    bool inner = true;
    for (int a = 0; a < 3 && inner; ++a)
      for (int t : {-1, 1}) inner = inner && in[std::size_t(l + t * step[a])];
    if (inner) part[std::size_t(l)] = -2;  // eroded, not yet in a part
  }
  auto each26 = [&](std::int64_t l, auto&& f) {
    for (int dk = -1; dk <= 1; ++dk)
      for (int dj = -1; dj <= 1; ++dj)
        for (int di = -1; di <= 1; ++di) {
          const std::int64_t m = l + di + box[0] * (dj + box[1] * dk);
          if ((di || dj || dk) && m >= 0 && m < std::int64_t(n)) f(m);
        }
  };
  // The 26-connected voxels marked `want` from l, marked as the next part.
  auto flood = [&](std::int64_t l, int want) {
    const int id = int(sizes.size());
    std::vector<std::int64_t> got{l};
    part[std::size_t(l)] = id;
    for (std::size_t q = 0; q < got.size(); ++q)
      each26(got[q], [&](std::int64_t m) {
        if (in[std::size_t(m)] && part[std::size_t(m)] == want)
          part[std::size_t(m)] = id, got.push_back(m);
      });
    sizes.push_back(std::int64_t(got.size()));
    return got;
  };
  std::vector<std::int64_t> seeds;
  for (const std::int64_t v : p.voxels)
    if (part[std::size_t(at(v))] == -2) {
      const std::vector<std::int64_t> got = flood(at(v), -2);
      seeds.insert(seeds.end(), got.begin(), got.end());
    }
  const std::int64_t least = std::int64_t(minShare * double(p.voxels.size()));
  std::vector<int> big;
  for (int i = 0; i < int(sizes.size()); ++i)
    if (sizes[std::size_t(i)] >= least) big.push_back(i);
  if (big.empty()) return {from};
  // Small eroded parts are not seeds: their voxels are grown over like the eroded ones.
  std::vector<std::int64_t> frontier;
  for (const std::int64_t l : seeds)
    if (sizes[std::size_t(part[std::size_t(l)])] >= least)
      frontier.push_back(l);
    else
      part[std::size_t(l)] = -1;
  // The opening: one ring around the seeds. What it does not give back is thinner than the
  // erosion (a scapula one voxel thick on a coarse grid, wholly eroded): its large pieces
  // are parts of their own.
  {
    std::vector<std::int64_t> ring;
    for (const std::int64_t l : frontier)
      each26(l, [&](std::int64_t m) {
        if (in[std::size_t(m)] && part[std::size_t(m)] < 0)
          part[std::size_t(m)] = part[std::size_t(l)], ring.push_back(m);
      });
    frontier.insert(frontier.end(), ring.begin(), ring.end());
    for (const std::int64_t v : p.voxels) {
      if (part[std::size_t(at(v))] != -1) continue;
      const std::vector<std::int64_t> got = flood(at(v), -1);
      if (sizes.back() >= least) {
        big.push_back(int(sizes.size()) - 1);
        frontier.insert(frontier.end(), got.begin(), got.end());
      } else {
        for (const std::int64_t m : got) part[std::size_t(m)] = -3;  // grown over below
      }
    }
    for (const std::int64_t v : p.voxels)
      if (part[std::size_t(at(v))] == -3) part[std::size_t(at(v))] = -1;
  }
  if (big.size() < 2) return {from};
  while (!frontier.empty()) {
    std::vector<std::int64_t> ring;
    for (const std::int64_t l : frontier)
      each26(l, [&](std::int64_t m) {
        if (in[std::size_t(m)] && part[std::size_t(m)] < 0)
          part[std::size_t(m)] = part[std::size_t(l)], ring.push_back(m);
      });
    frontier.swap(ring);
  }
  std::sort(big.begin(), big.end(),
            [&](int a, int b) { return sizes[std::size_t(a)] > sizes[std::size_t(b)]; });
  std::vector<int> out{from};
  for (std::size_t k = 1; k < big.size(); ++k) {
    const int id = big[k];
    const int made = carve(from, [&](std::int64_t v) { return part[std::size_t(at(v))] == id; });
    if (made >= 0 && made != from) out.push_back(made);
  }
  return out;
}

void SkeletonPieces::merge(int into, int from) {
  Piece& a = pieces_[std::size_t(into)];
  Piece& b = pieces_[std::size_t(from)];
  for (const std::int64_t v : b.voxels) owner_[std::size_t(local(v))] = into;
  a.voxels.insert(a.voxels.end(), b.voxels.begin(), b.voxels.end());
  b.voxels.clear();
  describe(a);
}

int SkeletonPieces::cutAcross(int from, const V& u, double lo, double hi) {
  const Piece& p = pieces_[std::size_t(from)];
  double a = 1e300, b = -1e300;
  for (const std::int64_t v : p.voxels) {
    const double t = grid_.ras(v).dot(u);
    a = std::min(a, t), b = std::max(b, t);
  }
  const double width = std::fabs(u.x()) * grid_.spacing.x() + std::fabs(u.y()) * grid_.spacing.y() +
                       std::fabs(u.z()) * grid_.spacing.z();
  const std::size_t bins = std::size_t(std::ceil((b - a) / width)) + 1;
  std::vector<std::int64_t> count(bins, 0);
  for (const std::int64_t v : p.voxels) ++count[std::size_t((grid_.ras(v).dot(u) - a) / width)];
  std::size_t best = bins;
  for (std::size_t k = std::size_t(lo * double(bins));
       k < std::min(bins, std::size_t(hi * double(bins)) + 1); ++k)
    if (best == bins || count[k] < count[best]) best = k;
  if (best == bins) return -1;
  const double at = a + (double(best) + 0.5) * width;
  const int d = carve(from, [&](std::int64_t v) { return grid_.ras(v).dot(u) > at; });
  return d == from ? -1 : d;
}

int SkeletonPieces::carve(int from, const std::function<bool(std::int64_t)>& take) {
  Piece fresh;
  std::vector<std::int64_t> keep;
  for (const std::int64_t v : pieces_[std::size_t(from)].voxels)
    (take(v) ? fresh.voxels : keep).push_back(v);
  if (fresh.voxels.empty() || keep.empty()) return fresh.voxels.empty() ? -1 : from;
  pieces_[std::size_t(from)].voxels.swap(keep);
  describe(pieces_[std::size_t(from)]);
  describe(fresh);
  for (const std::int64_t v : fresh.voxels) owner_[std::size_t(local(v))] = int(pieces_.size());
  pieces_.push_back(std::move(fresh));
  return int(pieces_.size()) - 1;
}

}  // namespace repose::rig
