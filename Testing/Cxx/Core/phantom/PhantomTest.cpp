// Properties of the synthetic phantom that tests and benchmarks rely on: labels present, parts
// covering the body, symmetry, bones in their segments, joints on the bone axes, the hand-hip gap
// or contact, slab independence and a lossless streamed write.
#include "TestPaths.h"

#include "repose/io/VolumeIO.h"
#include "repose/phantom/Phantom.h"
#include "repose/volume/DistanceTransform.h"
#include "repose/util/Error.h"

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <algorithm>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <map>
#include <set>

using namespace repose;

namespace {

using Maps = std::pair<Volume, Volume>;

// Generated once per configuration: the 2 mm phantom takes a fraction of a second, but many
// tests look at it.
const Maps& maps(double voxel, bool touching) {
  static std::map<std::pair<double, bool>, Maps> cache;
  auto it = cache.find({voxel, touching});
  if (it == cache.end()) {
    PhantomOptions o;
    o.voxelMm = voxel;
    o.armsTouching = touching;
    it = cache.emplace(std::make_pair(voxel, touching), Phantom(o).makeVolumes()).first;
  }
  return it->second;
}

int organValue(const std::string& name) {
  static const LabelTable table = Phantom().organLabels();
  for (const Label& l : table.labels())
    if (l.name == name) return l.value;
  ADD_FAILURE() << "no organ label " << name;
  return -1;
}

std::map<int, std::int64_t> histogram(const Volume& v) {
  std::map<int, std::int64_t> h;
  const auto* d = v.data<std::uint8_t>();
  for (std::int64_t i = 0; i < v.numVoxels(); ++i) ++h[d[i]];
  return h;
}

bool isHand(int part) {
  return part == kPartHandLeft || part == kPartHandRight;
}
bool isTorsoOrThigh(int part) {
  return part == kPartTorso || part == kPartThighLeft || part == kPartThighRight;
}

// Face-adjacent (hand voxel, torso-or-thigh voxel) pairs, per side (0 left, 1 right).
std::array<int, 2> handContacts(const Volume& s) {
  std::array<int, 2> contacts{0, 0};
  const auto& d = s.dims();
  const auto* p = s.data<std::uint8_t>();
  const std::int64_t step[3] = {1, d[0], d[0] * d[1]};
  for (std::int64_t k = 1; k + 1 < d[2]; ++k)
    for (std::int64_t j = 1; j + 1 < d[1]; ++j)
      for (std::int64_t i = 1; i + 1 < d[0]; ++i) {
        const std::int64_t at = s.index(i, j, k);
        if (!isHand(p[at])) continue;
        for (std::int64_t st : step)
          for (std::int64_t n : {at - st, at + st})
            if (isTorsoOrThigh(p[n])) ++contacts[p[at] == kPartHandRight];
      }
  return contacts;
}

double distanceToSegment(const Eigen::Vector3d& p, const Eigen::Vector3d& a,
                         const Eigen::Vector3d& b) {
  const double t = std::clamp((p - a).dot(b - a) / (b - a).squaredNorm(), 0.0, 1.0);
  return (p - (a + t * (b - a))).norm();
}

}  // namespace

TEST(Phantom, HasAllOrganLabelsAt2mm) {
  const Maps& m = maps(2, false);
  const auto h = histogram(m.first);
  const LabelTable table = Phantom().organLabels();
  int present = 0;
  for (const auto& [value, count] : h) {
    if (value == 0) continue;
    ++present;
    const Label* l = table.find(value);
    ASSERT_NE(l, nullptr) << "label " << value << " has no name";
    EXPECT_FALSE(l->name.empty());
  }
  EXPECT_GE(present, 15);
  EXPECT_EQ(present, static_cast<int>(table.size()));  // every documented label shows up
  for (const char* name : {"skin", "subcutaneous_fat", "muscle", "brain", "lung_left", "lung_right",
                           "heart", "liver", "kidney_left", "kidney_right"})
    EXPECT_GT(h.count(organValue(name)), 0u) << name;
}

