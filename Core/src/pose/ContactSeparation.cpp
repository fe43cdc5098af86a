#include "repose/pose/ContactSeparation.h"

#include "repose/util/Error.h"
#include "repose/volume/DistanceTransform.h"

#include <nlohmann/json.hpp>

#include <algorithm>
#include <cmath>
#include <iterator>
#include <map>
#include <set>

namespace repose {
namespace {

// The joints of the standard body parts (the phantom's and the rig's names): a pair of parts
// they connect touches across a joint, so it is never cut whole.
bool standardJointPair(const std::string& a, const std::string& b) {
  static const std::set<std::pair<std::string, std::string>> pairs = [] {
    std::set<std::pair<std::string, std::string>> out{{"head", "torso"}, {"pelvis", "torso"}};
    for (const char* side : {"_left", "_right"}) {
      const std::string s = side;
      for (const auto& [p, q] : {std::pair{"torso", "upper_arm"},
                                 {"torso", "shoulder_girdle"},
                                 {"shoulder_girdle", "upper_arm"},
                                 {"upper_arm", "forearm"},
                                 {"forearm", "hand"},
                                 {"torso", "thigh"},
                                 {"pelvis", "thigh"},
                                 {"thigh", "shank"},
                                 {"shank", "foot"}}) {
        const std::string x = std::string(p) == "torso" || std::string(p) == "pelvis" ? p : p + s,
                          y = q + s;
        out.insert({std::min(x, y), std::max(x, y)});
      }
    }
    return out;
  }();
  return pairs.count({std::min(a, b), std::max(a, b)}) > 0;
}

std::string nameOf(const LabelTable& table, int label) {
  const Label* l = table.find(label);
  return l && !l->name.empty() ? l->name : std::to_string(label);
}

}  // namespace

std::vector<LimbSeparation> ContactSeparations::separations() const {
  std::vector<LimbSeparation> out;
  for (const ContactSeparation& c : made) out.push_back(c.separation);
  return out;
}

std::string ContactSeparations::json() const {
  nlohmann::json cuts = nlohmann::json::array();
  for (const ContactSeparation& c : made)
    cuts.push_back({{"parts", {c.names[0], c.names[1]}},
                    {"labels", {c.separation.labelA, c.separation.labelB}},
                    {"joint", c.joint.empty() ? nlohmann::json() : nlohmann::json(c.joint)},
                    {"region", nlohmann::json::parse(regionToJson(c.separation.region))},
                    {"gap_mm", c.gapMm},
                    {"contact_voxels", c.contactVoxels},
                    {"touching_voxels", c.touchingVoxels},
                    {"centroid_ras", {c.centroid.x(), c.centroid.y(), c.centroid.z()}},
                    {"box_ras", {c.lo.x(), c.lo.y(), c.lo.z(), c.hi.x(), c.hi.y(), c.hi.z()}}});
  return nlohmann::json({{"made", cuts}, {"left_joined", skipped}, {"reach_mm", reachMm}}).dump();
}

double contactReachMm(const CageOptions& cage, const Volume& parts) {
  // The cage's working voxel as CageField.cpp chooses it: whole blocks of input voxels.
  const double target =
      cage.workingVoxelMm > 0 ? cage.workingVoxelMm : std::clamp(cage.dilateMm / 2.5, 3.0, 8.0);
  const Eigen::Vector3d spacing = parts.geometry().spacing();
  double work = 0;
  for (int c = 0; c < 3; ++c)
    work = std::max(work, spacing[c] * std::max(1.0, std::floor(target / spacing[c] + 1e-9)));
  return 2 * (cage.dilateMm + work);
}

std::vector<std::pair<int, int>> groupOfParts(const Pose& pose, const Volume& parts) {
  std::set<int> present;
  dispatchScalar(parts.scalarType(), [&](auto* tag) {
    using T = std::remove_pointer_t<decltype(tag)>;
    const T* s = parts.data<T>();
    std::vector<char> seen(65536, 0);
    for (std::int64_t i = 0; i < parts.numVoxels(); ++i) {
      const double v = double(s[i]);
      if (v > 0 && v < 65536 && !seen[std::size_t(v)])
        seen[std::size_t(v)] = 1, present.insert(int(v));
    }
  });
  std::map<int, int> owner;
  int rest = -1;
  bool allByParts = true;
  for (std::size_t g = 0; g < pose.groups.size(); ++g) {
    const PoseSelection& s = pose.groups[g].select;
    if (s.rest) {
      rest = int(g);
      continue;
    }
    std::vector<int> labels = s.parts;
    for (const std::string& name : s.partNames)
      for (const Label& l : parts.labels().labels())
        if (l.name == name) labels.push_back(l.value);
    if (labels.empty()) allByParts = false;
    for (const int p : labels) owner.emplace(p, int(g));  // the first group naming it
  }
  if (rest >= 0 && allByParts)
    for (const int p : present)
      if (!owner.count(p)) owner[p] = rest;
  return {owner.begin(), owner.end()};
}

namespace {

// Per pair of labels (smaller first): the voxels of either within reach of the other, with their
// squared centre distance to it, and those with a face on the other.
struct PairNear {
  std::vector<std::pair<std::int64_t, double>> voxels;  // may repeat
  std::vector<std::int64_t> touching;
};

std::array<std::int64_t, 3> ijkOf(std::int64_t v, const std::array<std::int64_t, 3>& d) {
  return {v % d[0], (v / d[0]) % d[1], v / (d[0] * d[1])};
}

}  // namespace

ContactSeparations findContactSeparations(const Volume& parts, const Pose& pose,
                                          const Skeleton* skeleton, const ContactOptions& options) {
  ContactSeparations out;
  out.reachMm = options.reachMm;
  const auto owners = groupOfParts(pose, parts);
  std::map<int, int> group(owners.begin(), owners.end());
  // Groups that move: a fixed group (or two) never needs cutting from another fixed one.
  std::vector<char> moves(pose.groups.size(), 0);
  for (std::size_t g = 0; g < pose.groups.size(); ++g) moves[g] = !pose.groups[g].fixed;
  auto cut = [&](int ga, int gb) {
    return ga >= 0 && gb >= 0 && ga != gb && (moves[std::size_t(ga)] || moves[std::size_t(gb)]);
  };

  const auto& d = parts.dims();
  const Eigen::Vector3d spacing = parts.geometry().spacing();
  const std::int64_t step[3] = {1, d[0], d[0] * d[1]};
  std::vector<int> labelAt(std::size_t(parts.numVoxels()), 0);
  std::vector<int> groupOf(65536, -1);
  for (const auto& [p, g] : group)
    if (p > 0 && p < 65536) groupOf[std::size_t(p)] = g;
  // Per label carried by a group: its voxels' index box.
  std::map<int, std::array<std::int64_t, 6>> boxes;
  dispatchScalar(parts.scalarType(), [&](auto* tag) {
    using T = std::remove_pointer_t<decltype(tag)>;
    if constexpr (std::is_integral_v<T>) {
      const T* s = parts.data<T>();
      for (std::int64_t k = 0; k < d[2]; ++k)
        for (std::int64_t j = 0; j < d[1]; ++j)
          for (std::int64_t i = 0; i < d[0]; ++i) {
            const std::int64_t at = parts.index(i, j, k);
            const double v = double(s[at]);
            if (!(v > 0 && v < 65536) || groupOf[std::size_t(v)] < 0) continue;
            labelAt[std::size_t(at)] = int(v);
            auto [it, fresh] =
                boxes.try_emplace(int(v), std::array<std::int64_t, 6>{i, j, k, i, j, k});
            if (!fresh) {
              auto& b = it->second;
              b[0] = std::min(b[0], i), b[1] = std::min(b[1], j), b[2] = std::min(b[2], k);
              b[3] = std::max(b[3], i), b[4] = std::max(b[4], j), b[5] = std::max(b[5], k);
            }
          }
    }
  });
  auto gOf = [&](int label) { return label > 0 ? groupOf[std::size_t(label)] : -1; };

  std::map<std::pair<int, int>, PairNear> near;
  // Touching: voxel pairs across a face whose labels belong to groups that are cut apart.
  for (std::int64_t k = 0; k < d[2]; ++k)
    for (std::int64_t j = 0; j < d[1]; ++j)
      for (std::int64_t i = 0; i < d[0]; ++i) {
        const std::int64_t at = parts.index(i, j, k);
        const int a = labelAt[std::size_t(at)];
        if (!a) continue;
        const std::int64_t ijk[3] = {i, j, k};
        for (int axis = 0; axis < 3; ++axis) {
          if (ijk[axis] + 1 >= d[axis]) continue;
          const std::int64_t nb = at + step[axis];
          const int b = labelAt[std::size_t(nb)];
          if (!b || !cut(gOf(a), gOf(b))) continue;
          PairNear& n = near[{std::min(a, b), std::max(a, b)}];
          n.touching.push_back(at);
          n.touching.push_back(nb);
        }
      }
  // Whether the way from a voxel (box coordinates) to the nearest voxel of the label whose
  // squared distance field `d2` is crosses air: straight down the field's gradient, in steps of
  // half the smallest spacing. A gap is air between two parts; voxels as close through the body
  // itself (the two sides of a joint beyond its sphere) are not near each other.
  std::vector<std::uint8_t> bodyAt(std::size_t(parts.numVoxels()), 0);
  for (std::int64_t v = 0; v < parts.numVoxels(); ++v)
    bodyAt[std::size_t(v)] = parts.valueAsDouble(v) != 0;
  auto acrossAir = [&](const std::array<std::int64_t, 3>& at, const std::array<std::int64_t, 3>& n,
                       const std::array<std::int64_t, 3>& lo, const std::vector<float>& d2,
                       double dist2) {
    auto field = [&](std::int64_t i, std::int64_t j, std::int64_t k) {
      i = std::clamp<std::int64_t>(i, 0, n[0] - 1);
      j = std::clamp<std::int64_t>(j, 0, n[1] - 1);
      k = std::clamp<std::int64_t>(k, 0, n[2] - 1);
      return std::sqrt(double(d2[std::size_t(i + n[0] * (j + n[1] * k))]));
    };
    Eigen::Vector3d g;
    for (int c = 0; c < 3; ++c) {
      std::array<std::int64_t, 3> up = at, down = at;
      ++up[std::size_t(c)], --down[std::size_t(c)];
      g[c] = (field(up[0], up[1], up[2]) - field(down[0], down[1], down[2])) / (2 * spacing[c]);
    }
    if (g.norm() < 1e-6) return false;
    const Eigen::Vector3d towards = -g.normalized();  // mm, towards the label
    const double stepMm = 0.5 * spacing.minCoeff(), length = std::sqrt(dist2);
    for (double t = stepMm; t < length; t += stepMm) {
      std::array<std::int64_t, 3> q;
      for (int c = 0; c < 3; ++c)
        q[std::size_t(c)] =
            lo[std::size_t(c)] + at[std::size_t(c)] + std::llround(t * towards[c] / spacing[c]);
      if (q[0] < 0 || q[1] < 0 || q[2] < 0 || q[0] >= d[0] || q[1] >= d[1] || q[2] >= d[2])
        return true;  // outside the volume: air
      if (!bodyAt[std::size_t(parts.index(q[0], q[1], q[2]))]) return true;
    }
    return false;
  };
  // Near: for each label B, the exact distance to it over its box grown by the reach; every
  // voxel of a label A cut from B within the reach, across air, is near B.
  if (options.reachMm > 0) {
    const double reach2 = options.reachMm * options.reachMm;
    for (const auto& [b, box] : boxes) {
      std::array<std::int64_t, 3> lo, n;
      for (int c = 0; c < 3; ++c) {
        const std::int64_t grow = std::int64_t(std::ceil(options.reachMm / spacing[c]));
        lo[c] = std::max<std::int64_t>(0, box[std::size_t(c)] - grow);
        n[c] = std::min<std::int64_t>(d[c] - 1, box[std::size_t(c) + 3] + grow) - lo[c] + 1;
      }
      // Only worth a transform when some voxel of another, cut label lies in the box.
      bool any = false;
      std::vector<std::uint8_t> mask(std::size_t(n[0] * n[1] * n[2]), 0);
      for (std::int64_t k = 0; k < n[2]; ++k)
        for (std::int64_t j = 0; j < n[1]; ++j)
          for (std::int64_t i = 0; i < n[0]; ++i) {
            const int l = labelAt[std::size_t(parts.index(lo[0] + i, lo[1] + j, lo[2] + k))];
            mask[std::size_t(i + n[0] * (j + n[1] * k))] = l == b;
            any = any || (l && l != b && cut(gOf(l), gOf(b)));
          }
      if (!any) continue;
      const std::vector<float> d2 = squaredDistanceToMask(mask, n, spacing, options.threads);
      for (std::int64_t k = 0; k < n[2]; ++k)
        for (std::int64_t j = 0; j < n[1]; ++j)
          for (std::int64_t i = 0; i < n[0]; ++i) {
            const std::int64_t at = parts.index(lo[0] + i, lo[1] + j, lo[2] + k);
            const int a = labelAt[std::size_t(at)];
            if (!a || a == b || !cut(gOf(a), gOf(b))) continue;
            const double dist2 = double(d2[std::size_t(i + n[0] * (j + n[1] * k))]);
            if (dist2 > reach2 * (1 + 1e-12)) continue;
            if (!acrossAir({i, j, k}, n, lo, d2, dist2)) continue;
            near[{std::min(a, b), std::max(a, b)}].voxels.emplace_back(at, dist2);
          }
    }
  }

  const LabelTable& table = parts.labels();
  for (auto& [pair, list] : near) {
    ContactSeparation c;
    c.separation.labelA = pair.first;
    c.separation.labelB = pair.second;
    c.names = {nameOf(table, pair.first), nameOf(table, pair.second)};
    const SkeletonJoint* joint = nullptr;
    if (skeleton) {
      for (const SkeletonJoint& j : skeleton->joints)
        if ((j.parts[0] == c.names[0] && j.parts[1] == c.names[1]) ||
            (j.parts[0] == c.names[1] && j.parts[1] == c.names[0]))
          joint = &j;
      // Two parts that meet across a joint through a part between them (the torso and the upper
      // arm across the shoulder, where the girdle is a part of its own; the torso and a thigh
      // across the hip, below the pelvis) are spared that joint's sphere: the armpit and the groin
      // are the joint's crease, not a contact.
      for (const SkeletonJoint& j : skeleton->joints) {
        if (joint) break;
        for (int end = 0; end < 2 && !joint; ++end) {
          if (j.parts[1] != c.names[std::size_t(end)]) continue;
          const std::string& other = c.names[std::size_t(1 - end)];
          for (const SkeletonJoint& k : skeleton->joints)
            if (k.parts[0] == other && k.parts[1] == j.parts[0] && !other.empty()) joint = &j;
        }
      }
    }
    if (joint && joint->radiusMm <= 0) {
      out.skipped.push_back(c.names[0] + " and " + c.names[1] + ": the skeleton's joint " +
                            joint->name + " has no radius_mm, so the contact cannot be told " +
                            "from the joint");
      continue;
    }
    if (!joint && standardJointPair(c.names[0], c.names[1])) {
      out.skipped.push_back(c.names[0] + " and " + c.names[1] +
                            ": they meet at a joint the skeleton does not have" +
                            (skeleton ? std::string() : std::string(" (no skeleton)")));
      continue;
    }
    if (joint) {
      c.joint = joint->name;
      c.separation.region.shape = Region::Shape::OutsideSphere;
      c.separation.region.a = joint->centre;
      c.separation.region.b = Eigen::Vector3d(joint->radiusMm, 0, 0);
    } else {
      c.separation.region.shape = Region::Shape::Everywhere;
    }
    auto centre = [&](std::int64_t v) {
      const auto ijk = ijkOf(v, d);
      return parts.geometry().voxelToRas(double(ijk[0]), double(ijk[1]), double(ijk[2]));
    };
    // Near voxels of two parts that meet at a joint count only beyond the joint's sphere grown by
    // the reach: closer in, the air between them is the joint's own crease (the groin, the
    // armpit), which the joint's bend shapes, not a gap between two separate parts.
    Region nearRegion = c.separation.region;
    if (joint) nearRegion.b.x() = joint->radiusMm + options.reachMm;
    std::vector<std::int64_t> voxels, touching;
    double closest2 = 1e300;  // the smallest centre distance inside the region
    for (const auto& [v, d2] : list.voxels)
      if (nearRegion.contains(centre(v))) voxels.push_back(v), closest2 = std::min(closest2, d2);
    for (const std::int64_t v : list.touching)
      if (c.separation.region.contains(centre(v))) touching.push_back(v);
    for (auto* l : {&voxels, &touching}) {
      std::sort(l->begin(), l->end());
      l->erase(std::unique(l->begin(), l->end()), l->end());
    }
    // Touching voxels are within any reach (a face apart).
    std::vector<std::int64_t> all;
    std::set_union(voxels.begin(), voxels.end(), touching.begin(), touching.end(),
                   std::back_inserter(all));
    if (all.empty()) continue;
    c.contactVoxels = std::int64_t(all.size());
    c.touchingVoxels = std::int64_t(touching.size());
    // The air between the nearest voxels: at least the closest centre distance less the voxel's
    // diagonal, so only voxels that close are searched, each over the other label's voxels
    // around it.
    if (touching.empty()) {
      const double diagonal = spacing.norm(), r = std::sqrt(closest2);
      double best = r;
      for (const auto& [v, d2] : list.voxels) {
        if (std::sqrt(d2) > best + diagonal || !nearRegion.contains(centre(v))) continue;
        const int own = labelAt[std::size_t(v)];
        const int other = own == pair.first ? pair.second : pair.first;
        const auto ijk = ijkOf(v, d);
        const double within = std::sqrt(d2) + diagonal;
        std::array<std::int64_t, 3> grow;
        for (int a = 0; a < 3; ++a)
          grow[std::size_t(a)] = std::int64_t(std::ceil(within / spacing[a]));
        for (std::int64_t dk = -grow[2]; dk <= grow[2]; ++dk)
          for (std::int64_t dj = -grow[1]; dj <= grow[1]; ++dj)
            for (std::int64_t di = -grow[0]; di <= grow[0]; ++di) {
              const std::int64_t x = ijk[0] + di, y = ijk[1] + dj, z = ijk[2] + dk;
              if (x < 0 || y < 0 || z < 0 || x >= d[0] || y >= d[1] || z >= d[2]) continue;
              if (labelAt[std::size_t(parts.index(x, y, z))] != other) continue;
              const Eigen::Vector3d air(std::max(0.0, double(std::llabs(di)) - 1) * spacing[0],
                                        std::max(0.0, double(std::llabs(dj)) - 1) * spacing[1],
                                        std::max(0.0, double(std::llabs(dk)) - 1) * spacing[2]);
              best = std::min(best, air.norm());
            }
      }
      c.gapMm = best;
    }
    c.lo = Eigen::Vector3d::Constant(1e300);
    c.hi = Eigen::Vector3d::Constant(-1e300);
    for (const std::int64_t v : all) {
      const Eigen::Vector3d p = centre(v);
      c.centroid += p;
      c.lo = c.lo.cwiseMin(p);
      c.hi = c.hi.cwiseMax(p);
    }
    c.centroid /= double(all.size());
    out.made.push_back(c);
  }
  return out;
}

}  // namespace repose
