#include "repose/pose/JointClearance.h"

#include "repose/pose/ContactSeparation.h"
#include "repose/util/Error.h"

#include <Eigen/LU>

#include <algorithm>
#include <array>
#include <cmath>
#include <map>

namespace repose {
namespace {

// The distal bone within this reach of the joint (at least kReachMm, else 2.5 joint radii): the
// bone ends that meet there, not the far end of a long bone.
constexpr double kReachMm = 30;

}  // namespace

JointClearance::JointClearance(const Pose& pose, const Skeleton& skeleton, const Volume& organs,
                               const Volume& parts, const std::vector<int>& rigidLabels) {
  if (organs.dims() != parts.dims()) throw Error("joint clearance: G and S are on other grids");
  grid_ = organs.geometry();
  std::vector<int> rigid = rigidLabels;
  std::sort(rigid.begin(), rigid.end());
  if (rigid.empty()) return;
  auto isRigid = [&](double v) {
    return v == std::floor(v) && std::binary_search(rigid.begin(), rigid.end(), int(v));
  };
  // Which group carries each part, and each group's followers.
  std::map<int, int> groupOf;
  for (const auto& [label, group] : groupOfParts(pose, parts)) groupOf[label] = group;
  std::map<std::string, int> named;
  for (std::size_t g = 0; g < pose.groups.size(); ++g) named[pose.groups[g].name] = int(g);
  auto follows = [&](int g, int ancestor) {
    for (int at = g, hops = 0; at >= 0 && hops <= int(pose.groups.size()); ++hops) {
      if (at == ancestor) return true;
      const auto it = named.find(pose.groups[std::size_t(at)].follows);
      at = it == named.end() ? -1 : it->second;
    }
    return false;
  };
  auto labelOf = [&](const std::string& name) {
    for (const Label& l : parts.labels().labels())
      if (l.name == name) return l.value;
    return 0;
  };
  const Eigen::Matrix4d toIjk = grid_.ijkToRas.inverse();
  const auto d = grid_.dims;
  const Eigen::Vector3d half = 0.5 * grid_.spacing();  // a voxel's box around its centre
  for (const SkeletonJoint& j : skeleton.joints) {
    const int a = labelOf(j.parts[0]), b = labelOf(j.parts[1]);
    if (a <= 0 || b <= 0 || !groupOf.count(a) || !groupOf.count(b)) continue;
    Site site;
    site.name = j.name;
    site.proximal = groupOf[a];
    site.distal = groupOf[b];
    if (site.proximal == site.distal || follows(site.proximal, site.distal)) continue;
    site.centre = j.centre;
    for (std::size_t g = 0; g < pose.groups.size(); ++g)
      if (follows(int(g), site.distal)) site.carried.push_back(int(g));
    const double reach = std::max(kReachMm, 2.5 * j.radiusMm);
    // The box of the ball in voxels.
    std::array<std::int64_t, 3> lo{d[0], d[1], d[2]}, hi{-1, -1, -1};
    for (int corner = 0; corner < 8; ++corner) {
      const Eigen::Vector3d c =
          j.centre +
          reach * Eigen::Vector3d(corner & 1 ? 1 : -1, corner & 2 ? 1 : -1, corner & 4 ? 1 : -1);
      const Eigen::Vector4d p = toIjk * Eigen::Vector4d(c.x(), c.y(), c.z(), 1);
      for (int x = 0; x < 3; ++x) {
        lo[std::size_t(x)] = std::min(lo[std::size_t(x)], std::int64_t(std::floor(p[x])));
        hi[std::size_t(x)] = std::max(hi[std::size_t(x)], std::int64_t(std::ceil(p[x])));
      }
    }
    for (int x = 0; x < 3; ++x) {
      lo[std::size_t(x)] = std::max<std::int64_t>(0, lo[std::size_t(x)]);
      hi[std::size_t(x)] = std::min<std::int64_t>(d[std::size_t(x)] - 1, hi[std::size_t(x)]);
    }
    for (std::int64_t k = lo[2]; k <= hi[2]; ++k)
      for (std::int64_t jj = lo[1]; jj <= hi[1]; ++jj)
        for (std::int64_t i = lo[0]; i <= hi[0]; ++i) {
          const std::int64_t v = organs.index(i, jj, k);
          const double s = parts.valueAsDouble(v);
          if ((s != a && s != b) || !isRigid(organs.valueAsDouble(v))) continue;
          const Eigen::Vector3d ras = grid_.voxelToRas(double(i), double(jj), double(k));
          if ((ras - j.centre).norm() > reach) continue;
          if (s == a) {
            site.proximalBone.push_back(v);
            site.proximalBox.extend(ras - half), site.proximalBox.extend(ras + half);
          } else {
            site.distalBone.push_back(v);
            site.distalCentroid += ras;
            site.distalBox.extend(ras - half), site.distalBox.extend(ras + half);
          }
        }
    if (site.proximalBone.empty() || site.distalBone.empty()) continue;
    site.distalCentroid /= double(site.distalBone.size());
    site.reachMm = reach;
    std::sort(site.proximalBone.begin(), site.proximalBone.end());
    std::sort(site.distalBone.begin(), site.distalBone.end());
    sites_.push_back(std::move(site));
  }
}

std::int64_t JointClearance::overlap(const Site& site, const Eigen::Isometry3d& proximal,
                                     const Eigen::Isometry3d& distal) const {
  // PosedTally's rule on the posed lattice (the rest grid's, shifted by whole voxels): a posed
  // voxel both groups map back onto their bone. Only the lattice around the posed joint.
  const Eigen::Matrix4d toIjk = grid_.ijkToRas.inverse();
  const Eigen::Matrix4d toDistal = toIjk * distal.inverse().matrix() * grid_.ijkToRas;
  const Eigen::Matrix4d toProximal = toIjk * proximal.inverse().matrix() * grid_.ijkToRas;
  // Where both bones can be: the posed boxes of the two bones' rest boxes, intersected, in the
  // lattice's IJK (most joints' bone ends do not reach into each other's box at all).
  std::array<double, 3> lo{-1e300, -1e300, -1e300}, hi{1e300, 1e300, 1e300};
  for (const auto& [box, motion] :
       {std::pair{&site.distalBox, &distal}, std::pair{&site.proximalBox, &proximal}}) {
    std::array<double, 3> blo{1e300, 1e300, 1e300}, bhi{-1e300, -1e300, -1e300};
    for (int corner = 0; corner < 8; ++corner) {
      const Eigen::Vector3d c((corner & 1 ? box->max() : box->min()).x(),
                              (corner & 2 ? box->max() : box->min()).y(),
                              (corner & 4 ? box->max() : box->min()).z());
      const Eigen::Vector3d ras = *motion * c;
      const Eigen::Vector4d p = toIjk * Eigen::Vector4d(ras.x(), ras.y(), ras.z(), 1);
      for (int x = 0; x < 3; ++x)
        blo[std::size_t(x)] = std::min(blo[std::size_t(x)], p[x]),
        bhi[std::size_t(x)] = std::max(bhi[std::size_t(x)], p[x]);
    }
    for (int x = 0; x < 3; ++x)
      lo[std::size_t(x)] = std::max(lo[std::size_t(x)], std::floor(blo[std::size_t(x)] - 1)),
      hi[std::size_t(x)] = std::min(hi[std::size_t(x)], std::ceil(bhi[std::size_t(x)] + 1));
  }
  const auto d = grid_.dims;
  auto voxel = [&](const Eigen::Matrix4d& m, double i, double j, double k) -> std::int64_t {
    const Eigen::Vector4d p = m * Eigen::Vector4d(i, j, k, 1);
    const double x = std::floor(p.x() + 0.5), y = std::floor(p.y() + 0.5),
                 z = std::floor(p.z() + 0.5);
    if (x < 0 || y < 0 || z < 0 || x >= double(d[0]) || y >= double(d[1]) || z >= double(d[2]))
      return -1;
    return std::int64_t(x) + d[0] * (std::int64_t(y) + d[1] * std::int64_t(z));
  };
  auto in = [](const std::vector<std::int64_t>& set, std::int64_t v) {
    return v >= 0 && std::binary_search(set.begin(), set.end(), v);
  };
  std::int64_t n = 0;
  for (double k = lo[2]; k <= hi[2]; ++k)
    for (double j = lo[1]; j <= hi[1]; ++j)
      for (double i = lo[0]; i <= hi[0]; ++i)
        n += in(site.distalBone, voxel(toDistal, i, j, k)) &&
             in(site.proximalBone, voxel(toProximal, i, j, k));
  return n;
}

std::vector<JointClearance::Shift> JointClearance::apply(
    std::vector<Eigen::Isometry3d>& motions) const {
  std::vector<Shift> out;
  for (const Site& site : sites_) {
    if (std::size_t(std::max(site.proximal, site.distal)) >= motions.size()) continue;
    const Eigen::Isometry3d& proximal = motions[std::size_t(site.proximal)];
    const Eigen::Isometry3d distal = motions[std::size_t(site.distal)];
    if ((proximal.inverse() * distal).matrix().isApprox(Eigen::Matrix4d::Identity(), 1e-12))
      continue;  // the joint does not move
    // What the collision target allows is left as posed: 0.1 % of the smaller bone end within
    // reach of the joint, at least a voxel (docs/QUALITY.md's target takes 0.1 % of the whole
    // smaller bone, so this is the stricter of the two).
    const std::int64_t allowed = std::max<std::int64_t>(
        1,
        std::int64_t(0.001 * double(std::min(site.distalBone.size(), site.proximalBone.size()))));
    const std::int64_t before = overlap(site, proximal, distal);
    if (before <= allowed) continue;
    // Along the distal bone: from the posed joint centre to the posed bone's centroid.
    const Eigen::Vector3d along = distal * site.distalCentroid - distal * site.centre;
    if (!(along.norm() > 1e-9)) continue;
    const Eigen::Vector3d dir = along.normalized();
    std::int64_t best = before;
    double bestMm = 0;
    for (double mm = kStepMm; mm <= kMaxShiftMm + 1e-9 && best > 0; mm += kStepMm) {
      const std::int64_t n = overlap(site, proximal, Eigen::Translation3d(mm * dir) * distal);
      if (n < best) best = n, bestMm = mm;
    }
    // Parted within the target, or left as posed: a limb moved millimetres for a collision it
    // does not clear (a scapula turned into the ribs beside the joint) is worse than none.
    if (bestMm == 0 || best > allowed) continue;
    const Eigen::Translation3d shift(bestMm * dir);
    for (const int g : site.carried)
      if (std::size_t(g) < motions.size())
        motions[std::size_t(g)] = shift * motions[std::size_t(g)];
    Shift s;
    s.joint = site.name;
    s.group = site.distal;
    s.shiftMm = bestMm * dir;
    s.voxelsBefore = before;
    s.voxelsAfter = best;
    out.push_back(s);
  }
  return out;
}

}  // namespace repose
