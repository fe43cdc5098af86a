// Dimensions of the mannequin: a standing child of about 1.30 m (soles at z = 0, RAS mm), built
// from the skeleton outwards so every limb primitive and bone runs through its joints.
//
// Joints are congruent, as in a real skeleton: at each joint one bone ends in a convex articular
// surface centred on the joint (the humeral and femoral heads, the humeral and femoral condyles
// across the flexion axis, the carpals, the talus) and its partner stops a cartilage gap beyond
// it, so turning a limb about its joint never drives one bone into the other.
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
  for (const auto& [c, r] : holes)
    if ((p - c).squaredNorm() < r * r) return false;
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

void BlendedDistance::add(const Segment& s, double d, double blendMm) {
  for (int c = 0; c < 3; ++c)
    if (s.blends & (1 << c)) acc[c] = smoothMin(acc[c], d, blendMm);
}

namespace {

V mirror(const V& p) {
  return {-p.x(), p.y(), p.z()};
}

// Cartilage between the articular ends of a joint's two bones.
constexpr double kCartilageMm = 3;

// Right-side (+x) joint positions of the default pose; the left side is their mirror image.
struct SideJoints {
  V shoulder{148, 0, 1030}, elbow{176, -14, 806}, wrist{194, 4, 602}, handTip{202, 14, 454};
  V hip{74, 0, 700}, knee{72, 6, 385}, ankle{70, 0, 76}, toe{70, 145, 20};
};

// Radii of the limb segments at their joints (mm): the body surface primitives.
constexpr double kUpperArmR[2] = {40, 31}, kForearmR[2] = {31, 22}, kHandR[2] = {24, 22};
constexpr double kThighR[2] = {68, 44}, kShankR[2] = {44, 27};
constexpr double kHandThin = 0.5;  // the hand's thickness over its width

struct Builder {
  BodyModel m;
  bool detailed = false;
  double limbVesselR = 0;                // PhantomOptions::limbVesselMm / 2 (0: anatomical radii)
  bool girdlesTouching = false;          // PhantomOptions::girdlesTouching
  std::vector<RoundCone> trunk, thighs;  // what a resting arm lies against

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
  Structure& cone(std::uint8_t label, std::uint8_t part, const RoundCone& c) {
    Structure& s = structure(StructureKind::Cone, label, part);
    s.cone = c;
    return s;
  }
  // A limb bone piece: claims its voxels for its part. With the detailed anatomy its marrow is
  // the same shape `cortex` mm thinner. The pieces of a limb are queued and flushed marrow first
  // (flushBones), so the bone is one cortical shell around one continuous marrow canal.
  std::vector<Structure> marrowQueue, cortexQueue;
  void bone(std::uint8_t label, std::uint8_t marrow, std::uint8_t part, const RoundCone& c,
            double cortex) {
    Structure s;
    s.kind = StructureKind::Cone;
    s.part = part;
    s.claimsPart = true;
    if (detailed && marrow) {
      s.label = marrow;
      s.cone = c;
      s.cone.r1 -= cortex;
      s.cone.r2 -= cortex;
      s.cone.sinT = (s.cone.r1 - s.cone.r2) / s.cone.len;
      s.cone.cosT = std::sqrt(1 - s.cone.sinT * s.cone.sinT);
      marrowQueue.push_back(s);
    }
    s.label = label;
    s.cone = c;
    cortexQueue.push_back(s);
  }
  void flushBones() {
    for (auto* queue : {&marrowQueue, &cortexQueue}) {
      m.structures.insert(m.structures.end(), queue->begin(), queue->end());
      queue->clear();
    }
  }
  void ellipsoid(std::uint8_t label, std::uint8_t part, const V& c, const V& r,
                 double zmin = -1e300) {
    Structure& s = structure(StructureKind::Ellipsoid, label, part);
    s.outer = {c, r};
    s.zmin = zmin;
  }
  // A vessel as a chain of tapered tubes through these points (any part; the label is set by
  // the region of the part the voxel lies in).
  void vessel(const std::vector<V>& points, double r0, double r1) {
    for (std::size_t i = 0; i + 1 < points.size(); ++i) {
      const double a = r0 + (r1 - r0) * double(i) / double(points.size() - 1);
      const double b = r0 + (r1 - r0) * double(i + 1) / double(points.size() - 1);
      cone(kVesselsTrunk, 0, RoundCone::make(points[i], points[i + 1], a, b)).anyPart = true;
    }
  }
  void joint(const std::string& name, const std::string& parent, const V& ras) {
    m.joints.push_back({name, parent, ras});
  }
  void info(const std::string& name, JointKind kind, int side, const V& distal,
            std::uint8_t proximal, std::uint8_t distalPart, double radius,
            const V& palmar = V::Zero()) {
    BodyModel::JointInfo i;
    i.kind = kind;
    i.side = side;
    i.distal = distal.normalized();
    i.palmar = palmar;
    i.proximal = proximal;
    i.distalPart = distalPart;
    i.radiusMm = radius;
    m.jointInfo.emplace_back(name, i);
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

RoundCone ball(const V& c, double r) {
  return RoundCone::make(c - V(0, 0, 0.01), c + V(0, 0, 0.01), r, r);
}

RoundCone hand(const V& wrist, const V& tip, const V& across, double shrink) {
  const V u = (tip - wrist).normalized();
  return RoundCone::make(wrist + 8 * u, tip - 22 * u, kHandR[0] * shrink, kHandR[1] * shrink,
                         across, kHandThin, 1);
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

// How deep a limb segment from p to q (radii r0 to r1 towards the body) reaches into `body` at
// its deepest, over the part of its length beyond `skip`.
double reach(const V& p, const V& q, double r0, double r1, const std::vector<RoundCone>& body,
             double skip) {
  double deepest = -1e300;
  for (int s = 0; s <= 40; ++s) {
    const double t = skip + (1 - skip) * s / 40.0;
    const V a = p + t * (q - p);
    double d = 1e300;
    for (const RoundCone& c : body) d = std::min(d, c.distance(a));
    deepest = std::max(deepest, r0 + t * (r1 - r0) - d);
  }
  return deepest;
}

// Moves `moving` along x (outwards for larger values) until the segment from `fixed` presses
// `press` mm into `body`: the arms-resting posture, one segment at a time.
void restOn(const V& fixed, V& moving, double r0, double r1, const std::vector<RoundCone>& body,
            double skip, double press) {
  double lo = fixed.x() - 120, hi = fixed.x() + 120;  // too far in, too far out
  for (int it = 0; it < 60; ++it) {
    const double mid = 0.5 * (lo + hi);
    V q = moving;
    q.x() = mid;
    (reach(fixed, q, r0, r1, body, skip) > press ? lo : hi) = mid;
  }
  moving.x() = hi;
}

// The arms against the trunk along their length (the upper arm on the chest wall, the forearm
// on the hip), the hands on the thighs, the thighs touching from the groin to the knees, as in
// the ICRP 110 reference phantoms and most supine CT. Legs first: the hands rest on them.
void restLegs(SideJoints& j) {
  j.knee.x() = 38;  // the inner thighs meet from mid-thigh down, the knees press together
  j.ankle.x() = 50;
  j.toe.x() = 50;
}
// The air between a primitive and a set of others (hard union), measured from the primitive's
// inside on a 1 mm lattice: exact to the lattice's step.
double clearance(const RoundCone& shape, const std::vector<RoundCone>& body) {
  const Box box = shape.bounds();
  double best = 1e300;
  for (double x = box.lo.x(); x <= box.hi.x(); x += 1)
    for (double y = box.lo.y(); y <= box.hi.y(); y += 1)
      for (double z = box.lo.z(); z <= box.hi.z(); z += 1) {
        const V p(x, y, z);
        if (shape.distance(p) > 0) continue;
        for (const RoundCone& c : body) best = std::min(best, c.distance(p));
      }
  return best;
}

// Turns the hand about the wrist (its tip along x) until its surface, as the body draws it,
// stands `gap` mm off the thighs: the near contact of a reference phantom's hand.
void holdHandOff(SideJoints& j, const std::vector<RoundCone>& thighs, double gap) {
  double lo = j.wrist.x() - 250, hi = j.wrist.x() + 120;  // too far in, too far out
  for (int it = 0; it < 30; ++it) {
    const double mid = 0.5 * (lo + hi);
    V tip = j.handTip;
    tip.x() = mid;
    (clearance(hand(j.wrist, tip, V::UnitX(), 1.0), thighs) < gap ? lo : hi) = mid;
  }
  j.handTip.x() = hi;
}

// With gaps (PhantomOptions::handGapMm), the forearm and the hand stand off the body by them
// instead of pressing into it: a negative press.
void restArms(SideJoints& j, const Builder& b, double press, double forearmGap, double handGap) {
  // Held off, the arm hangs a little away from the body: the upper arm leaves the chest wall
  // towards the elbow (its distal 40 % the forearm's gap off), and the forearm keeps its gap
  // from the elbow down, as in a reference phantom whose forearm is that far from the trunk.
  if (forearmGap > 0)
    restOn(j.shoulder, j.elbow, kUpperArmR[0], kUpperArmR[1], b.trunk, 0.6, -forearmGap);
  else
    restOn(j.shoulder, j.elbow, kUpperArmR[0], kUpperArmR[1], b.trunk, 0.2, press);
  std::vector<RoundCone> hip = b.trunk;
  hip.insert(hip.end(), b.thighs.begin(), b.thighs.end());
  if (forearmGap > 0)
    restOn(j.elbow, j.wrist, kForearmR[0], kForearmR[1], hip, 0.0, -forearmGap);
  else
    restOn(j.elbow, j.wrist, kForearmR[0], kForearmR[1], hip, 0.15, press);
  // The hand's thin side faces the thigh; it starts 8 mm past the wrist.
  if (handGap > 0)
    holdHandOff(j, b.thighs, handGap);
  else
    restOn(j.wrist, j.handTip, kHandR[0] * kHandThin, kHandR[1] * kHandThin, b.thighs, 0.1, press);
}

void addTorsoAndHead(Builder& b) {
  const V Y = V::UnitY(), X = V::UnitX();
  b.segment(kPartTorso, RoundCone::make({0, 0, 775}, {0, 0, 885}, 114, 106, Y, 0.7, 1));
  b.trunk.push_back(b.m.segments.back().shape);
  b.segment(kPartTorso, RoundCone::make({0, 0, 885}, {0, 0, 945}, 106, 110, Y, 0.76, 1));
  b.trunk.push_back(b.m.segments.back().shape);
  for (double side : {1.0, -1.0})  // shoulder girdle: trapezius and clavicle line
    b.segment(kPartTorso,
              RoundCone::make({side * 40, -5, 1040}, {side * 148, 0, 1030}, 50, 42, Y, 0.8, 1));
  b.segment(kPartTorso, RoundCone::make({0, 0, 1045}, {0, 0, 1140}, 44, 40));
  b.m.segments.back().neckSplit = true;
  b.segment(kPartHead, RoundCone::make({0, 20, 1162}, {0, -5, 1212}, 58, 88, X, 0.85, 1));
  b.m.segments.back().neckSplit = true;
  // The head-neck border: a plane through the joint between the spine and the skull base,
  // 15 degrees lower in front (the jaw line) than behind.
  b.m.neckCentre = V(0, -10, 1150);
  const double tilt = 15 * M_PI / 180;
  b.m.neckNormal = V(0, std::sin(tilt), std::cos(tilt));
}

void addArm(Builder& b, const SideJoints& j, const V& across, bool left, bool detached) {
  auto P = [&](const V& p) { return left ? mirror(p) : p; };
  const V ac = left ? mirror(across) : across;
  const std::uint8_t upper = left ? kPartUpperArmLeft : kPartUpperArmRight;
  const std::uint8_t fore = left ? kPartForearmLeft : kPartForearmRight;
  const std::uint8_t handPart = left ? kPartHandLeft : kPartHandRight;
  const V s = P(j.shoulder), e = P(j.elbow), w = P(j.wrist), t = P(j.handTip);
  const V uu = (e - s).normalized(), uf = (w - e).normalized(), uh = (t - w).normalized();
  b.cutSegment(upper, RoundCone::make(s, e, kUpperArmR[0], kUpperArmR[1]), s, uu, kPartTorso);
  const std::uint8_t arm = left ? kBlendArmLeft : kBlendArmRight;
  // Held off the body, the forearm and hand blend with their own upper arm only (the elbow),
  // and the upper arm with both the body (the shoulder) and them.
  if (detached) b.m.segments.back().blends = kBlendMain | arm;
  b.segment(fore, RoundCone::make(e, w, kForearmR[0], kForearmR[1]));
  if (detached) b.m.segments.back().blends = arm;
  b.segment(handPart, hand(w, t, ac, 1.0));
  if (detached) b.m.segments.back().blends = arm;
  // Humerus: the head (a ball on the shoulder joint), the shaft, and the condyles across the
  // elbow's flexion axis; the forearm bones start a cartilage gap beyond the condyles and end
  // one before the carpals, whose rounded end is centred on the wrist joint.
  const V flex = uf.cross(V::UnitY()).normalized();
  const double head = 13, condyle = 10, carpal = 10;
  b.bone(kHumerus, kHumerusMarrow, upper, ball(s, head), 3);
  b.bone(kHumerus, kHumerusMarrow, upper, RoundCone::make(s, e, 11, condyle), 3);
  b.bone(kHumerus, kHumerusMarrow, upper,
         RoundCone::make(e - 12 * flex, e + 12 * flex, condyle, condyle), 3);
  const double rf0 = 10, rf1 = 9;
  b.bone(kRadiusUlna, kRadiusUlnaMarrow, fore,
         RoundCone::make(e + (condyle + kCartilageMm + rf0) * uf,
                         w - (carpal + kCartilageMm + rf1) * uf, rf0, rf1, ac, 1, 0.9),
         3);
  // The carpals' rounded proximal surface is the hand bones' end, centred on the wrist.
  b.bone(kHandBones, 0, handPart, RoundCone::make(w, t - 12 * uh, carpal, 6, ac, 0.55, 1), 0);
  b.flushBones();
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
  b.cutSegment(thigh, RoundCone::make(h, k, kThighR[0], kThighR[1]), h, groin, kPartTorso);
  b.thighs.push_back(b.m.segments.back().shape);
  // The heel below the ankle belongs to the foot, whose bones start there.
  b.cutSegment(shank, RoundCone::make(k, a, kShankR[0], kShankR[1]), a, -us, foot);
  const V heel(a.x(), -18, 28), toeCentre = t - V(0, 24, 0);
  b.segment(foot, RoundCone::make(heel, toeCentre, 36, 24, Z, 0.72, 1));
  b.segment(foot, RoundCone::make(a, V(a.x(), 55, 30), 27, 24, Z, 0.9, 1));  // ankle and instep
  // Femur: the head (a ball on the hip joint, in the pelvis's socket), the shaft and the
  // condyles across the knee's flexion axis; tibia and fibula a cartilage gap below, ending one
  // above the talus (across the ankle's axis) from which the foot bones run.
  const V knee = us.cross(-V::UnitY()).normalized();
  const V ankle = uf.cross(V::UnitZ()).normalized();
  const double head = 15, condyle = 12, talus = 10;
  b.bone(kFemur, kFemurMarrow, thigh, ball(h, head), 4);
  b.bone(kFemur, kFemurMarrow, thigh, RoundCone::make(h, k, 13, condyle), 4);
  b.bone(kFemur, kFemurMarrow, thigh,
         RoundCone::make(k - 16 * knee, k + 16 * knee, condyle, condyle), 4);
  const double rt0 = 13, rt1 = 9;
  b.bone(kTibiaFibula, kTibiaFibulaMarrow, shank,
         RoundCone::make(k + (condyle + kCartilageMm + rt0) * us,
                         a - (talus + kCartilageMm + rt1) * us, rt0, rt1),
         3);
  b.bone(kFootBones, 0, foot, RoundCone::make(a - 8 * ankle, a + 8 * ankle, talus, talus), 0);
  b.bone(kFootBones, 0, foot, RoundCone::make(a, t - 14 * uf, talus, 7, Z, 0.6, 1), 0);
  b.bone(kFootBones, 0, foot, RoundCone::make(a, V(a.x(), -22, 30), talus, 10), 0);  // heel
  b.flushBones();
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

// Blood vessels of a few millimetres (detailed anatomy): the aorta and carotids in the trunk,
// the axillary-brachial artery down the inner upper arm, through the elbow's crease and on as
// the radial and ulnar arteries, and the iliac-femoral artery in front of the hip, down the inner
// thigh, behind the knee and down the calf.
void addVessels(Builder& b, const SideJoints& j) {
  b.vessel({{-6, 8, 985}, {0, -20, 955}, {0, -22, 850}, {0, -22, 765}}, 8, 7);  // aorta
  for (const double side : {1.0, -1.0}) {
    auto P = [&](const V& p) { return V(side * p.x(), p.y(), p.z()); };
    b.vessel({P({6, 6, 985}), P({16, 10, 1060}), P({18, 12, 1135})}, 3, 3);  // carotid
    const V s = P(j.shoulder), e = P(j.elbow), w = P(j.wrist);
    const V uu = (e - s).normalized(), uf = (w - e).normalized();
    auto across = [](const V& axis, const V& dir) {
      return V((dir - dir.dot(axis) * axis).normalized());
    };
    const V med = across(uu, P(V(-1, 0, 0))), ant = across(uu, V::UnitY());
    const V medF = across(uf, P(V(-1, 0, 0))), antF = across(uf, V::UnitY());
    auto r = [&](double anatomical) { return b.limbVesselR > 0 ? b.limbVesselR : anatomical; };
    b.vessel({P({6, 6, 985}), P({70, 2, 1000}), s + 35 * uu + 16 * med + 6 * ant,
              e - 60 * uu + 15 * med + 10 * ant, e + 16 * ant + 4 * med},
             r(4), r(2.5));
    for (const double to : {1.0, -1.0})  // ulnar (medial) and radial (lateral)
      b.vessel({e + 16 * ant + 4 * med, e + 40 * uf + 14 * antF + to * 9 * medF,
                w - 25 * uf + 12 * antF + to * 11 * medF},
               r(2.2), r(2));
    const V h = P(j.hip), k = P(j.knee), a = P(j.ankle);
    const V ut = (k - h).normalized(), us = (a - k).normalized();
    const V medT = across(ut, P(V(-1, 0, 0))), antT = across(ut, V::UnitY());
    b.vessel({{0, -22, 765},
              P({40, 10, 725}),
              h + 22 * antT + 14 * medT - 10 * ut,
              h + 150 * ut + 25 * medT + 12 * antT,
              k - 70 * ut + 22 * medT - 5 * antT,
              k - 20 * V::UnitY() + 5 * medT,
              k + 80 * us - 18 * V::UnitY(),
              a - 30 * us - 14 * V::UnitY() + 8 * medT},
             r(5), r(2.5));
  }
}

// The point `depth` mm under the back's surface above (x, z) (the trunk's primitives without
// their blend, which adds at most a quarter of its radius), found along -y.
V underBack(const Builder& b, double x, double z, double depth) {
  double inside = 0, outside = -250;
  for (int it = 0; it < 50; ++it) {
    const double mid = 0.5 * (inside + outside);
    (b.distanceTo(V(x, mid, z), {kPartTorso}) < -depth ? inside : outside) = mid;
  }
  return V(x, inside, z);
}

// The shoulder girdle (detailed anatomy): each clavicle from beside the sternum's top, under the
// skin of the upper chest, to the acromion over the humeral head; each scapula a plate on the back
// of the ribs with its spine running up to the acromion and its neck out to the glenoid, a
// cartilage gap off the humeral head. They belong to the torso's part in the phantom's own S; a
// rig that knows the girdle makes them parts of their own. Before the ribs: where a scapula lies
// on them, it is the scapula.
void addShoulderGirdle(Builder& b, const SideJoints& j) {
  for (const double side : {1.0, -1.0}) {
    auto P = [&](const V& p) { return V(side * p.x(), p.y(), p.z()); };
    auto bone = [&](std::uint8_t label, const RoundCone& c) {
      Structure& s = b.cone(label, kPartTorso, c);
      s.claimsPart = true;  // the glenoid and acromion reach past the shoulder's plane
    };
    const V s = P(j.shoulder);
    // The clavicle: medial end a few millimetres of joint beside the manubrium, lateral end at the
    // acromion; with the girdles touching, the medial ends meet over the manubrium's notch.
    const V c0 = P({b.girdlesTouching ? 11.0 : 26.0, 36, b.girdlesTouching ? 1030.0 : 1022.0}),
            c1 = P({75, 32, 1038}), c2 = P({126, 6, 1050});
    bone(kClavicle, RoundCone::make(c0, c1, 7, 6.5));
    bone(kClavicle, RoundCone::make(c1, c2, 6.5, 6));
    // The acromion over the humeral head (its underside 13 + 3 + 3 mm above the joint).
    const V acromion = P({148, -14, 1055});
    bone(kScapula, RoundCone::make(c2 + 6 * (acromion - c2).normalized(), acromion, 6, 6));
    // The scapula's body, flat against the back, its spine and its neck to the glenoid.
    const V top = underBack(b, 70, 995, 12), bottom = underBack(b, 84, 935, 12);
    const V mid = underBack(b, 77, 965, 12), surface = underBack(b, 77, 965, 0);
    const V normal = (surface - mid).normalized();
    bone(kScapula, RoundCone::make(P(top), P(bottom), 30, 15, P(normal), 0.12, 1));
    bone(kScapula, RoundCone::make(P(underBack(b, 76, 1002, 11)), acromion, 6, 5));
    const V lateralAngle = P(underBack(b, 104, 1016, 18));
    const V glenoid = s + 27 * (lateralAngle - s).normalized();
    bone(kScapula, RoundCone::make(lateralAngle, glenoid, 9, 10));
  }
}

void addTorsoStructures(Builder& b, const SideJoints& j) {
  const V Y = V::UnitY();
  if (b.detailed) addShoulderGirdle(b, j);
  // Spine: lumbar-thoracic column, then the cervical part curving forward into the neck and
  // stopping below the skull base (the neck joint is the gap between them).
  const V l0(0, -50, 700), t1(0, -48, 1000), c1(0, -10, 1138);
  b.cone(kSpinalCord, kPartTorso, RoundCone::make(l0, t1, 5, 5));
  b.cone(kSpinalCord, kPartTorso, RoundCone::make(t1, c1, 5, 4));
  if (b.detailed) {
    // The lumbosacral disc (detailed anatomy): soft tissue between the sacrum and L5, where the
    // rig puts the lumbosacral joint (a quarter of the pelvis's height below the iliac crests),
    // so the pelvis can tilt back under the spine without bone running into bone.
    // The cones' round ends reach their radius past their end points: the disc is 747-758 mm.
    const V s1(0, -50, 747 - 16), l5(0, -50, 758 + 16);
    b.cone(kVertebrae, kPartTorso, RoundCone::make(l0, s1, 16, 16));
    b.cone(kVertebrae, kPartTorso, RoundCone::make(l5, t1, 16, 14));
  } else {
    b.cone(kVertebrae, kPartTorso, RoundCone::make(l0, t1, 16, 14));
  }
  b.cone(kVertebrae, kPartTorso, RoundCone::make(t1, c1, 14, 8));
  b.cone(kSternum, kPartTorso, RoundCone::make({0, 64, 905}, {0, 40, 1020}, 11, 10, Y, 0.5, 1));
  Structure& ribs = b.structure(StructureKind::Ribs, kRibs, kPartTorso);
  ribs.zmin = 905;
  ribs.zmax = 1000;  // the first rib leaves T1 (t1 above), below the shoulder joints
  // With the shoulder girdle (detailed anatomy) the ribs lie deeper, under the scapulae and the
  // muscles between (a scapula glides on them, it does not touch them).
  ribs.depthMin = b.m.skinMm + b.m.fatMm[kPartTorso] + (b.detailed ? 12 : 3);
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
  for (const double side : {1.0, -1.0}) {  // the sockets of the femoral heads
    const V hip = side > 0 ? j.hip : mirror(j.hip);
    pelvis.holes.emplace_back(hip, 15 + kCartilageMm);
    // The socket opens forwards and outwards, as an acetabulum does, so a thigh flexed up to a
    // right angle turns its shaft clear of the rim.
    if (b.detailed) pelvis.holes.emplace_back(hip + V(side * 10, 18, -12), 25);
  }
  if (b.detailed) addVessels(b, j);
  b.ellipsoid(kHeart, kPartTorso, {-18, 26, 948}, {40, 32, 45});
  // The liver clear of the iliac crests a tilted pelvis lifts (detailed anatomy).
  if (b.detailed)
    b.ellipsoid(kLiver, kPartTorso, {26, 8, 858}, {66, 50, 42});
  else
    b.ellipsoid(kLiver, kPartTorso, {26, 8, 850}, {66, 50, 48});
  b.ellipsoid(kStomach, kPartTorso, {-42, 22, 875}, {34, 28, 40});
  b.ellipsoid(kSpleen, kPartTorso, {-72, -30, 885}, {18, 26, 35});
  b.ellipsoid(kKidneyLeft, kPartTorso, {-48, -38, 815}, {22, 18, 40});
  b.ellipsoid(kKidneyRight, kPartTorso, {48, -38, 805}, {22, 18, 40});
  // Inside the ribs, which lie deeper with the shoulder girdle (detailed anatomy): the scapulae
  // lie on the ribs, never on a lung.
  if (b.detailed) {
    b.ellipsoid(kLungLeft, kPartTorso, {-46, 8, 965}, {30, 30, 65});
    b.ellipsoid(kLungRight, kPartTorso, {46, 8, 965}, {30, 30, 65});
  } else {
    b.ellipsoid(kLungLeft, kPartTorso, {-50, -8, 965}, {42, 50, 75});
    b.ellipsoid(kLungRight, kPartTorso, {50, -8, 965}, {42, 50, 75});
  }
  b.ellipsoid(kBladder, kPartTorso, {0, 25, 705}, {26, 22, 22});
  b.ellipsoid(kSmallBowel, kPartTorso, {0, 18, 760}, {85, 50, 58});
}

// Joints of the skeleton and, for the posable ones, their kind, parts and reach.
void addJoints(Builder& b, const SideJoints& j, const V& across) {
  b.joint("pelvis", "", {0, 0, 720});
  b.joint("spine", "pelvis", {0, 0, 885});
  b.joint("chest", "spine", {0, 0, 1045});
  b.joint("neck", "chest", b.m.neckCentre);
  b.joint("head_top", "neck", {0, -5, 1300});
  b.info("neck", JointKind::Neck, 0, b.m.neckNormal, kPartTorso, kPartHead, 1.3 * 44);
  for (bool left : {true, false}) {
    const std::string sfx = left ? "_left" : "_right";
    auto P = [&](const V& p) { return left ? mirror(p) : p; };
    const int side = left ? -1 : 1;
    const V s = P(j.shoulder), e = P(j.elbow), w = P(j.wrist), t = P(j.handTip);
    const V h = P(j.hip), k = P(j.knee), a = P(j.ankle), toe = P(j.toe);
    b.joint("shoulder" + sfx, "chest", s);
    b.joint("elbow" + sfx, "shoulder" + sfx, e);
    b.joint("wrist" + sfx, "elbow" + sfx, w);
    b.joint("hand_tip" + sfx, "wrist" + sfx, t);
    b.joint("hip" + sfx, "pelvis", h);
    b.joint("knee" + sfx, "hip" + sfx, k);
    b.joint("ankle" + sfx, "knee" + sfx, a);
    b.joint("toe" + sfx, "ankle" + sfx, toe);
    const auto u = [&](std::uint8_t p) { return left ? p : std::uint8_t(p + 3); };
    const std::uint8_t upper = u(kPartUpperArmLeft), fore = u(kPartForearmLeft),
                       handP = u(kPartHandLeft);
    const std::uint8_t thigh = u(kPartThighLeft), shank = u(kPartShankLeft),
                       foot = u(kPartFootLeft);
    // The palm faces the hand's thin side towards the body's midline.
    V palm = left ? mirror(across) : across;
    if (palm.dot(P(V(-1, 0, 0))) < 0) palm = -palm;
    b.info("shoulder" + sfx, JointKind::Shoulder, side, e - s, kPartTorso, upper,
           1.3 * kUpperArmR[0]);
    b.info("elbow" + sfx, JointKind::Elbow, side, w - e, upper, fore, 1.3 * kForearmR[0]);
    b.info("wrist" + sfx, JointKind::Wrist, side, t - w, fore, handP, 1.3 * kHandR[0], palm);
    b.info("hip" + sfx, JointKind::Hip, side, k - h, kPartTorso, thigh, 1.3 * kThighR[0]);
    b.info("knee" + sfx, JointKind::Knee, side, a - k, thigh, shank, 1.3 * kShankR[0]);
    b.info("ankle" + sfx, JointKind::Ankle, side, toe - a, shank, foot, 1.3 * 36);
  }
}

}  // namespace

BodyModel buildBody(const PhantomOptions& options) {
  Builder b;
  BodyModel& m = b.m;
  b.detailed = options.armsResting;
  b.limbVesselR = options.limbVesselMm / 2;
  b.girdlesTouching = options.girdlesTouching;
  m.spacing = options.spacing();
  // The skin is at least one voxel thick so every boundary voxel is skin at any voxel size (on a
  // thick-slice grid, the voxel's extent along the surface's normal: Phantom.cpp).
  m.skinMm = std::max(2.0, 1.05 * m.spacing.minCoeff());
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
  if (options.armsResting) restLegs(j);
  addLeg(b, j, false);
  addLeg(b, j, true);
  if (options.armsTouching) pressArmToHip(j, across, b, 3.0);
  const bool detached = options.armsResting && (options.handGapMm > 0 || options.forearmGapMm > 0);
  if (options.armsResting) restArms(j, b, 3.0, options.forearmGapMm, options.handGapMm);
  addArm(b, j, across, false, detached);
  addArm(b, j, across, true, detached);
  addTorsoStructures(b, j);
  addJoints(b, j, across);

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