TEST(Phantom, PartsCoverExactlyTheBody) {
  const Maps& m = maps(2, false);
  const auto* g = m.first.data<std::uint8_t>();
  const auto* s = m.second.data<std::uint8_t>();
  std::int64_t mismatch = 0, body = 0;
  std::set<int> parts;
  for (std::int64_t i = 0; i < m.first.numVoxels(); ++i) {
    mismatch += (g[i] != 0) != (s[i] != 0);
    body += g[i] != 0;
    parts.insert(s[i]);
  }
  EXPECT_EQ(mismatch, 0);
  EXPECT_EQ(parts.size(), 15u);  // background and the 14 parts
  EXPECT_EQ(*parts.rbegin(), kPartFootRight);
  // A 1.3 m child of about 26 litres, not a stick figure or a blob.
  EXPECT_NEAR(body * 8e-6, 26.0, 5.0);
}

TEST(Phantom, SkinIsTheOutermostLayerAndFatLiesUnderIt) {
  for (double voxel : {2.0, 4.0}) {
    const Maps& m = maps(voxel, false);
    const auto& d = m.first.dims();
    const auto* g = m.first.data<std::uint8_t>();
    std::int64_t boundary = 0, notSkin = 0;
    for (std::int64_t k = 1; k + 1 < d[2]; ++k)
      for (std::int64_t j = 1; j + 1 < d[1]; ++j)
        for (std::int64_t i = 1; i + 1 < d[0]; ++i) {
          const std::int64_t at = m.first.index(i, j, k);
          if (!g[at]) continue;
          const bool outside = !g[at - 1] || !g[at + 1] || !g[at - d[0]] || !g[at + d[0]] ||
                               !g[at - d[0] * d[1]] || !g[at + d[0] * d[1]];
          if (!outside) continue;
          ++boundary;
          notSkin += g[at] != organValue("skin");
        }
    EXPECT_GT(boundary, 1000);
    EXPECT_EQ(notSkin, 0) << "at " << voxel << " mm";
  }
}

TEST(Phantom, LeftAndRightAreMirrorImages) {
  const Maps& m = maps(2, false);
  const auto* g = m.first.data<std::uint8_t>();
  const auto* s = m.second.data<std::uint8_t>();
  std::map<std::pair<int, int>, std::int64_t> count;  // (organ, part) -> voxels
  for (std::int64_t i = 0; i < m.first.numVoxels(); ++i) ++count[{g[i], s[i]}];
  const std::pair<int, int> pairs[] = {
      {kPartUpperArmLeft, kPartUpperArmRight}, {kPartForearmLeft, kPartForearmRight},
      {kPartHandLeft, kPartHandRight},         {kPartThighLeft, kPartThighRight},
      {kPartShankLeft, kPartShankRight},       {kPartFootLeft, kPartFootRight}};
  for (const char* organ : {"skin", "muscle", "humerus", "radius_ulna", "hand_bones", "femur",
                            "tibia_fibula", "foot_bones"}) {
    for (const auto& [left, right] : pairs) {
      const double l = count[{organValue(organ), left}], r = count[{organValue(organ), right}];
      EXPECT_NEAR(l, r, 0.02 * std::max(l, r) + 2) << organ << " in parts " << left << "/" << right;
    }
  }
  // The grid itself is centred so that mirroring i maps the body onto itself.
  const auto& d = m.first.dims();
  std::int64_t differ = 0, body = 0;
  for (std::int64_t k = 0; k < d[2]; ++k)
    for (std::int64_t j = 0; j < d[1]; ++j)
      for (std::int64_t i = 0; i < d[0]; ++i) {
        const bool a = g[m.first.index(i, j, k)] != 0,
                   b = g[m.first.index(d[0] - 1 - i, j, k)] != 0;
        differ += a != b;
        body += a;
      }
  EXPECT_LT(differ, body / 1000);
}

