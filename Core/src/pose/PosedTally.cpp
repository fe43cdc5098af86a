#include "repose/pose/PosedTally.h"

#include "repose/util/Error.h"
#include "repose/util/Parallel.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <mutex>
#include <string>
#include <type_traits>

namespace repose {
namespace {

// Counts of one run of slices, merged into the tally's at the end (sums: any order gives the
// same figures).
struct Counts {
  std::map<int, std::int64_t> labels;
  std::vector<GroupDiceCounts> groups;
  std::map<std::pair<PieceId, PieceId>, std::int64_t> collisions;
};

// Which labels are rigid: a table over the 16-bit range (every real map's labels), a search
// beyond it.
class RigidLookup {
 public:
  explicit RigidLookup(const std::vector<int>& sorted) : sorted_(sorted) {
    for (const int l : sorted)
      if (l >= kLow && l < kLow + kSpan) table_[std::size_t(l - kLow)] = 1;
  }
  bool any() const { return !sorted_.empty(); }
  bool operator()(int label) const {
    if (label >= kLow && label < kLow + kSpan) return table_[std::size_t(label - kLow)] != 0;
    return std::binary_search(sorted_.begin(), sorted_.end(), label);
  }

 private:
  static constexpr int kLow = -32768, kSpan = 65536;
  const std::vector<int>& sorted_;
  std::vector<char> table_ = std::vector<char>(kSpan, 0);
};

// The first group's rigid tissue claiming a posed voxel of the slice being counted.
struct Claim {
  int group = -1;
  PieceId piece;
};

void mergeInto(std::map<int, std::int64_t>& to, const std::map<int, std::int64_t>& from) {
  for (const auto& [label, n] : from) to[label] += n;
}

// Per label value, a dense counter: the rest map's values are few, the posed map's the same.
template <class T>
struct Dense {
  std::vector<std::int64_t> n;
  void add(T value) {
    const std::size_t at = std::size_t(std::int64_t(value) - std::int64_t(kMin));
    if (at >= n.size()) n.resize(at + 1, 0);
    ++n[at];
  }
  void into(std::map<int, std::int64_t>& map, bool skipZero) const {
    for (std::size_t at = 0; at < n.size(); ++at)
      if (n[at] && !(skipZero && std::int64_t(at) + std::int64_t(kMin) == 0))
        map[int(std::int64_t(at) + std::int64_t(kMin))] += n[at];
  }
  static constexpr T kMin = std::is_signed_v<T> ? std::numeric_limits<T>::lowest() : T(0);
};

template <class TG, class TS>
void countSlices(const Volume& G, const Volume& S, const std::vector<RigidHandle>* handles,
                 const RigidLookup& rigid, const VolumeGeometry& grid, const TG* pg, const TS* ps,
                 std::int64_t k0, std::int64_t ka, std::int64_t kb, Counts& out) {
  const std::int64_t nx = grid.dims[0], ny = grid.dims[1], plane = nx * ny;
  // Labels of the posed G: small types through a dense counter, wide ones through the map.
  if constexpr (sizeof(TG) <= 2) {
    Dense<TG> dense;
    for (std::int64_t v = (ka - k0) * plane; v < (kb - k0) * plane; ++v) dense.add(pg[v]);
    dense.into(out.labels, true);
  } else {
    for (std::int64_t v = (ka - k0) * plane; v < (kb - k0) * plane; ++v)
      if (pg[v] != TG(0)) ++out.labels[int(pg[v])];
  }
  if (!handles) return;
  const TG* g = G.data<TG>();
  const TS* sp = S.data<TS>();
  const auto rd = G.dims();
  out.groups.resize(handles->size());
  // Per group, once: its parts and the map from a posed voxel to the rest continuous index
  // (affine: one matrix for the whole grid).
  std::vector<std::vector<char>> inParts(handles->size());
  std::vector<Eigen::Matrix4d> toRest(handles->size());
  for (std::size_t h = 0; h < handles->size(); ++h) {
    const RigidHandle& handle = (*handles)[h];
    if (handle.parts.empty()) continue;
    inParts[h].assign(1 << 16, 0);
    for (const int p : handle.parts)
      if (p >= 0 && p < (1 << 16)) inParts[h][std::size_t(p)] = 1;
    toRest[h] = G.geometry().ijkToRas.inverse() * handle.motion.inverse().matrix() * grid.ijkToRas;
  }
  std::vector<Claim> claims(rigid.any() ? std::size_t(plane) : 0);
  for (std::int64_t k = ka; k < kb; ++k) {
    std::fill(claims.begin(), claims.end(), Claim{});
    for (std::size_t h = 0; h < handles->size(); ++h) {
      if (inParts[h].empty()) continue;
      const std::vector<char>& in = inParts[h];
      auto partOf = [&](auto s) {
        return s >= 0 && std::int64_t(s) < (1 << 16) && in[std::size_t(s)];
      };
      GroupDiceCounts& c = out.groups[h];
      for (std::int64_t j = 0; j < ny; ++j)
        for (std::int64_t i = 0; i < nx; ++i) {
          const std::int64_t o = (k - k0) * plane + j * nx + i;
          const int posed = partOf(ps[o]) ? int(pg[o]) : 0;
          const Eigen::Vector4d r = toRest[h] * Eigen::Vector4d(double(i), double(j), double(k), 1);
          const double ri = std::floor(r.x() + 0.5), rj = std::floor(r.y() + 0.5),
                       rk = std::floor(r.z() + 0.5);
          int expected = 0;
          std::int64_t q = -1;
          if (ri >= 0 && rj >= 0 && rk >= 0 && ri < rd[0] && rj < rd[1] && rk < rd[2]) {
            q = G.index(std::int64_t(ri), std::int64_t(rj), std::int64_t(rk));
            if (partOf(sp[q])) expected = int(g[q]);
          }
          if (posed) ++c.posed[posed];
          if (expected) ++c.expected[expected];
          if (posed && posed == expected) ++c.both[posed];
          if (expected && !claims.empty() && rigid(expected)) {
            Claim& first = claims[std::size_t(j * nx + i)];
            const PieceId piece{expected, int(sp[q])};
            if (first.group < 0)
              first = {int(h), piece};
            else if (first.group != int(h))
              ++out.collisions[piece < first.piece ? std::make_pair(piece, first.piece)
                                                   : std::make_pair(first.piece, piece)];
          }
        }
    }
  }
}

}  // namespace

PosedTally::PosedTally(const Volume& organs, const Volume& parts,
                       const std::vector<RigidHandle>* handles, const VolumeGeometry& grid,
                       int threads)
    : organs_(organs),
      parts_(parts),
      handles_(handles),
      grid_(grid),
      threads_(threads),
      holes_(grid.dims) {
  if (organs.dims() != parts.dims())
    throw Error("the body-part map is not on the organ map's grid");
  if (!isIntegerType(organs.scalarType()) || !isIntegerType(parts.scalarType()))
    throw Error("the pose report counts label maps, not float volumes");
  if (!handles) return;
  // The rest side, once: per group, the voxels of each label of G within its parts.
  groups_.resize(handles->size());
  dispatchScalar(organs.scalarType(), [&](auto* gt) {
    using TG = std::remove_pointer_t<decltype(gt)>;
    dispatchScalar(parts.scalarType(), [&](auto* st) {
      using TS = std::remove_pointer_t<decltype(st)>;
      const TG* g = organs.data<TG>();
      const TS* s = parts.data<TS>();
      for (std::size_t h = 0; h < handles->size(); ++h) {
        std::vector<char> inParts(1 << 16, 0);
        for (const int p : (*handles)[h].parts)
          if (p >= 0 && p < (1 << 16)) inParts[std::size_t(p)] = 1;
        for (std::int64_t v = 0; v < organs.numVoxels(); ++v)
          if (s[v] >= 0 && std::int64_t(s[v]) < (1 << 16) && inParts[std::size_t(s[v])])
            ++groups_[h].rest[int(g[v])];
      }
    });
  });
}

void PosedTally::add(const void* posedOrgans, const void* posedParts, std::int64_t k0,
                     std::int64_t k1) {
  if (k0 != next_ || k1 <= k0 || k1 > grid_.dims[2])
    throw Error("pose report: slices [" + std::to_string(k0) + ", " + std::to_string(k1) +
                ") out of order (expected from slice " + std::to_string(next_) + " of " +
                std::to_string(grid_.dims[2]) + ")");
  std::mutex merging;
  const RigidLookup rigid(rigid_);
  dispatchScalar(organs_.scalarType(), [&](auto* gt) {
    using TG = std::remove_pointer_t<decltype(gt)>;
    dispatchScalar(parts_.scalarType(), [&](auto* st) {
      using TS = std::remove_pointer_t<decltype(st)>;
      if constexpr (std::is_integral_v<TG> && std::is_integral_v<TS>) {
        const TG* pg = static_cast<const TG*>(posedOrgans);
        const TS* ps = static_cast<const TS*>(posedParts);
        parallelFor(
            k1 - k0, threads_,
            [&](std::int64_t a, std::int64_t b) {
              Counts local;
              countSlices<TG, TS>(organs_, parts_, handles_, rigid, grid_, pg, ps, k0, k0 + a,
                                  k0 + b, local);
              const std::lock_guard<std::mutex> lock(merging);
              mergeInto(labels_, local.labels);
              for (std::size_t h = 0; h < local.groups.size(); ++h) {
                mergeInto(groups_[h].posed, local.groups[h].posed);
                mergeInto(groups_[h].expected, local.groups[h].expected);
                mergeInto(groups_[h].both, local.groups[h].both);
              }
              for (const auto& [pair, n] : local.collisions) collisions_[pair] += n;
            },
            1);
      }
    });
  });
  holes_.add(posedOrgans, organs_.scalarType(), k0, k1);
  next_ = k1;
}

void PosedTally::countCollisions(const std::vector<int>& rigidLabels) {
  if (next_ != 0) throw Error("pose report: collisions are counted from the first slice");
  rigid_.clear();
  for (const int l : rigidLabels)
    if (l != 0) rigid_.push_back(l);
  std::sort(rigid_.begin(), rigid_.end());
  rigid_.erase(std::unique(rigid_.begin(), rigid_.end()), rigid_.end());
}

std::vector<PieceOverlap> PosedTally::collisions() const {
  std::vector<PieceOverlap> out;
  for (const auto& [pair, n] : collisions_) out.push_back({pair.first, pair.second, n});
  return out;
}

void PosedTally::addWhole(const Volume& posedOrgans, const Volume& posedParts) {
  if (posedOrgans.dims() != grid_.dims || posedParts.dims() != grid_.dims)
    throw Error("pose report: the posed maps are not on the posed grid");
  if (posedOrgans.scalarType() != organs_.scalarType() ||
      posedParts.scalarType() != parts_.scalarType())
    throw Error("pose report: the posed maps' types are not the rest maps'");
  add(posedOrgans.layerData(0), posedParts.layerData(0), 0, grid_.dims[2]);
}

}  // namespace repose
