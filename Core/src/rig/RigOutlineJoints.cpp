// The wrist and the ankle of a map without hand or foot bones (TotalSegmentator's `total` task
// labels no radius, ulna, hand, tibia, fibula or foot): fitted from the outline of the limb's
// part beyond the elbow or knee, which the rig's flood gave the whole forearm and hand, or shank
// and foot. Along that part's own axis (the forearm's bend at the elbow is the outline's, not the
// humerus's), the cross-section's area says where the joint is:
// - the wrist where the section is narrowest near 77 % of the humerus's length from the elbow
//   (the radius is 75-78 % of the humerus in adults), when the narrowing is clear (5 % below both
//   ends of a window of +-10 %); else there;
// - the ankle between the shank's narrowest section (above the malleoli) and the level where the
//   foot widens the section to 1.5 times that; without such a widening at 86 % of the
//   knee-to-sole length (the shank's share of shank and foot height).
// The part beyond the joint's plane becomes the hand or the foot (bone voxels keep their part).
#include "RigInternal.h"

#include <Eigen/Eigenvalues>

#include <algorithm>
#include <cmath>
#include <sstream>

namespace repose::rig {
namespace {

const FittedJoint* named(const std::vector<FittedJoint>& joints, const std::string& name) {
  for (const FittedJoint& j : joints)
    if (j.name == name) return &j;
  return nullptr;
}

struct Section {
  std::vector<std::int64_t> voxels;  // of the part
  V axis = V::UnitZ();               // from the proximal joint, along the part
  double length = 0, step = 1;       // extent along the axis from the joint, bin size (mm)
  std::vector<std::int64_t> count;   // voxels per bin along the axis
};

Section profile(const Volume& parts, int part, const V& from, const Grid& grid) {
  Section s;
  const std::uint8_t* p = parts.data<std::uint8_t>();
  for (std::int64_t i = 0; i < grid.count(); ++i)
    if (p[i] == part) s.voxels.push_back(i);
  if (s.voxels.size() < 64) return s;
  V c = V::Zero();
  for (const std::int64_t v : s.voxels) c += grid.ras(v);
  c /= double(s.voxels.size());
  Eigen::Matrix3d cov = Eigen::Matrix3d::Zero();
  for (const std::int64_t v : s.voxels) cov += (grid.ras(v) - c) * (grid.ras(v) - c).transpose();
  s.axis = Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d>(cov).eigenvectors().col(2).normalized();
  if (s.axis.dot(c - from) < 0) s.axis = -s.axis;
  s.step = std::max(2.0, s.axis.cwiseAbs().dot(grid.spacing));
  for (const std::int64_t v : s.voxels)
    s.length = std::max(s.length, (grid.ras(v) - from).dot(s.axis));
  s.count.assign(std::size_t(s.length / s.step) + 1, 0);
  for (const std::int64_t v : s.voxels) {
    const double t = (grid.ras(v) - from).dot(s.axis);
    if (t >= 0) ++s.count[std::min(s.count.size() - 1, std::size_t(t / s.step))];
  }
  return s;
}

std::size_t bin(const Section& s, double t) {
  return std::min(s.count.size() - 1, std::size_t(std::max(0.0, t) / s.step));
}

// Where the wrist lies along the forearm part (mm from the elbow), and how that was found. The
// length comes from the humerus, not from the part's outline: a hand resting on the thigh leaves
// its fingertips to the thigh's flood, and the part's length with them.
double wristAt(const Section& s, double humerusMm, std::string& how) {
  const double share = 0.77 * humerusMm, half = 0.1 * share;
  const std::size_t lo = bin(s, share - half), hi = bin(s, share + half);
  std::size_t least = lo;
  for (std::size_t b = lo; b <= hi; ++b)
    if (s.count[b] < s.count[least]) least = b;
  const bool clear = least > lo && least < hi &&
                     double(s.count[least]) <= 0.95 * double(std::min(s.count[lo], s.count[hi]));
  how = clear ? "the forearm's narrowest section near 77 % of the humerus's length from the elbow"
              : "77 % of the humerus's length from the elbow (the forearm's outline narrows "
                "nowhere clearly there)";
  return clear ? (double(least) + 0.5) * s.step : share;
}

// Where the ankle lies along the shank part (mm from the knee), and how that was found.
double ankleAt(const Section& s, std::string& how) {
  const std::size_t lo = bin(s, 0.5 * s.length), hi = bin(s, 0.92 * s.length);
  std::size_t narrow = lo;
  for (std::size_t b = lo; b <= hi; ++b)
    if (s.count[b] < s.count[narrow]) narrow = b;
  for (std::size_t b = narrow + 1; b < s.count.size(); ++b)
    if (double(s.count[b]) >= 1.5 * double(s.count[narrow])) {
      how = "between the shank's narrowest section and the foot's widening";
      return (0.5 * double(narrow + b) + 0.5) * s.step;
    }
  how = "86 % of the knee-to-sole length (the outline does not widen into a foot)";
  return 0.86 * s.length;
}

}  // namespace

void fitDistalJointsFromOutline(Volume& parts, const Volume& organs,
                                const LabelConvention& convention, const Bones& bones,
                                std::vector<FittedJoint>& joints, const Grid& grid,
                                std::vector<std::string>& missing) {
  std::vector<char> bone(65536, 0);
  for (const auto& [v, r] : convention.roles)
    if (v > 0 && v < 65536) bone[std::size_t(v)] = r.rigid;
  auto isBone = [&](std::int64_t i) {
    const double g = organs.valueAsDouble(i);
    return g > 0 && g < 65536 && bone[std::size_t(g)];
  };
  std::uint8_t* p = parts.data<std::uint8_t>();
  for (const int side : {-1, 1}) {
    const std::string sfx = side < 0 ? "_left" : "_right";
    for (const bool arm : {true, false}) {
      const std::string upper = (arm ? "elbow" : "knee") + sfx,
                        name = (arm ? "wrist" : "ankle") + sfx;
      const FittedJoint* above = named(joints, upper);
      if (!above || named(joints, name) || bones.find(arm ? BoneKind::Hand : BoneKind::Foot, side))
        continue;
      const int part = partOf(arm ? BoneKind::Forearm : BoneKind::Shank, side),
                beyond = partOf(arm ? BoneKind::Hand : BoneKind::Foot, side);
      const Section s = profile(parts, part, above->centre, grid);
      if (s.count.size() < 8) continue;
      std::string how;
      const Bone* humerus = bones.find(BoneKind::Humerus, side);
      if (arm && !humerus) continue;
      const double at = arm ? wristAt(s, humerus->length, how) : ankleAt(s, how);
      FittedJoint j;
      j.kind = arm ? JointKind::Wrist : JointKind::Ankle;
      j.name = name;
      j.side = side;
      j.parts = {part, beyond};
      V centre = V::Zero();
      int n = 0;
      for (const std::int64_t v : s.voxels)
        if (std::fabs((grid.ras(v) - above->centre).dot(s.axis) - at) <= 0.5 * s.step)
          centre += grid.ras(v), ++n;
      j.centre = n ? V(centre / n) : V(above->centre + at * s.axis);
      j.planeNormal = s.axis;
      j.distal = s.axis;
      for (const std::int64_t v : s.voxels)
        if ((grid.ras(v) - j.centre).dot(s.axis) > 0 && !isBone(v)) p[v] = std::uint8_t(beyond);
      if (!arm) {  // the foot's direction: its principal axis, heel to toes (forwards)
        V c = V::Zero();
        std::vector<V> foot;
        for (const std::int64_t v : s.voxels)
          if (p[v] == beyond) foot.push_back(grid.ras(v)), c += foot.back();
        if (foot.size() > 8) {
          c /= double(foot.size());
          Eigen::Matrix3d cov = Eigen::Matrix3d::Zero();
          for (const V& q : foot) cov += (q - c) * (q - c).transpose();
          V toes = Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d>(cov).eigenvectors().col(2);
          j.distal = toes.dot(bones.frame.anterior) >= 0 ? toes : V(-toes);
        }
      }
      std::ostringstream method;
      method << "outline: " << how << " (no " << (arm ? "hand" : "foot") << " bones labelled)";
      j.method = method.str();
      joints.push_back(j);
      missing.erase(
          std::remove_if(missing.begin(), missing.end(),
                         [&](const std::string& m) { return m.rfind(name + ":", 0) == 0; }),
          missing.end());
    }
  }
}

}  // namespace repose::rig