TEST(Phantom, BonesAndOrgansLieInTheirOwnPart) {
  const Maps& m = maps(2, false);
  const auto* g = m.first.data<std::uint8_t>();
  const auto* s = m.second.data<std::uint8_t>();
  const std::map<std::string, std::set<int>> allowed = {
      {"humerus", {kPartUpperArmLeft, kPartUpperArmRight}},
      {"radius_ulna", {kPartForearmLeft, kPartForearmRight}},
      {"hand_bones", {kPartHandLeft, kPartHandRight}},
      {"femur", {kPartThighLeft, kPartThighRight}},
      {"tibia_fibula", {kPartShankLeft, kPartShankRight}},
      {"foot_bones", {kPartFootLeft, kPartFootRight}},
      {"brain", {kPartHead}},
      {"skull", {kPartHead}},
      {"eye", {kPartHead}},
      {"heart", {kPartTorso}},
      {"liver", {kPartTorso}},
      {"lung_left", {kPartTorso}},
      {"pelvis", {kPartTorso}},
      {"vertebrae", {kPartTorso}}};
  std::map<int, const std::set<int>*> byValue;
  for (const auto& [name, parts] : allowed) byValue[organValue(name)] = &parts;
  std::map<int, std::int64_t> wrong, seen;
  for (std::int64_t i = 0; i < m.first.numVoxels(); ++i) {
    auto it = byValue.find(g[i]);
    if (it == byValue.end()) continue;
    ++seen[g[i]];
    wrong[g[i]] += !it->second->count(s[i]);
  }
  for (const auto& [value, parts] : byValue) {
    EXPECT_GT(seen[value], 0) << value;
    EXPECT_EQ(wrong[value], 0) << "label " << value;
  }
  // Left organs at negative x (RAS): the heart leans left, the liver right.
  auto meanX = [&](int value) {
    double sum = 0, n = 0;
    const auto& d = m.first.dims();
    for (std::int64_t k = 0; k < d[2]; ++k)
      for (std::int64_t j = 0; j < d[1]; ++j)
        for (std::int64_t i = 0; i < d[0]; ++i)
          if (g[m.first.index(i, j, k)] == value)
            sum += m.first.geometry().voxelToRas(i, j, k).x(), ++n;
    return sum / n;
  };
  EXPECT_LT(meanX(organValue("heart")), 0);
  EXPECT_LT(meanX(organValue("lung_left")), 0);
  EXPECT_GT(meanX(organValue("liver")), 0);
  EXPECT_LT(meanX(organValue("spleen")), 0);
}

TEST(Phantom, JointsFormASkeletonInsideTheBody) {
  const Phantom p;
  std::set<std::string> names;
  for (const Joint& j : p.joints()) names.insert(j.name);
  for (const char* n : {"pelvis", "spine", "chest", "neck", "head_top"})
    EXPECT_TRUE(names.count(n)) << n;
  for (const char* base : {"shoulder", "elbow", "wrist", "hand_tip", "hip", "knee", "ankle", "toe"})
    for (const char* side : {"_left", "_right"}) EXPECT_TRUE(names.count(std::string(base) + side));
  for (const Joint& j : p.joints()) {
    if (j.name == "pelvis")
      EXPECT_TRUE(j.parent.empty());
    else
      EXPECT_TRUE(names.count(j.parent)) << j.name << " -> " << j.parent;
    const bool tip =
        j.name == "head_top" || j.name.rfind("hand_tip", 0) == 0 || j.name.rfind("toe", 0) == 0;
    std::uint8_t organ = 0, part = 0;
    // End effectors sit on the skin; look just inside along the way back to their parent.
    const Eigen::Vector3d at =
        tip ? Eigen::Vector3d(j.ras + 3 * (p.joint(j.parent).ras - j.ras).normalized()) : j.ras;
    p.classify(at, organ, part);
    EXPECT_NE(organ, 0) << j.name;
  }
  EXPECT_LT(p.joint("shoulder_left").ras.x(), 0);  // patient's left is -x in RAS
  EXPECT_GT(p.joint("shoulder_right").ras.x(), 0);
  EXPECT_GT(p.joint("head_top").ras.z(), p.joint("toe_left").ras.z() + 1200);
  EXPECT_THROW(p.joint("tail"), Error);
  for (const char* side : {"_left", "_right"}) {
    const Eigen::Vector3d s = p.joint(std::string("shoulder") + side).ras,
                          e = p.joint(std::string("elbow") + side).ras,
                          w = p.joint(std::string("wrist") + side).ras;
    const double t = (e - s).dot(w - s) / (w - s).squaredNorm();
    EXPECT_GT(t, 0.2);
    EXPECT_LT(t, 0.8);
    EXPECT_LT(distanceToSegment(e, s, w), 0.1 * (w - s).norm());
  }
}

