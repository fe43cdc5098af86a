#include "repose/raster/PocketFilling.h"

#include "repose/util/Error.h"
#include "repose/volume/BackgroundTrace.h"
#include "repose/volume/LabelStatistics.h"

#include <Eigen/LU>

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <map>
#include <string>

namespace repose {
namespace {

constexpr std::int64_t kNoVoxel = std::numeric_limits<std::int64_t>::min();

// The value of layer 0 at `v` of a map of `type`, as a 64-bit integer.
std::int64_t valueAt(const void* data, ScalarType type, std::int64_t v) {
  std::int64_t out = 0;
  dispatchScalar(type, [&](auto* tag) {
    using T = std::remove_pointer_t<decltype(tag)>;
    if constexpr (std::is_integral_v<T>) out = std::int64_t(static_cast<const T*>(data)[v]);
  });
  return out;
}

void setValue(void* data, ScalarType type, std::int64_t v, std::int64_t value) {
  dispatchScalar(type, [&](auto* tag) {
    using T = std::remove_pointer_t<decltype(tag)>;
    if constexpr (std::is_integral_v<T>) static_cast<T*>(data)[v] = T(value);
  });
}

}  // namespace

// A background voxel the trace left open in its slab: whether it is to be filled when enclosed
// (it does not come from a cavity of the rest body), and its six neighbours' sampled labels in G
// and S (-x, +x, -y, +y, -z, +z; kNoLabel beyond the grid).
struct OpenVoxel {
  std::int64_t voxel = 0;
  std::array<std::int32_t, 6> organs{}, parts{};  // labels are 32-bit (RoundingCandidate's too)
  bool fill = false;
};
constexpr std::int32_t kNoLabel = std::numeric_limits<std::int32_t>::min();

struct PosePockets::Impl {
  const Volume& rest;
  VolumeGeometry posed;
  std::vector<char> restOutside;
  BackgroundTrace trace;
  std::vector<OpenVoxel> open;
  bool withParts = false;
  ScalarType partsType = ScalarType::UInt8;
  bool filled = false;
  // After fill(): the pockets (ascending) and the labels they take (0: no wall to fill from).
  std::vector<std::int64_t> pockets;
  std::vector<std::int64_t> pocketOrgans, pocketParts;
  std::int64_t next = 0;

  std::vector<std::int64_t> rigid;  // sorted

  Impl(const Volume& r, const VolumeGeometry& p, const std::vector<int>& rigidLabels)
      : rest(r),
        posed(p),
        restOutside(outsideBackground(r)),
        trace(p.dims),
        rigid(rigidLabels.begin(), rigidLabels.end()) {
    std::sort(rigid.begin(), rigid.end());
  }

  std::array<std::int64_t, 6> neighbours(std::int64_t voxel) const {
    const auto d = posed.dims;
    const std::int64_t i = voxel % d[0], j = (voxel / d[0]) % d[1], k = voxel / (d[0] * d[1]);
    const std::int64_t plane = d[0] * d[1];
    return {i > 0 ? voxel - 1 : kNoVoxel,     i + 1 < d[0] ? voxel + 1 : kNoVoxel,
            j > 0 ? voxel - d[0] : kNoVoxel,  j + 1 < d[1] ? voxel + d[0] : kNoVoxel,
            k > 0 ? voxel - plane : kNoVoxel, k + 1 < d[2] ? voxel + plane : kNoVoxel};
  }

