// Dimensions of the mannequin: a standing child of about 1.30 m (soles at z = 0, RAS mm), built
// from the skeleton outwards so every limb primitive and bone runs through its joints.
#include "PhantomBody.h"

#include "PhantomLabels.h"

#include "repose/util/Error.h"

#include <Eigen/Geometry>

#include <cmath>
#include <map>

namespace repose::phantom {

using V = Eigen::Vector3d;

bool Structure::contains(const V& p, double depth) const {
  if (p.z() < zmin || p.z() > zmax) return false;
  switch (kind) {
    case StructureKind::Cone:
      return cone.inside(p);
    case StructureKind::Ellipsoid:
      return outer.inside(p);
    case StructureKind::Shell:
      return outer.inside(p) && !(p.z() >= innerZmin && inner.inside(p));
    case StructureKind::Ribs: {
      if (depth < depthMin || depth > depthMax || std::fabs(p.x()) < gapX) return false;
      // Ribs slope down towards the front: the phase follows z + slope * y.
      const double phase = std::fmod(p.z() + slope * p.y() - zmin + 10 * period, period);
      return phase < thickness;
    }
  }
  return false;
}

namespace {

V mirror(const V& p) {
  return {-p.x(), p.y(), p.z()};
}

// Right-side (+x) joint positions of the default pose; the left side is their mirror image.
struct SideJoints {
  V shoulder{148, 0, 1030}, elbow{176, -14, 806}, wrist{194, 4, 602}, handTip{202, 14, 454};
  V hip{74, 0, 700}, knee{72, 6, 385}, ankle{70, 0, 76}, toe{70, 145, 20};
};

struct Builder {
  BodyModel m;

