// The rig's body-part map S. Soft tissue goes to the body part it belongs to through the body, not
// to the nearest bone in a straight line. Each bone floods its limb (or the trunk) through the
// body, deepest tissue first: a voxel joins the flood that reaches it along the widest path (the
// largest distance to the body's surface along the way). Where an arm rests on the trunk they
// touch across a narrow neck of tissue, so each side's own flood fills it before the other's can
// cross (a watershed on the distance to the surface, seeded by the bones). Tissue labels that say
// their region (ICRP 110's arm, leg and trunk skin, muscle, adipose, vessels) hold it. Each limb's
// flood is then cut into segments by its joints' planes, and every bone keeps its own part.
#include "RigInternal.h"

#include "repose/util/Error.h"
#include "repose/volume/DistanceTransform.h"

#include <algorithm>
#include <cmath>

namespace repose::rig {
namespace {

// Floods: 0 the axial body (torso and head), 1 left arm, 2 right arm, 3 left leg, 4 right leg.
int floodOf(BoneKind kind, int side) {
  switch (kind) {
    case BoneKind::Humerus:
    case BoneKind::Forearm:
    case BoneKind::Hand:
      return side < 0 ? 1 : 2;
    case BoneKind::Femur:
    case BoneKind::Shank:
    case BoneKind::Patella:
    case BoneKind::Foot:
      return side < 0 ? 3 : 4;
    default:
      return 0;
  }
}

// Which floods a voxel of a region may join (bit per flood).
std::uint8_t allowedFloods(BodyRegion region) {
  switch (region) {
    case BodyRegion::Head:
    case BodyRegion::Trunk:
      return 1;
    case BodyRegion::Arms:
      return 2 | 4;
    case BodyRegion::Legs:
      return 8 | 16;
    case BodyRegion::Unknown:
      break;
  }
  return 31;
}

const FittedJoint* jointNamed(const std::vector<FittedJoint>& joints, const std::string& name) {
  for (const FittedJoint& j : joints)
    if (j.name == name) return &j;
  return nullptr;
}

bool beyond(const FittedJoint* j, const V& p) {
  return j && (p - j->centre).dot(j->planeNormal) > 0;
}

}  // namespace

Volume assignParts(const Volume& organs, const LabelConvention& convention, const Bones& bones,
                   const std::vector<FittedJoint>& joints, const Grid& grid, int threads,
                   PartStats& stats, const std::vector<std::uint8_t>* body) {
  const std::int64_t n = grid.count();
  const auto& d = grid.dims;
  // Per voxel: which floods it may join (0: not body).
  std::vector<std::uint8_t> allowed(std::size_t(n), 0);
  {
    std::vector<std::uint8_t> byLabel(65536, 0);
    for (const auto& [v, r] : convention.roles)
      if (v > 0 && v < 65536) byLabel[std::size_t(v)] = allowedFloods(r.region);
    dispatchScalar(organs.scalarType(), [&](auto* tag) {
      using T = std::remove_pointer_t<decltype(tag)>;
      if constexpr (std::is_integral_v<T>) {
        const T* g = organs.data<T>();
        for (std::int64_t i = 0; i < n; ++i)
          if (g[i] > 0 && double(g[i]) < 65536)
            allowed[std::size_t(i)] = byLabel[std::size_t(g[i])];
      }
    });
  }
  // The body beyond G's labels (the image's outline): tissue no label names, any flood's.
  if (body)
    for (std::int64_t i = 0; i < n; ++i)
      if ((*body)[std::size_t(i)] && !allowed[std::size_t(i)]) allowed[std::size_t(i)] = 31;
  // The distance of every body voxel to the body's surface (mm).
  std::vector<std::uint8_t> outside(static_cast<std::size_t>(n));
  for (std::int64_t i = 0; i < n; ++i) outside[std::size_t(i)] = allowed[std::size_t(i)] == 0;
  std::vector<float> depth = squaredDistanceToMaskLean(outside, d, grid.spacing, threads);
  outside = {};
  for (float& v : depth) v = std::isfinite(v) ? std::sqrt(v) : 1e6f;

  // A limb floods only from its root bone: a forearm without its humerus stays with the torso.
  auto limbRooted = [&](BoneKind kind, int side) {
    switch (floodOf(kind, side)) {
      case 1:
      case 2:
        return bones.find(BoneKind::Humerus, side) != nullptr;
      case 3:
      case 4:
        return bones.find(BoneKind::Femur, side) != nullptr;
      default:
        return true;
    }
  };
  std::vector<std::int8_t> flood(std::size_t(n), -1);
  // A bucket queue of levels of a quarter millimetre, deepest first, FIFO within a level.
  constexpr double kLevel = 0.25;
  float deepest = 0;
  for (std::int64_t i = 0; i < n; ++i)
    if (allowed[std::size_t(i)]) deepest = std::max(deepest, depth[std::size_t(i)]);
  const std::size_t levels = std::size_t(deepest / kLevel) + 2;
  std::vector<std::vector<std::int64_t>> bucket(levels);
  auto level = [&](float v) { return std::min(levels - 1, std::size_t(double(v) / kLevel)); };
  for (const auto& [key, bone] : bones.byKind) {
    const int f = limbRooted(bone.kind, bone.side) ? floodOf(bone.kind, bone.side) : 0;
    for (const std::int64_t v : bone.voxels) {
      flood[std::size_t(v)] = std::int8_t(f);
      bucket[level(depth[std::size_t(v)])].push_back(v);
    }
  }
  const std::int64_t step[3] = {1, d[0], d[0] * d[1]};
  for (std::size_t l = levels; l-- > 0;) {
    std::vector<std::int64_t>& q = bucket[l];
    for (std::size_t at = 0; at < q.size(); ++at) {
      const std::int64_t v = q[at];
      const int f = flood[std::size_t(v)];
      const std::int64_t ijk[3] = {v % d[0], (v / d[0]) % d[1], v / (d[0] * d[1])};
      for (int a = 0; a < 3; ++a)
        for (const int s : {-1, 1}) {
          const std::int64_t c = ijk[a] + s;
          if (c < 0 || c >= d[a]) continue;
          const std::int64_t nb = v + s * step[a];
          if (flood[std::size_t(nb)] >= 0 || !(allowed[std::size_t(nb)] & (1u << f))) continue;
          flood[std::size_t(nb)] = std::int8_t(f);
          bucket[std::min(l, level(depth[std::size_t(nb)]))].push_back(nb);
        }
    }
    std::vector<std::int64_t>().swap(q);
  }

  // Segments: each flood cut by its joints' planes, proximal to distal.
  Volume parts(*grid.geometry, ScalarType::UInt8);
  parts.setLabelMap(true);
  parts.labels() = rigPartLabels();
  std::uint8_t* s = parts.data<std::uint8_t>();
  const FittedJoint* neck = jointNamed(joints, "neck");
  const FittedJoint* chain[5][3] = {};
  for (int side : {-1, 1}) {
    const std::string sfx = side < 0 ? "_left" : "_right";
    const int arm = side < 0 ? 1 : 2, leg = side < 0 ? 3 : 4;
    chain[arm][0] = jointNamed(joints, "shoulder" + sfx);
    chain[arm][1] = jointNamed(joints, "elbow" + sfx);
    chain[arm][2] = jointNamed(joints, "wrist" + sfx);
    chain[leg][0] = jointNamed(joints, "hip" + sfx);
    chain[leg][1] = jointNamed(joints, "knee" + sfx);
    chain[leg][2] = jointNamed(joints, "ankle" + sfx);
  }
  for (std::int64_t i = 0; i < n; ++i) {
    if (!allowed[std::size_t(i)]) continue;
    int f = flood[std::size_t(i)];
    if (f < 0) {
      ++stats.unreached;
      f = 0;
    }
    const V p = grid.ras(i);
    if (f == 0) {
      s[i] = beyond(neck, p) ? 1 : 2;
      continue;
    }
    const int side = f == 1 || f == 3 ? -1 : 1;
    const bool arm = f <= 2;
    const BoneKind segment[3] = {arm ? BoneKind::Humerus : BoneKind::Femur,
                                 arm ? BoneKind::Forearm : BoneKind::Shank,
                                 arm ? BoneKind::Hand : BoneKind::Foot};
    if (!beyond(chain[f][0], p)) {
      s[i] = 2;  // proximal of the shoulder or the groin: the torso
      continue;
    }
    int k = 0;
    while (k < 2 && chain[f][k + 1] && beyond(chain[f][k + 1], p)) ++k;
    s[i] = std::uint8_t(partOf(segment[k], side));
  }
  // Bones keep their own part (a humeral head reaches across the shoulder's plane).
  for (const auto& [key, bone] : bones.byKind) {
    const int part = limbRooted(bone.kind, bone.side) ? partOf(bone.kind, bone.side) : 2;
    for (const std::int64_t v : bone.voxels) s[v] = std::uint8_t(part);
  }
  assignGirdlesAndPelvis(parts, bones, joints, grid, threads);
  return parts;
}

void assignGirdlesAndPelvis(Volume& parts, const Bones& bones,
                            const std::vector<FittedJoint>& joints, const Grid& grid, int threads) {
  std::uint8_t* s = parts.data<std::uint8_t>();
  const std::int64_t n = grid.count();
  const V up = bones.frame.superior;
  // The pelvis: the trunk below the lumbosacral joint's plane, with the pelvic bones whole and
  // the spine below the plane (the sacrum).
  if (const FittedJoint* ls = jointNamed(joints, "lumbosacral")) {
    for (std::int64_t i = 0; i < n; ++i)
      if (s[i] == 2 && (grid.ras(i) - ls->centre).dot(up) < 0) s[i] = kPartPelvis;
    if (const Bone* pelvis = bones.find(BoneKind::Pelvis, 0))
      for (const std::int64_t v : pelvis->voxels) s[v] = kPartPelvis;
  }
  // Each shoulder girdle: its clavicle and scapula, and the trunk's tissue within kGirdleMm of
  // them that lies nearer them than the rest of the axial skeleton (the ribs under the scapula,
  // the spine beside its medial border, the sternum), on their side of the midline.
  constexpr double kGirdleMm = 25;
  for (const int side : {-1, 1}) {
    if (!jointNamed(joints, side < 0 ? "sternoclavicular_left" : "sternoclavicular_right"))
      continue;
    const std::uint8_t part = std::uint8_t(side < 0 ? kPartGirdleLeft : kPartGirdleRight);
    std::vector<const Bone*> own, other;
    for (const BoneKind k : {BoneKind::Clavicle, BoneKind::Scapula})
      if (const Bone* b = bones.find(k, side)) own.push_back(b);
    for (const BoneKind k : {BoneKind::Ribs, BoneKind::Spine, BoneKind::Sternum})
      if (const Bone* b = bones.find(k, 0)) other.push_back(b);
    // The girdle bones' box grown by the reach, in voxels.
    const auto& d = grid.dims;
    std::array<std::int64_t, 3> lo{d[0], d[1], d[2]}, hi{-1, -1, -1};
    for (const Bone* b : own)
      for (const std::int64_t v : b->voxels) {
        const std::int64_t ijk[3] = {v % d[0], (v / d[0]) % d[1], v / (d[0] * d[1])};
        for (int a = 0; a < 3; ++a)
          lo[std::size_t(a)] = std::min(lo[std::size_t(a)], ijk[a]),
          hi[std::size_t(a)] = std::max(hi[std::size_t(a)], ijk[a]);
      }
    if (hi[0] < 0) continue;
    std::array<std::int64_t, 3> box;
    for (int a = 0; a < 3; ++a) {
      const std::int64_t grow = std::int64_t(std::ceil(kGirdleMm / grid.spacing[a])) + 1;
      lo[std::size_t(a)] = std::max<std::int64_t>(0, lo[std::size_t(a)] - grow);
      hi[std::size_t(a)] = std::min<std::int64_t>(d[std::size_t(a)] - 1, hi[std::size_t(a)] + grow);
      box[std::size_t(a)] = hi[std::size_t(a)] - lo[std::size_t(a)] + 1;
    }
    auto local = [&](std::int64_t v) {
      const std::int64_t i = v % d[0] - lo[0], j = (v / d[0]) % d[1] - lo[1],
                         k = v / (d[0] * d[1]) - lo[2];
      if (i < 0 || j < 0 || k < 0 || i >= box[0] || j >= box[1] || k >= box[2])
        return std::int64_t(-1);
      return i + box[0] * (j + box[1] * k);
    };
    std::vector<std::uint8_t> mine(std::size_t(box[0] * box[1] * box[2]), 0),
        theirs(mine.size(), 0);
    for (const Bone* b : own)
      for (const std::int64_t v : b->voxels) mine[std::size_t(local(v))] = 1;
    for (const Bone* b : other)
      for (const std::int64_t v : b->voxels)
        if (const std::int64_t l = local(v); l >= 0) theirs[std::size_t(l)] = 1;
    const std::vector<float> toMine = squaredDistanceToMask(mine, box, grid.spacing, threads);
    const std::vector<float> toTheirs = squaredDistanceToMask(theirs, box, grid.spacing, threads);
    const double reach2 = kGirdleMm * kGirdleMm;
    for (std::int64_t k = lo[2]; k <= hi[2]; ++k)
      for (std::int64_t j = lo[1]; j <= hi[1]; ++j)
        for (std::int64_t i = lo[0]; i <= hi[0]; ++i) {
          const std::int64_t v = i + d[0] * (j + d[1] * k);
          if (s[v] != 2) continue;  // the trunk's tissue only (not the pelvis, a limb or the head)
          const std::size_t l =
              std::size_t((i - lo[0]) + box[0] * ((j - lo[1]) + box[1] * (k - lo[2])));
          if (double(toMine[l]) > reach2 || toMine[l] >= toTheirs[l]) continue;
          if ((grid.ras(v).x() - bones.frame.midlineX) * double(side) <= 0) continue;
          s[v] = part;
        }
    for (const Bone* b : own)
      for (const std::int64_t v : b->voxels) s[v] = part;
  }
}

double jointRadius(const Volume& parts, const FittedJoint& joint, const Grid& grid) {
  const std::uint8_t* s = parts.data<std::uint8_t>();
  const auto& d = grid.dims;
  const double slab = 1.5 * grid.spacing.maxCoeff();
  std::vector<double> reach;
  const std::int64_t step[3] = {1, d[0], d[0] * d[1]};
  auto isPair = [&](int a, int b) {
    return (a == joint.parts[0] && b == joint.parts[1]) ||
           (a == joint.parts[1] && b == joint.parts[0]);
  };
  for (std::int64_t k = 0; k < d[2]; ++k)
    for (std::int64_t j = 0; j < d[1]; ++j)
      for (std::int64_t i = 0; i < d[0]; ++i) {
        const std::int64_t v = i + d[0] * (j + d[1] * k);
        const int a = s[v];
        if (a != joint.parts[0] && a != joint.parts[1]) continue;
        const std::int64_t ijk[3] = {i, j, k};
        for (int ax = 0; ax < 3; ++ax) {
          if (ijk[ax] + 1 >= d[ax] || !isPair(a, s[v + step[ax]])) continue;
          const V m = 0.5 * (grid.ras(v) + grid.ras(v + step[ax]));
          if (!joint.wholeInterface && std::fabs((m - joint.centre).dot(joint.planeNormal)) > slab)
            continue;
          reach.push_back((m - joint.centre).norm());
        }
      }
  if (reach.empty()) return 0;
  std::sort(reach.begin(), reach.end());
  const double r98 = reach[std::min(reach.size() - 1, std::size_t(0.98 * double(reach.size())))];
  return 1.15 * r98 + grid.spacing.maxCoeff();
}

}  // namespace repose::rig