TEST(Phantom, LimbBonesRunAlongTheirJoints) {
  // Posing rotates a segment about its proximal joint: that only moves the bone rigidly with
  // its segment if the bone axis joins the two joints.
  const Phantom p({2.0});
  const Maps& m = maps(2, false);
  const auto* g = m.first.data<std::uint8_t>();
  const auto* s = m.second.data<std::uint8_t>();
  struct Bone {
    const char* organ;
    const char* from;
    const char* to;
    int leftPart;
    double reachMm;  // the bone's radius plus a voxel, or its condyles' half-width across the
                     // flexion axis plus a voxel
  };
  const Bone bones[] = {{"humerus", "shoulder", "elbow", kPartUpperArmLeft, 12 + 10 + 2},
                        {"radius_ulna", "elbow", "wrist", kPartForearmLeft, 10 + 2},
                        {"femur", "hip", "knee", kPartThighLeft, 16 + 12 + 2},
                        {"tibia_fibula", "knee", "ankle", kPartShankLeft, 13 + 2}};
  const auto& d = m.first.dims();
  for (const Bone& b : bones) {
    const int value = organValue(b.organ);
    double worst = 0;
    for (std::int64_t k = 0; k < d[2]; ++k)
      for (std::int64_t j = 0; j < d[1]; ++j)
        for (std::int64_t i = 0; i < d[0]; ++i) {
          const std::int64_t at = m.first.index(i, j, k);
          if (g[at] != value) continue;
          const std::string side = s[at] == b.leftPart ? "_left" : "_right";
          worst = std::max(worst,
                           distanceToSegment(m.first.geometry().voxelToRas(i, j, k),
                                             p.joint(b.from + side).ras, p.joint(b.to + side).ras));
        }
    EXPECT_LT(worst, b.reachMm) << b.organ;
  }
}

TEST(Phantom, HandsClearOfTheHipsByDefaultAndPressedAgainstThemWhenTouching) {
  const Maps& apart = maps(2, false);
  EXPECT_EQ(handContacts(apart.second)[0], 0);
  EXPECT_EQ(handContacts(apart.second)[1], 0);
  // A clear gap, not a hairline: no torso or thigh voxel within two voxels of a hand voxel.
  const auto& d = apart.second.dims();
  const auto* s = apart.second.data<std::uint8_t>();
  int near = 0;
  for (std::int64_t k = 2; k + 2 < d[2]; ++k)
    for (std::int64_t j = 2; j + 2 < d[1]; ++j)
      for (std::int64_t i = 2; i + 2 < d[0]; ++i) {
        if (!isHand(s[apart.second.index(i, j, k)])) continue;
        for (int dk = -2; dk <= 2; ++dk)
          for (int dj = -2; dj <= 2; ++dj)
            for (int di = -2; di <= 2; ++di)
              near += isTorsoOrThigh(s[apart.second.index(i + di, j + dj, k + dk)]);
      }
  EXPECT_EQ(near, 0);

  for (double voxel : {2.0, 4.0}) {
    const auto contacts = handContacts(maps(voxel, true).second);
    EXPECT_GE(contacts[0], 4) << voxel << " mm";  // a patch, not a single touching voxel
    EXPECT_GE(contacts[1], 4) << voxel << " mm";
    EXPECT_NEAR(contacts[0], contacts[1], 0.1 * contacts[0] + 2);
  }
}

