#include "repose/pose/ContactSeparation.h"

#include "repose/util/Error.h"

#include <nlohmann/json.hpp>

#include <algorithm>
#include <map>
#include <set>

namespace repose {
namespace {

// The joints of the standard body parts (the phantom's and the rig's names): a pair of parts
// they connect touches across a joint, so it is never cut whole.
bool standardJointPair(const std::string& a, const std::string& b) {
  static const std::set<std::pair<std::string, std::string>> pairs = [] {
    std::set<std::pair<std::string, std::string>> out{{"head", "torso"}};
    for (const char* side : {"_left", "_right"}) {
      const std::string s = side;
      for (const auto& [p, q] : {std::pair{"torso", "upper_arm"},
                                 {"upper_arm", "forearm"},
                                 {"forearm", "hand"},
                                 {"torso", "thigh"},
                                 {"thigh", "shank"},
                                 {"shank", "foot"}}) {
        const std::string x = std::string(p) == "torso" ? "torso" : p + s, y = q + s;
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
                    {"contact_voxels", c.contactVoxels},
                    {"centroid_ras", {c.centroid.x(), c.centroid.y(), c.centroid.z()}},
                    {"box_ras", {c.lo.x(), c.lo.y(), c.lo.z(), c.hi.x(), c.hi.y(), c.hi.z()}}});
  return nlohmann::json({{"made", cuts}, {"left_joined", skipped}}).dump();
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

ContactSeparations findContactSeparations(const Volume& parts, const Pose& pose,
                                          const Skeleton* skeleton) {
  ContactSeparations out;
  const auto owners = groupOfParts(pose, parts);
  std::map<int, int> group(owners.begin(), owners.end());
  // Groups that move: a fixed group (or two) never needs cutting from another fixed one.
  std::vector<char> moves(pose.groups.size(), 0);
  for (std::size_t g = 0; g < pose.groups.size(); ++g) moves[g] = !pose.groups[g].fixed;

  // Voxel pairs across a face whose labels belong to different groups, by label pair.
  const auto& d = parts.dims();
  std::map<std::pair<int, int>, std::vector<std::pair<std::int64_t, std::int64_t>>> faces;
  dispatchScalar(parts.scalarType(), [&](auto* tag) {
    using T = std::remove_pointer_t<decltype(tag)>;
    if constexpr (std::is_integral_v<T>) {
      const T* s = parts.data<T>();
      std::vector<int> groupOf(65536, -1);
      for (const auto& [p, g] : group)
        if (p > 0 && p < 65536) groupOf[std::size_t(p)] = g;
      auto gOf = [&](T v) { return v > 0 && double(v) < 65536 ? groupOf[std::size_t(v)] : -1; };
      const std::int64_t step[3] = {1, d[0], d[0] * d[1]};
      for (std::int64_t k = 0; k < d[2]; ++k)
        for (std::int64_t j = 0; j < d[1]; ++j)
          for (std::int64_t i = 0; i < d[0]; ++i) {
            const std::int64_t at = parts.index(i, j, k);
            const int ga = gOf(s[at]);
            if (ga < 0) continue;
            const std::int64_t ijk[3] = {i, j, k};
            for (int axis = 0; axis < 3; ++axis) {
              if (ijk[axis] + 1 >= d[axis]) continue;
              const std::int64_t nb = at + step[axis];
              const int gb = gOf(s[nb]);
              if (gb < 0 || gb == ga || (!moves[std::size_t(ga)] && !moves[std::size_t(gb)]))
                continue;
              const int a = int(s[at]), b = int(s[nb]);
              if (a < b)
                faces[{a, b}].emplace_back(at, nb);
              else
                faces[{b, a}].emplace_back(nb, at);
            }
          }
    }
  });

  const LabelTable& table = parts.labels();
  for (const auto& [pair, list] : faces) {
    ContactSeparation c;
    c.separation.labelA = pair.first;
    c.separation.labelB = pair.second;
    c.names = {nameOf(table, pair.first), nameOf(table, pair.second)};
    const SkeletonJoint* joint = nullptr;
    if (skeleton)
      for (const SkeletonJoint& j : skeleton->joints)
        if ((j.parts[0] == c.names[0] && j.parts[1] == c.names[1]) ||
            (j.parts[0] == c.names[1] && j.parts[1] == c.names[0]))
          joint = &j;
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
    std::set<std::int64_t> voxels;
    for (const auto& [va, vb] : list) {
      const std::int64_t i0 = va % d[0], j0 = (va / d[0]) % d[1], k0 = va / (d[0] * d[1]);
      const std::int64_t i1 = vb % d[0], j1 = (vb / d[0]) % d[1], k1 = vb / (d[0] * d[1]);
      const Eigen::Vector3d mid =
          0.5 * (parts.geometry().voxelToRas(double(i0), double(j0), double(k0)) +
                 parts.geometry().voxelToRas(double(i1), double(j1), double(k1)));
      if (!c.separation.region.contains(mid)) continue;
      voxels.insert(va);
      voxels.insert(vb);
    }
    if (voxels.empty()) continue;
    c.contactVoxels = std::int64_t(voxels.size());
    c.lo = Eigen::Vector3d::Constant(1e300);
    c.hi = Eigen::Vector3d::Constant(-1e300);
    for (const std::int64_t v : voxels) {
      const Eigen::Vector3d p = parts.geometry().voxelToRas(
          double(v % d[0]), double((v / d[0]) % d[1]), double(v / (d[0] * d[1])));
      c.centroid += p;
      c.lo = c.lo.cwiseMin(p);
      c.hi = c.hi.cwiseMax(p);
    }
    c.centroid /= double(voxels.size());
    out.made.push_back(c);
  }
  return out;
}

}  // namespace repose