  void segment(std::uint8_t part, const RoundCone& c) {
    Segment s;
    s.shape = c;
    s.part = part;
    m.segments.push_back(s);
  }
  // The segment claims voxels only on the `keep` side of the plane through `joint`.
  void cutSegment(std::uint8_t part, const RoundCone& c, const V& joint, const V& keep,
                  std::uint8_t beyond) {
    segment(part, c);
    m.segments.back().cut = true;
    m.segments.back().cutOwner = beyond;
    m.segments.back().cutPoint = joint;
    m.segments.back().cutNormal = keep;
  }
  Structure& structure(StructureKind kind, std::uint8_t label, std::uint8_t part) {
    Structure s;
    s.kind = kind;
    s.label = label;
    s.part = part;
    m.structures.push_back(s);
    return m.structures.back();
  }
  void cone(std::uint8_t label, std::uint8_t part, const RoundCone& c) {
    structure(StructureKind::Cone, label, part).cone = c;
  }
  void ellipsoid(std::uint8_t label, std::uint8_t part, const V& c, const V& r,
                 double zmin = -1e300) {
    Structure& s = structure(StructureKind::Ellipsoid, label, part);
    s.outer = {c, r};
    s.zmin = zmin;
  }
  void joint(const std::string& name, const std::string& parent, const V& ras) {
    m.joints.push_back({name, parent, ras});
  }
  // Distance to the body assembled so far, restricted to some parts.
  double distanceTo(const V& p, std::initializer_list<std::uint8_t> parts) const {
    double d = 1e300;
    for (const Segment& s : m.segments)
      for (auto part : parts)
        if (s.part == part) d = std::min(d, s.shape.distance(p));
    return d;
  }
};

RoundCone hand(const V& wrist, const V& tip, const V& across, double shrink) {
  const V u = (tip - wrist).normalized();
  return RoundCone::make(wrist + 8 * u, tip - 22 * u, 24 * shrink, 22 * shrink, across, 0.5, 1);
}

// Rotates the arm below the shoulder about the antero-posterior axis until the palm presses
// `press` mm into the thigh or hip: the hands-on-hips case for limb separation.
void pressArmToHip(SideJoints& j, V& across, const Builder& b, double press) {
  auto rotated = [&](double angle, const V& p) {
    return V(j.shoulder + Eigen::AngleAxisd(angle, V::UnitY()) * (p - j.shoulder));
  };
  auto penetration = [&](double angle) {
    const V w = rotated(angle, j.wrist), t = rotated(angle, j.handTip);
    const V ac = Eigen::AngleAxisd(angle, V::UnitY()) * across;
    const RoundCone h = hand(w, t, ac, 1.0);
    const V palm = h.a + 0.5 * h.len * h.u - h.e1 * (0.5 * (h.r1 + h.r2) * h.s1);
    return -b.distanceTo(palm, {kPartTorso, kPartThighRight});
  };
  // Walk inwards to the first contact, then refine: further in, the hand would cross the body.
  double lo = 0, hi = 0;
  while (penetration(hi) < press) {
    lo = hi;
    hi += 0.01;
    if (hi > 0.5) throw Error("phantom: the arms cannot reach the hips");
  }
  for (int it = 0; it < 60; ++it) {
    const double mid = 0.5 * (lo + hi);
    (penetration(mid) < press ? lo : hi) = mid;
  }
  j.elbow = rotated(hi, j.elbow);
  j.wrist = rotated(hi, j.wrist);
  j.handTip = rotated(hi, j.handTip);
  across = Eigen::AngleAxisd(hi, V::UnitY()) * across;
}

void addTorsoAndHead(Builder& b) {
  const V Y = V::UnitY(), X = V::UnitX();
  b.segment(kPartTorso, RoundCone::make({0, 0, 775}, {0, 0, 885}, 114, 106, Y, 0.7, 1));
  b.segment(kPartTorso, RoundCone::make({0, 0, 885}, {0, 0, 945}, 106, 110, Y, 0.76, 1));
  for (double side : {1.0, -1.0})  // shoulder girdle: trapezius and clavicle line
    b.segment(kPartTorso,
              RoundCone::make({side * 40, -5, 1040}, {side * 148, 0, 1030}, 50, 42, Y, 0.8, 1));
  b.segment(kPartTorso, RoundCone::make({0, 0, 1045}, {0, 0, 1140}, 44, 40));
  b.segment(kPartHead, RoundCone::make({0, 20, 1162}, {0, -5, 1212}, 58, 88, X, 0.85, 1));
}

void addArm(Builder& b, const SideJoints& j, const V& across, bool left) {
  auto P = [&](const V& p) { return left ? mirror(p) : p; };
  const V ac = left ? mirror(across) : across;
  const std::uint8_t upper = left ? kPartUpperArmLeft : kPartUpperArmRight;
  const std::uint8_t fore = left ? kPartForearmLeft : kPartForearmRight;
  const std::uint8_t handPart = left ? kPartHandLeft : kPartHandRight;
  const V s = P(j.shoulder), e = P(j.elbow), w = P(j.wrist), t = P(j.handTip);
  const V uu = (e - s).normalized(), uf = (w - e).normalized(), uh = (t - w).normalized();
  b.cutSegment(upper, RoundCone::make(s, e, 40, 31), s, uu, kPartTorso);
  b.segment(fore, RoundCone::make(e, w, 31, 22));
  b.segment(handPart, hand(w, t, ac, 1.0));
  b.cone(kHumerus, upper, RoundCone::make(s + 4 * uu, e - 4 * uu, 11, 10));
  b.cone(kRadiusUlna, fore, RoundCone::make(e + 5 * uf, w - 4 * uf, 10, 9, ac, 1, 0.9));
  b.cone(kHandBones, handPart, RoundCone::make(w + 5 * uh, t - 12 * uh, 10, 6, ac, 0.55, 1));
}

void addLeg(Builder& b, const SideJoints& j, bool left) {
  auto P = [&](const V& p) { return left ? mirror(p) : p; };
  const std::uint8_t thigh = left ? kPartThighLeft : kPartThighRight;
  const std::uint8_t shank = left ? kPartShankLeft : kPartShankRight;
  const std::uint8_t foot = left ? kPartFootLeft : kPartFootRight;
  const V h = P(j.hip), k = P(j.knee), a = P(j.ankle), t = P(j.toe);
  const V ut = (k - h).normalized(), us = (a - k).normalized(), uf = (t - a).normalized();
  const V Z = V::UnitZ();
  // The groin runs obliquely, lower towards the crotch than at the hip's side (30 degrees), so
  // the pelvic organs above the crotch stay in the torso, clear of the thigh's border.
  const V medial = P(V(-1, 0, 0));
  const V groin = (std::cos(M_PI / 6) * ut - std::sin(M_PI / 6) * medial).normalized();
  b.cutSegment(thigh, RoundCone::make(h, k, 68, 44), h, groin, kPartTorso);
  // The heel below the ankle belongs to the foot, whose bones start there.
  b.cutSegment(shank, RoundCone::make(k, a, 44, 27), a, -us, foot);
  const V heel(a.x(), -18, 28), toeCentre = t - V(0, 24, 0);
  b.segment(foot, RoundCone::make(heel, toeCentre, 36, 24, Z, 0.72, 1));
  b.segment(foot, RoundCone::make(a, V(a.x(), 55, 30), 27, 24, Z, 0.9, 1));  // ankle and instep
  b.cone(kFemur, thigh, RoundCone::make(h + 3 * ut, k - 5 * ut, 13, 12));
  b.cone(kTibiaFibula, shank, RoundCone::make(k + 5 * us, a - 5 * us, 13, 9));
  b.cone(kFootBones, foot, RoundCone::make(a + 5 * uf, t - 14 * uf, 12, 7, Z, 0.6, 1));
}

void addHeadStructures(Builder& b, const BodyModel& m) {
  // Eyes sit 12 mm under the face surface, found on the head primitive itself.
  const RoundCone& head = m.segments.back().shape;
  for (double side : {1.0, -1.0}) {
    double lo = 0, hi = 120;
    for (int it = 0; it < 60; ++it) {
      const double mid = 0.5 * (lo + hi);
      (head.distance({side * 28, mid, 1178}) < -12 ? lo : hi) = mid;
    }
    b.ellipsoid(kEye, kPartHead, {side * 28, lo, 1178}, V::Constant(10));
  }
  Structure& skull = b.structure(StructureKind::Shell, kSkull, kPartHead);
  skull.outer = {{0, -6, 1214}, {68, 80, 80}};
  skull.inner = {{0, -6, 1214}, {61, 73, 73}};
  skull.zmin = 1154;
  skull.innerZmin = 1162;  // the skull base: a floor of bone under the brain
  b.ellipsoid(kBrain, kPartHead, skull.inner.c, skull.inner.r, skull.innerZmin);
}

void addTorsoStructures(Builder& b) {
  const V Y = V::UnitY();
  // Spine: lumbar-thoracic column, then the cervical part curving forward into the neck.
  const V l0(0, -50, 700), t1(0, -48, 1000), c1(0, -10, 1150);
  b.cone(kSpinalCord, kPartTorso, RoundCone::make(l0, t1, 5, 5));
  b.cone(kSpinalCord, kPartTorso, RoundCone::make(t1, c1, 5, 4));
  b.cone(kVertebrae, kPartTorso, RoundCone::make(l0, t1, 16, 14));
  b.cone(kVertebrae, kPartTorso, RoundCone::make(t1, c1, 14, 8));
  b.cone(kSternum, kPartTorso, RoundCone::make({0, 64, 905}, {0, 40, 1020}, 11, 10, Y, 0.5, 1));
  Structure& ribs = b.structure(StructureKind::Ribs, kRibs, kPartTorso);
  ribs.zmin = 905;
  ribs.zmax = 1000;  // the first rib leaves T1 (t1 above), below the shoulder joints
  ribs.depthMin = b.m.skinMm + b.m.fatMm[kPartTorso] + 3;
  ribs.depthMax = ribs.depthMin + 8;
  ribs.period = 22;
  ribs.thickness = 9;
  ribs.slope = 0.35;
  ribs.gapX = 14;  // sternum in front, vertebrae behind
  Structure& pelvis = b.structure(StructureKind::Shell, kPelvis, kPartTorso);
  pelvis.outer = {{0, -5, 735}, {94, 66, 70}};
  pelvis.inner = {{0, -5, 735}, {85, 57, 80}};
  pelvis.zmin = 700;
  pelvis.zmax = 770;
  b.ellipsoid(kHeart, kPartTorso, {-18, 26, 948}, {40, 32, 45});
  b.ellipsoid(kLiver, kPartTorso, {26, 8, 850}, {66, 50, 48});
  b.ellipsoid(kStomach, kPartTorso, {-42, 22, 875}, {34, 28, 40});
  b.ellipsoid(kSpleen, kPartTorso, {-72, -30, 885}, {18, 26, 35});
  b.ellipsoid(kKidneyLeft, kPartTorso, {-48, -38, 815}, {22, 18, 40});
  b.ellipsoid(kKidneyRight, kPartTorso, {48, -38, 805}, {22, 18, 40});
  b.ellipsoid(kLungLeft, kPartTorso, {-50, -8, 965}, {42, 50, 75});
  b.ellipsoid(kLungRight, kPartTorso, {50, -8, 965}, {42, 50, 75});
  b.ellipsoid(kBladder, kPartTorso, {0, 25, 705}, {26, 22, 22});
  b.ellipsoid(kSmallBowel, kPartTorso, {0, 18, 760}, {85, 50, 58});
}

}  // namespace

BodyModel buildBody(const PhantomOptions& options) {
  Builder b;
  BodyModel& m = b.m;
  // The skin is at least one voxel thick so every boundary voxel is skin at any voxel size.
  m.skinMm = std::max(2.0, 1.05 * options.voxelMm);
  m.fatMm.fill(5);
  m.fatMm[kPartHead] = 3;
  m.fatMm[kPartTorso] = 7;
  for (auto p : {kPartForearmLeft, kPartForearmRight, kPartShankLeft, kPartShankRight})
    m.fatMm[p] = 4;
  for (auto p : {kPartHandLeft, kPartHandRight, kPartFootLeft, kPartFootRight}) m.fatMm[p] = 3;

  SideJoints j;
  V across = V::UnitX();  // the hand's thin axis: palms face the thighs
  addTorsoAndHead(b);
  addHeadStructures(b, m);
  addLeg(b, j, false);
  addLeg(b, j, true);
  if (options.armsTouching) pressArmToHip(j, across, b, 3.0);
  addArm(b, j, across, false);
  addArm(b, j, across, true);
  addTorsoStructures(b);

  b.joint("pelvis", "", {0, 0, 720});
  b.joint("spine", "pelvis", {0, 0, 885});
  b.joint("chest", "spine", {0, 0, 1045});
  b.joint("neck", "chest", {0, 0, 1140});
  b.joint("head_top", "neck", {0, -5, 1300});
  for (bool left : {true, false}) {
    const std::string sfx = left ? "_left" : "_right";
    auto P = [&](const V& p) { return left ? mirror(p) : p; };
    b.joint("shoulder" + sfx, "chest", P(j.shoulder));
    b.joint("elbow" + sfx, "shoulder" + sfx, P(j.elbow));
    b.joint("wrist" + sfx, "elbow" + sfx, P(j.wrist));
    b.joint("hand_tip" + sfx, "wrist" + sfx, P(j.handTip));
    b.joint("hip" + sfx, "pelvis", P(j.hip));
    b.joint("knee" + sfx, "hip" + sfx, P(j.knee));
    b.joint("ankle" + sfx, "knee" + sfx, P(j.ankle));
    b.joint("toe" + sfx, "ankle" + sfx, P(j.toe));
  }

  for (Segment& s : m.segments) {
    const Box tight = s.shape.bounds();
    m.bounds.extend(tight);
    s.box = tight.expanded(m.blendMm);
  }
  // The smooth union adds at most a quarter of the blend radius outside the primitives.
  m.bounds = m.bounds.expanded(0.25 * m.blendMm);
  for (Structure& s : m.structures) {
    switch (s.kind) {
      case StructureKind::Cone:
        s.box = s.cone.bounds();
        break;
      case StructureKind::Ellipsoid:
      case StructureKind::Shell:
        s.box = s.outer.bounds();
        break;
      case StructureKind::Ribs:
        s.box = m.bounds;
        break;
    }
    s.box.lo.z() = std::max(s.box.lo.z(), s.zmin);
    s.box.hi.z() = std::min(s.box.hi.z(), s.zmax);
  }
  return m;
}

}  // namespace repose::phantom