// The gap variant (`repose phantom --arms-resting --gap-mm HAND,FOREARM`): the near contacts of
// real reference phantoms. Measured on the voxels, on an isotropic grid and on thick slices: no
// hand voxel touches a thigh or the trunk, the nearest hand and thigh voxel centres lie the hand's
// gap apart (within two voxels beyond it), and the forearm beyond its elbow end keeps its gap from
// the trunk and hips; the upper arm still rests on the chest wall.
TEST(Phantom, TheGapVariantHoldsHandsAndForearmsOffTheBodyByTheirGaps) {
  for (const Eigen::Vector3d& spacing :
       {Eigen::Vector3d(2, 2, 2), Eigen::Vector3d(1.8, 1.8, 4.8)}) {
    PhantomOptions o;
    o.spacingMm = spacing;
    o.armsResting = true;
    o.handGapMm = 4;
    o.forearmGapMm = 15;
    const Phantom phantom(o);
    const auto [G, S] = phantom.makeVolumes();
    const auto& d = S.dims();
    const auto* s = S.data<std::uint8_t>();
    const std::size_t n = std::size_t(S.numVoxels());
    auto distanceTo = [&](auto pick) {
      std::vector<std::uint8_t> mask(n);
      for (std::size_t i = 0; i < n; ++i) mask[i] = pick(int(s[i]));
      return squaredDistanceToMask(mask, d, spacing);
    };
    const std::vector<float> toThigh =
        distanceTo([](int p) { return p == kPartThighLeft || p == kPartThighRight; });
    const std::vector<float> toTrunkOrThigh = distanceTo(isTorsoOrThigh);
    const std::vector<float> toTorso = distanceTo([](int p) { return p == kPartTorso; });
    for (const bool left : {true, false}) {
      const std::string side = left ? "_left" : "_right";
      const int hand = left ? kPartHandLeft : kPartHandRight;
      const int forearm = left ? kPartForearmLeft : kPartForearmRight;
      const int upper = left ? kPartUpperArmLeft : kPartUpperArmRight;
      const Eigen::Vector3d elbow = phantom.joint("elbow" + side).ras;
      const Eigen::Vector3d wrist = phantom.joint("wrist" + side).ras;
      double handThigh = 1e300, handBody = 1e300, forearmBody = 1e300, upperTorso = 1e300;
      for (std::size_t i = 0; i < n; ++i) {
        if (s[i] == hand) {
          handThigh = std::min(handThigh, std::sqrt(double(toThigh[i])));
          handBody = std::min(handBody, std::sqrt(double(toTrunkOrThigh[i])));
        } else if (s[i] == forearm) {
          const Eigen::Vector3d p = S.geometry().voxelToRas(
              double(std::int64_t(i) % d[0]), double((std::int64_t(i) / d[0]) % d[1]),
              double(std::int64_t(i) / (d[0] * d[1])));
          if ((p - elbow).dot(wrist - elbow) > 0.15 * (wrist - elbow).squaredNorm())
            forearmBody = std::min(forearmBody, std::sqrt(double(toTrunkOrThigh[i])));
        } else if (s[i] == upper) {
          upperTorso = std::min(upperTorso, std::sqrt(double(toTorso[i])));
        }
      }
      const double voxel = spacing.maxCoeff();
      EXPECT_GE(handThigh, 4.0) << side << " " << spacing.transpose();
      EXPECT_LE(handThigh, 4.0 + 2 * voxel) << side << " " << spacing.transpose();
      EXPECT_GE(handBody, 4.0) << side;
      EXPECT_GE(forearmBody, 15.0 - 1e-9) << side << " " << spacing.transpose();
      EXPECT_LE(forearmBody, 15.0 + 2 * voxel + 6) << side << " " << spacing.transpose();
      EXPECT_LE(upperTorso, 1.05 * spacing.minCoeff()) << side;  // touching
    }
  }
  PhantomOptions bad;
  bad.handGapMm = 3;
  EXPECT_THROW(Phantom{bad}, Error);  // gaps belong to the arms-resting posture
}