  // Fills the pockets layer by layer from their walls: each takes the most common non-zero label
  // among its 6 neighbours not waiting to be filled (ties to the smaller label), `wall(n, q)`
  // giving neighbour n (of the pocket's OpenVoxel) voxel q's label when q is no pocket. A label
  // of `avoid` (sorted: G's rigid pieces) is taken only by a pocket that no other label can reach:
  // a gap a pose opens between a bone and its neighbour (a scapula lifted off the ribs) is soft
  // tissue, and a rigid label keeps its count (issue 64).
  template <class Wall>
  std::vector<std::int64_t> fillFromWalls(const std::vector<std::size_t>& entries, Wall&& wall,
                                          const std::vector<std::int64_t>& avoid) const {
    std::vector<std::int64_t> value(pockets.size(), 0);
    std::vector<char> waiting(pockets.size(), 1);
    std::vector<std::size_t> pending(pockets.size());
    for (std::size_t p = 0; p < pending.size(); ++p) pending[p] = p;
    auto pocketIndex = [&](std::int64_t q) -> std::ptrdiff_t {
      const auto it = std::lower_bound(pockets.begin(), pockets.end(), q);
      return it != pockets.end() && *it == q ? it - pockets.begin() : -1;
    };
    auto avoided = [&](std::int64_t label) {
      return std::binary_search(avoid.begin(), avoid.end(), label);
    };
    auto mostCommon = [](const std::map<std::int64_t, int>& votes) {
      std::int64_t best = votes.begin()->first;
      int most = 0;
      for (const auto& [label, count] : votes)
        if (count > most) most = count, best = label;
      return best;
    };
    while (!pending.empty()) {
      std::vector<std::pair<std::size_t, std::int64_t>> layer, avoidedOnly;
      std::vector<std::size_t> rest;
      for (const std::size_t p : pending) {
        const OpenVoxel& o = open[entries[p]];
        const std::array<std::int64_t, 6> around = neighbours(o.voxel);
        std::map<std::int64_t, int> votes, avoidedVotes;
        for (int n = 0; n < 6; ++n) {
          const std::int64_t q = around[std::size_t(n)];
          if (q == kNoVoxel) continue;  // beyond the grid
          const std::ptrdiff_t at = pocketIndex(q);
          const std::int64_t v =
              at >= 0 ? (waiting[std::size_t(at)] ? 0 : value[std::size_t(at)]) : wall(o, n, q);
          if (v != 0) ++(avoided(v) ? avoidedVotes : votes)[v];
        }
        if (!votes.empty()) {
          layer.emplace_back(p, mostCommon(votes));
        } else {
          if (!avoidedVotes.empty()) avoidedOnly.emplace_back(p, mostCommon(avoidedVotes));
          rest.push_back(p);
        }
      }
      // Walled by rigid labels alone, and no other label will come nearer: take them.
      if (layer.empty()) {
        if (avoidedOnly.empty()) break;  // no labelled wall (cannot happen when enclosed)
        layer.swap(avoidedOnly);
        rest.clear();
        std::vector<char> taken(pockets.size(), 0);
        for (const auto& pl : layer) taken[pl.first] = 1;
        for (const std::size_t p : pending)
          if (!taken[p]) rest.push_back(p);
      }
      for (const auto& [p, label] : layer) value[p] = label, waiting[p] = 0;
      pending.swap(rest);
    }
    return value;
  }
};

PosePockets::PosePockets(const Volume& rest, const VolumeGeometry& posed,
                         const std::vector<int>& rigidLabels) {
  if (!isIntegerType(rest.scalarType()))
    throw Error("pockets are filled in label maps, not in float volumes");
  impl_ = std::make_unique<Impl>(rest, posed, rigidLabels);
}

PosePockets::~PosePockets() = default;

void PosePockets::addSlab(std::int64_t k0, std::int64_t k1, const void* organsBelow,
                          const void* organs, const void* organsAbove, const void* partsBelow,
                          const void* parts, const void* partsAbove, ScalarType partsType,
                          const float* field) {
  Impl& r = *impl_;
  const auto d = r.posed.dims;
  if (r.filled || k0 != r.next || k1 <= k0 || k1 > d[2])
    throw Error("pocket filling: slab [" + std::to_string(k0) + ", " + std::to_string(k1) +
                ") out of order (expected from slice " + std::to_string(r.next) + ")");
  if ((k0 > 0 && !organsBelow) || (k1 < d[2] && !organsAbove) ||
      (parts && ((k0 > 0 && !partsBelow) || (k1 < d[2] && !partsAbove))))
    throw Error("pocket filling: a slab inside the grid needs the slices beside it");
  if (k0 == 0) r.withParts = parts != nullptr, r.partsType = partsType;
  if (parts && !isIntegerType(partsType))
    throw Error("pockets are filled in label maps, not in float volumes");
  r.next = k1;
  const ScalarType type = r.rest.scalarType();
  const std::int64_t plane = d[0] * d[1], n = plane * (k1 - k0);
  std::vector<std::int64_t> open;
  r.trace.add(organs, type, k0, k1, &open);
  const Eigen::Matrix4d toRestIjk = r.rest.geometry().ijkToRas.inverse();
  const auto rd = r.rest.dims();
  // A neighbour's sampled label: in the slab, or in the slice beside it.
  auto around = [&](const void* below, const void* slab, const void* above, ScalarType t,
                    std::int64_t q) {
    const std::int64_t local = q - k0 * plane;
    if (local < 0) return valueAt(below, t, local + plane);
    if (local >= n) return valueAt(above, t, local - n);
    return valueAt(slab, t, local);
  };
  for (const std::int64_t c : open) {
    const std::int64_t local = c - k0 * plane;
    const std::int64_t i = c % d[0], j = (c / d[0]) % d[1], k = c / plane;
    OpenVoxel o;
    o.voxel = c;
    const Eigen::Vector3d ras =
        r.posed.voxelToRas(double(i), double(j), double(k)) +
        Eigen::Vector3d(field[3 * local], field[3 * local + 1], field[3 * local + 2]);
    const Eigen::Vector4d p = toRestIjk * Eigen::Vector4d(ras.x(), ras.y(), ras.z(), 1);
    const double ri = std::floor(p.x() + 0.5), rj = std::floor(p.y() + 0.5),
                 rk = std::floor(p.z() + 0.5);
    const bool onGrid = ri >= 0 && rj >= 0 && rk >= 0 && ri < rd[0] && rj < rd[1] && rk < rd[2];
    // Off the rest grid: no tet covered it (the field points far outside) or it came from the
    // rest grid's own outside; either way not a cavity of the body. From rest background
    // enclosed by the body: a cavity the body has. From its outside, from tissue (the rasterizer
    // put background there, so not) or from no rest position at all: a pocket the pose made.
    const std::int64_t q =
        onGrid ? r.rest.index(std::int64_t(ri), std::int64_t(rj), std::int64_t(rk)) : -1;
    const bool fromCavity =
        q >= 0 && !r.restOutside[std::size_t(q)] && valueAt(r.rest.layerData(0), type, q) == 0;
    o.fill = !fromCavity;
    const std::array<std::int64_t, 6> next = r.neighbours(c);
    for (int m = 0; m < 6; ++m) {
      const std::int64_t v = next[std::size_t(m)];
      o.organs[std::size_t(m)] =
          v == kNoVoxel ? kNoLabel
                        : std::int32_t(around(organsBelow, organs, organsAbove, type, v));
      o.parts[std::size_t(m)] =
          v == kNoVoxel || !parts
              ? kNoLabel
              : std::int32_t(around(partsBelow, parts, partsAbove, partsType, v));
    }
    r.open.push_back(o);
  }
  // What this slab joined to the outside is dropped: memory follows the holes, not the
  // background that only later slices open to the outside.
  std::vector<std::int64_t> voxels;
  voxels.reserve(r.open.size());
  for (const OpenVoxel& o : r.open) voxels.push_back(o.voxel);
  r.trace.keepOpen(voxels);
  if (voxels.size() < r.open.size()) {
    std::size_t kept = 0;
    for (const OpenVoxel& o : r.open)
      if (kept < voxels.size() && o.voxel == voxels[kept]) r.open[kept++] = o;
    r.open.resize(kept);
  }
}

PocketReport PosePockets::fill(
    const std::function<std::int64_t(std::int64_t, std::int64_t)>& finalOrgan) {
  Impl& r = *impl_;
  if (r.filled || r.next != r.posed.dims[2])
    throw Error("pocket filling: filled before its last slab (slice " + std::to_string(r.next) +
                " of " + std::to_string(r.posed.dims[2]) + ")");
  r.filled = true;
  PocketReport report;
  std::vector<std::size_t> entries;
  for (std::size_t e = 0; e < r.open.size(); ++e) {
    const OpenVoxel& o = r.open[e];
    if (!r.trace.enclosed(o.voxel)) continue;
    if (o.fill) {
      entries.push_back(e);
      r.pockets.push_back(o.voxel);
    } else {
      ++report.keptCavities;
    }
  }
  report.filled = std::int64_t(r.pockets.size());
  r.pocketOrgans = r.fillFromWalls(
      entries,
      [&](const OpenVoxel& o, int n, std::int64_t q) {
        const std::int64_t sampled = o.organs[std::size_t(n)];
        return sampled != 0 && finalOrgan ? finalOrgan(q, sampled) : sampled;
      },
      r.rigid);
  if (r.withParts)
    r.pocketParts = r.fillFromWalls(
        entries, [&](const OpenVoxel& o, int n, std::int64_t) { return o.parts[std::size_t(n)]; },
        {});
  // Only the pockets are needed from here on.
  r.open.clear(), r.open.shrink_to_fit();
  return report;
}

void PosePockets::apply(std::int64_t k0, std::int64_t k1, void* organs, void* parts) const {
  const Impl& r = *impl_;
  if (!r.filled) throw Error("pocket filling: applied before the fill");
  const std::int64_t plane = r.posed.dims[0] * r.posed.dims[1];
  const auto first = std::lower_bound(r.pockets.begin(), r.pockets.end(), k0 * plane);
  for (auto it = first; it != r.pockets.end() && *it < k1 * plane; ++it) {
    const std::size_t p = std::size_t(it - r.pockets.begin());
    if (r.pocketOrgans[p] != 0)
      setValue(organs, r.rest.scalarType(), *it - k0 * plane, r.pocketOrgans[p]);
    if (parts && r.withParts && r.pocketParts[p] != 0)
      setValue(parts, r.partsType, *it - k0 * plane, r.pocketParts[p]);
  }
}

PocketReport fillPosePockets(Volume& posed, const Volume& rest, const std::vector<float>& field,
                             Volume* posedParts, const std::vector<int>& rigidLabels) {
  if (!isIntegerType(posed.scalarType()) || !isIntegerType(rest.scalarType()))
    throw Error("pockets are filled in label maps, not in float volumes");
  if (posed.scalarType() != rest.scalarType())
    throw Error("the posed label map is not of the rest map's type");
  const std::int64_t n = posed.numVoxels();
  if (field.size() != std::size_t(3 * n))
    throw Error("the displacement field does not match the posed grid");
  if (posedParts && posedParts->dims() != posed.dims())
    throw Error("the posed parts map is on another grid");
  // One slab of every slice: a frame made slab by slab fills the same voxels with the same labels.
  PosePockets pockets(rest, posed.geometry(), rigidLabels);
  void* parts = posedParts ? posedParts->layerData(0) : nullptr;
  const ScalarType partsType = posedParts ? posedParts->scalarType() : ScalarType::UInt8;
  pockets.addSlab(0, posed.dims()[2], nullptr, posed.layerData(0), nullptr, nullptr, parts, nullptr,
                  partsType, field.data());
  const PocketReport report = pockets.fill();
  pockets.apply(0, posed.dims()[2], posed.layerData(0), parts);
  return report;
}

}  // namespace repose