// The thin-vessel variant (PhantomOptions::limbVesselMm, issue 64): each limb's artery one or two
// voxels across, as on a reference phantom's grid, and still one unbroken vessel from the trunk to
// the ankle and the wrist: on every slice between the hip and the knee, and between the shoulder
// and the elbow, each side holds a voxel of it. A tube of diameter D covers a voxel centre on
// every cross-section when D >= sqrt(3) voxels: 3.5 mm on 2 mm voxels. The anatomical vessels
// hold more voxels (the legs' three times as many or more). Near the shoulder the artery runs in
// the girdle and takes the trunk's vessel label, so the upper arm is checked from 60 mm below it.
TEST(Phantom, TheThinVesselVariantRunsOneVoxelVesselsThroughTheLimbs) {
  auto vessels = [](double mm) {
    PhantomOptions o;
    o.armsResting = true;
    o.handGapMm = 4;
    o.limbVesselMm = mm;
    return Phantom(o);
  };
  const Phantom thin = vessels(3.5), anatomical = vessels(0);
  const auto [G, S] = thin.makeVolumes();
  const auto [G0, S0] = anatomical.makeVolumes();
  auto count = [](const Volume& g, int label) {
    std::int64_t n = 0;
    for (std::int64_t v = 0; v < g.numVoxels(); ++v) n += g.data<std::uint8_t>()[v] == label;
    return n;
  };
  auto valueOf = [&](const std::string& name) {
    for (const Label& l : G.labels().labels())
      if (l.name == name) return l.value;
    ADD_FAILURE() << "no label " << name;
    return -1;
  };
  const int legs = valueOf("blood_vessels_legs"), arms = valueOf("blood_vessels_arms");
  for (const int label : {legs, arms}) {
    const std::int64_t n = count(G, label), n0 = count(G0, label);
    EXPECT_GT(n, 0) << label;
    EXPECT_LT((label == legs ? 3 : 1) * n, n0)
        << label << ": " << n << " voxels, anatomical " << n0;
  }
  const Skeleton sk = thin.skeleton();
  auto jointZ = [&](const std::string& name) {
    for (const auto& j : sk.joints)
      if (j.name == name) return j.centre.z();
    ADD_FAILURE() << "no joint " << name;
    return 0.0;
  };
  const auto& d = G.dims();
  for (const std::string side : {"_left", "_right"})
    for (const auto& [from, to, label] :
         {std::tuple{"hip", "knee", legs}, std::tuple{"shoulder", "elbow", arms}}) {
      const double z0 = jointZ(to + side) + 20,
                   z1 = jointZ(from + side) - (label == arms ? 60 : 20);
      const double sideX = side == "_left" ? 1 : -1;
      for (std::int64_t k = 0; k < d[2]; ++k) {
        const double z = G.geometry().voxelToRas(0, 0, double(k)).z();
        if (z < z0 || z > z1) continue;
        bool found = false;
        for (std::int64_t j = 0; j < d[1] && !found; ++j)
          for (std::int64_t i = 0; i < d[0] && !found; ++i)
            found = G.data<std::uint8_t>()[G.index(i, j, k)] == label &&
                    G.geometry().voxelToRas(double(i), double(j), double(k)).x() * sideX > 0;
        EXPECT_TRUE(found) << from << side << " to " << to << side << ": no vessel at z " << z;
      }
    }
  PhantomOptions bad;
  bad.limbVesselMm = 2;
  EXPECT_THROW(Phantom{bad}, Error);  // the vessels belong to the arms-resting posture
  bad.armsResting = true;
  bad.limbVesselMm = -1;
  EXPECT_THROW(Phantom{bad}, Error);
}

TEST(Phantom, SlabsAndPointsAgreeWithTheWholeVolume) {
  PhantomOptions o;
  o.voxelMm = 4;
  o.armsTouching = true;
  o.threads = 1;
  const Phantom p(o);
  const Maps& whole = maps(4, true);
  const auto& d = p.geometry().dims;
  ASSERT_EQ(d, whole.first.dims());
  const std::int64_t slice = d[0] * d[1];
  std::vector<std::uint8_t> g(slice * 7), s(slice * 7);
  for (std::int64_t k = 0; k < d[2]; k += 7) {
    const std::int64_t n = std::min<std::int64_t>(7, d[2] - k);
    p.fillSlices(k, k + n, g.data(), s.data());
    ASSERT_EQ(0, std::memcmp(g.data(), whole.first.data<std::uint8_t>() + k * slice, n * slice));
    ASSERT_EQ(0, std::memcmp(s.data(), whole.second.data<std::uint8_t>() + k * slice, n * slice));
  }
  EXPECT_THROW(p.fillSlices(d[2] - 1, d[2] + 1, g.data(), s.data()), Error);
  // classify() at voxel centres is the same function.
  const double v = o.voxelMm;
  const Eigen::Vector3d origin = p.geometry().origin();
  int checked = 0;
  for (std::int64_t at = 0; at < whole.first.numVoxels(); at += 997) {
    const std::int64_t i = at % d[0], j = (at / d[0]) % d[1], k = at / slice;
    std::uint8_t organ = 9, part = 9;
    p.classify(origin + Eigen::Vector3d(i * v, j * v, k * v), organ, part);
    EXPECT_EQ(organ, whole.first.data<std::uint8_t>()[at]);
    EXPECT_EQ(part, whole.second.data<std::uint8_t>()[at]);
    checked += organ != 0;
  }
  EXPECT_GT(checked, 50);
}

TEST(Phantom, GridIsAxisAlignedRasWithTheMarginLeftFree) {
  PhantomOptions o;
  o.voxelMm = 4;
  o.marginMm = 20;
  const Phantom p(o);
  const VolumeGeometry& g = p.geometry();
  EXPECT_EQ(g.axisCodes(), "RAS");
  const Eigen::Matrix3d linear = g.ijkToRas.block<3, 3>(0, 0);
  EXPECT_TRUE(linear.isApprox(4 * Eigen::Matrix3d::Identity()));
  const Maps m = p.makeVolumes();
  const auto& d = g.dims;
  const std::int64_t border = static_cast<std::int64_t>(o.marginMm / o.voxelMm) - 1;
  const auto* s = m.second.data<std::uint8_t>();
  std::int64_t bodyInBorder = 0;
  for (std::int64_t k = 0; k < d[2]; ++k)
    for (std::int64_t j = 0; j < d[1]; ++j)
      for (std::int64_t i = 0; i < d[0]; ++i) {
        const bool inBorder = i < border || j < border || k < border || i >= d[0] - border ||
                              j >= d[1] - border || k >= d[2] - border;
        bodyInBorder += inBorder && s[m.second.index(i, j, k)];
      }
  EXPECT_EQ(bodyInBorder, 0);
  EXPECT_THROW(Phantom(PhantomOptions{0.0}), Error);
  EXPECT_THROW(Phantom(PhantomOptions{-1.0}), Error);
}

TEST(Phantom, WritesFilesThatReadBackIdentically) {
  test::ScratchDir dir;
  PhantomOptions o;
  o.voxelMm = 6;
  const Phantom p(o);
  const Maps m = p.makeVolumes();
  int calls = 0;
  const PhantomFiles files =
      writePhantom(p, dir.path().string(), ".nii.gz", [&](double, const std::string& stage) {
        EXPECT_EQ(stage, "phantom");
        ++calls;
        return true;
      });
  EXPECT_GE(calls, 2);
  for (const auto& [path, expected] :
       {std::make_pair(files.organs, &m.first), std::make_pair(files.parts, &m.second)}) {
    const Volume back = readVolume(path);
    ASSERT_EQ(back.dims(), expected->dims()) << path;
    EXPECT_TRUE(back.geometry().ijkToRas.isApprox(expected->geometry().ijkToRas, 1e-6)) << path;
    EXPECT_TRUE(back.isLabelMap());
    ASSERT_EQ(back.scalarType(), ScalarType::UInt8);
    EXPECT_EQ(back.bytes(), expected->bytes()) << path;
    for (const Label& l : expected->labels().labels()) {
      const Label* found = back.labels().find(l.value);
      ASSERT_NE(found, nullptr) << l.name;
      EXPECT_EQ(found->name, l.name);
    }
  }
  std::ifstream in(files.skeleton);
  const auto j = nlohmann::json::parse(in);
  EXPECT_EQ(j["space"], "RAS");
  EXPECT_EQ(j["units"], "mm");
  ASSERT_EQ(j["joints"].size(), p.joints().size());
  EXPECT_EQ(j["joints"][0]["name"], p.joints()[0].name);
  EXPECT_NEAR(j["joints"][5]["ras"][2].get<double>(), p.joints()[5].ras.z(), 1e-9);
  // Only the three outputs: no temporary folders left behind.
  EXPECT_EQ(std::distance(std::filesystem::directory_iterator(dir.path()), {}), 3);
}

// The CT-like image: streamed slab by slab it is the image of the whole G (the noise depends on
// the voxel index only), each tissue within the noise of its value, air exactly -1000, and
// lung darker than fat darker than soft tissue darker than bone.
TEST(Phantom, WritesASyntheticCTOfG) {
  test::ScratchDir dir;
  PhantomOptions o;
  o.voxelMm = 6;
  const Phantom p(o);
  const Maps m = p.makeVolumes();
  const PhantomFiles files = writePhantom(p, dir.path().string(), ".nii.gz", {}, "x_", true);
  EXPECT_EQ(files.image, dir.file("x_CT.nii.gz"));
  const Volume ct = readVolume(files.image);
  ASSERT_EQ(ct.scalarType(), ScalarType::Int16);
  EXPECT_FALSE(ct.isLabelMap());
  EXPECT_TRUE(ct.geometry().ijkToRas.isApprox(m.first.geometry().ijkToRas, 1e-6));
  const Volume whole = syntheticCT(m.first);
  ASSERT_EQ(ct.bytes(), whole.bytes());
  const auto* g = m.first.data<std::uint8_t>();
  const auto* hu = ct.data<std::int16_t>();
  for (std::int64_t v = 0; v < ct.numVoxels(); ++v) {
    if (g[v] == 0) {
      ASSERT_EQ(hu[v], -1000) << v;
    } else {
      ASSERT_LE(std::abs(hu[v] - phantomHounsfield(g[v])), 12) << v;
    }
  }
  const LabelTable organLabels = p.organLabels();  // kept: labels() refers into it
  auto value = [&](const std::string& name) {
    for (const Label& l : organLabels.labels())
      if (l.name == name) return phantomHounsfield(l.value);
    ADD_FAILURE() << name;
    return std::int16_t(0);
  };
  EXPECT_LT(value("lung_left"), value("subcutaneous_fat"));
  EXPECT_LT(value("subcutaneous_fat"), value("muscle"));
  EXPECT_LT(value("muscle"), value("femur"));
  EXPECT_EQ(std::distance(std::filesystem::directory_iterator(dir.path()), {}), 4);
}

TEST(Phantom, CancelledOrFailedWritesLeaveNothing) {
  test::ScratchDir dir;
  const Phantom p(PhantomOptions{6.0});
  int calls = 0;
  EXPECT_THROW(writePhantom(p, dir.path().string(), ".nii",
                            [&](double, const std::string&) { return ++calls < 2; }),
               Cancelled);
  EXPECT_THROW(writePhantom(p, dir.path().string(), ".nrrd"), Error);
  EXPECT_THROW(writePhantom(p, dir.file("missing"), ".nii"), Error);
  EXPECT_EQ(std::distance(std::filesystem::directory_iterator(dir.path()), {}), 0);
}
