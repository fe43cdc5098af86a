// The scapulohumeral and lumbopelvic rhythms applied to a pose (PoseRhythm.h), and the joints'
// ranges of motion checked.
#include "repose/pose/PoseRhythm.h"

#include <Eigen/Geometry>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <map>

namespace repose {
namespace {

constexpr double kPi = 3.14159265358979323846;
constexpr double kDeg = kPi / 180;
// The girdle glides over the trunk and the pelvis turns under the lumbar spine: their turns are
// spread over this many rings of tets around them.
constexpr int kRhythmRings = 3;

// The name of a joint's side ("_left", "_right") or "" on the midline.
std::string sideOf(const std::string& joint) {
  for (const char* s : {"_left", "_right"})
    if (joint.size() > std::string(s).size() &&
        joint.compare(joint.size() - std::string(s).size(), std::string::npos, s) == 0)
      return s;
  return "";
}

std::string kindOf(const std::string& joint) {
  return joint.substr(0, joint.find('_'));
}

bool selects(const PoseGroup& g, const std::string& part, const LabelTable& labels) {
  if (std::find(g.select.partNames.begin(), g.select.partNames.end(), part) !=
      g.select.partNames.end())
    return true;
  for (const int v : g.select.parts)
    if (const Label* l = labels.find(v); l && l->name == part) return true;
  return false;
}

void unselect(PoseGroup& g, const std::string& part, const LabelTable& labels) {
  auto& names = g.select.partNames;
  names.erase(std::remove(names.begin(), names.end(), part), names.end());
  auto& values = g.select.parts;
  values.erase(std::remove_if(values.begin(), values.end(),
                              [&](int v) {
                                const Label* l = labels.find(v);
                                return l && l->name == part;
                              }),
               values.end());
}

// The transform a group has in each frame: the base, then one per keyframe (its own entry there,
// else the base).
std::vector<PoseTransform> perFrame(const Pose& pose, const std::string& group) {
  const PoseGroup* g = nullptr;
  for (const PoseGroup& x : pose.groups)
    if (x.name == group) g = &x;
  std::vector<PoseTransform> out{g->transform};
  for (const PoseKeyframe& k : pose.keyframes) {
    PoseTransform t = g->transform;
    for (const auto& [name, tk] : k.transforms)
      if (name == group) t = tk;
    out.push_back(t);
  }
  return out;
}

// Writes a group's transform of each frame (as perFrame lists them) into the pose.
void setPerFrame(Pose& pose, const std::string& group, const std::vector<PoseTransform>& t) {
  for (PoseGroup& g : pose.groups)
    if (g.name == group) g.transform = t[0];
  for (std::size_t k = 0; k < pose.keyframes.size(); ++k) {
    auto& list = pose.keyframes[k].transforms;
    bool set = false;
    for (auto& [name, tk] : list)
      if (name == group) tk = t[k + 1], set = true;
    if (!set) list.emplace_back(group, t[k + 1]);
  }
}

PoseTransform turn(const Eigen::Vector3d& axis, double angleDeg, const Eigen::Vector3d& pivot) {
  PoseTransform t;
  t.axis = axis.normalized();
  t.angleDeg = angleDeg;
  t.pivot = pivot;
  return t;
}

// The limb's transform re-expressed on the girdle or pelvis turn `carrier` it follows: the same
// orientation in the world, its joint (the pivot) carried along.
PoseTransform onCarrier(const PoseTransform& limb, const PoseTransform& carrier) {
  const Eigen::Isometry3d m = limb.isometry();
  const Eigen::Matrix3d carrierR = carrier.isometry().linear();
  const Eigen::AngleAxisd relative(carrierR.transpose() * m.linear());
  PoseTransform out;
  out.axis = relative.axis();
  out.angleDeg = relative.angle() / kDeg;
  out.pivot = limb.pivot;
  // The limb's own translation, into the carrier's frame (M(x) = R (x - p) + p + t).
  const Eigen::Vector3d t = m.translation() - (limb.pivot - m.linear() * limb.pivot);
  out.translation = carrierR.transpose() * t;
  return out;
}

std::string degrees(double v) {
  char text[32];
  std::snprintf(text, sizeof text, "%.1f", v);
  return text;
}

}  // namespace

double girdleTurnDeg(double elevationDeg) {
  return elevationDeg > 90 ? (elevationDeg - 90) / 3 : 0;
}

double pelvisTiltDeg(double flexionDeg) {
  return flexionDeg > 60 ? std::min(30.0, (flexionDeg - 60) * 5 / 6) : 0;
}

PoseRhythms::PoseRhythms(const Skeleton& skeleton, const LabelTable& partLabels)
    : partLabels_(partLabels) {
  auto hasPart = [&](const std::string& name) {
    for (const Label& l : partLabels.labels())
      if (l.name == name) return true;
    return false;
  };
  for (const SkeletonJoint& sc : skeleton.joints) {
    if (kindOf(sc.name) != "sternoclavicular") continue;
    const SkeletonJoint* shoulder = skeleton.find("shoulder" + sideOf(sc.name));
    if (!shoulder || shoulder->parts[0] != sc.parts[1] || !hasPart(sc.parts[1]) ||
        !hasPart(shoulder->parts[1]) || !shoulder->axis("rotation"))
      continue;
    Girdle g;
    g.side = sideOf(sc.name);
    g.girdlePart = sc.parts[1];
    g.armPart = shoulder->parts[1];
    g.joint = shoulder->name;
    g.sc = sc.centre;
    g.shoulder = shoulder->centre;
    g.distal = shoulder->axis("rotation")->normalized();
    girdles_.push_back(g);
  }
  if (const SkeletonJoint* ls = skeleton.find("lumbosacral");
      ls && hasPart(ls->parts[1]) && ls->axis("flexion")) {
    pelvis_.part = ls->parts[1];
    pelvis_.centre = ls->centre;
    pelvis_.axis = ls->axis("flexion")->normalized();
    for (const SkeletonJoint& hip : skeleton.joints)
      if (kindOf(hip.name) == "hip" && hip.parts[0] == pelvis_.part && hasPart(hip.parts[1]) &&
          hip.axis("rotation") && hip.axis("flexion"))
        pelvis_.hips.push_back({hip.name, hip.parts[1], hip.centre,
                                hip.axis("rotation")->normalized(),
                                hip.axis("flexion")->normalized()});
    pelvis_.present = !pelvis_.hips.empty();
  }
}

Pose PoseRhythms::apply(const Pose& pose, std::vector<std::string>* notes) const {
  Pose out = pose;
  if (empty()) return out;
  auto selectedByAny = [&](const std::string& part) {
    for (const PoseGroup& g : pose.groups)
      if (selects(g, part, partLabels_)) return true;
    return false;
  };
  // The limb group of a joint: moving, selecting the limb's part, turning about the joint.
  auto limbGroup = [&](const std::string& part, const Eigen::Vector3d& centre) -> PoseGroup* {
    for (PoseGroup& g : out.groups)
      if (!g.fixed && !g.select.rest && selects(g, part, partLabels_) &&
          (g.transform.pivot - centre).norm() < 1.0)
        return &g;
    return nullptr;
  };
  // The trunk's new parts belong to a group that selects the torso (a pose written before the
  // trunk had them), unless another group takes them.
  std::vector<std::string> trunkParts;
  for (const Girdle& g : girdles_) trunkParts.push_back(g.girdlePart);
  if (pelvis_.present) trunkParts.push_back(pelvis_.part);
  for (PoseGroup& g : out.groups)
    if (!g.select.rest && selects(g, "torso", partLabels_))
      for (const std::string& part : trunkParts)
        if (!selectedByAny(part)) g.select.partNames.push_back(part);
  // The group carrying the torso, which the new groups follow where it moves.
  std::string torsoGroup;
  for (const PoseGroup& g : out.groups)
    if (!g.fixed && !g.select.rest && selects(g, "torso", partLabels_)) torsoGroup = g.name;

  auto unique = [&](std::string name) {
    for (bool clash = true; clash;) {
      clash = false;
      for (const PoseGroup& g : out.groups) clash = clash || g.name == name;
      if (clash) name += "'";
    }
    return name;
  };

  if (pose.scapulohumeralRhythm)
    for (const Girdle& gd : girdles_) {
      if (selectedByAny(gd.girdlePart)) continue;  // the pose moves the girdle itself
      PoseGroup* arm = limbGroup(gd.armPart, gd.shoulder);
      if (!arm) continue;
      const std::string armName = arm->name;
      const std::vector<PoseTransform> armT = perFrame(out, armName);
      std::vector<PoseTransform> girdleT, newArmT;
      double most = 0;
      for (const PoseTransform& t : armT) {
        const Eigen::Vector3d moved = t.isometry().linear() * gd.distal;
        const double elevation = std::acos(std::clamp(moved.dot(gd.distal), -1.0, 1.0)) / kDeg;
        const double phi = girdleTurnDeg(elevation);
        Eigen::Vector3d axis = gd.distal.cross(moved);
        // Straight up (180 degrees) the two directions are opposite and say no plane: the turn's
        // own path does, through the direction halfway along it. A fallback that picked any axis
        // turned the girdles down instead of up, into the ribs and the organs below them.
        if (axis.norm() < 1e-6) {
          const Eigen::AngleAxisd whole(t.isometry().linear());
          const Eigen::Vector3d halfway =
              Eigen::AngleAxisd(whole.angle() / 2, whole.axis()) * gd.distal;
          axis = gd.distal.cross(halfway);
        }
        if (axis.norm() < 1e-9) axis = gd.distal.unitOrthogonal();
        girdleT.push_back(turn(axis, phi, gd.sc));
        newArmT.push_back(onCarrier(t, girdleT.back()));
        most = std::max(most, phi);
      }
      PoseGroup girdle;
      girdle.name = unique(gd.girdlePart + " (scapulohumeral rhythm)");
      girdle.select.partNames = {gd.girdlePart};
      girdle.widen = kRhythmRings;
      girdle.follows = arm->follows.empty() ? torsoGroup : arm->follows;
      for (PoseGroup& g : out.groups) unselect(g, gd.girdlePart, partLabels_);
      arm->follows = girdle.name;
      out.groups.push_back(girdle);
      setPerFrame(out, girdle.name, girdleT);
      setPerFrame(out, armName, newArmT);
      if (notes)
        notes->push_back("scapulohumeral rhythm: " + gd.girdlePart + " turns up to " +
                         degrees(most) + " deg about sternoclavicular" + gd.side +
                         " with group \"" + armName + "\"");
    }

  if (pose.lumbopelvicRhythm && pelvis_.present && !selectedByAny(pelvis_.part)) {
    std::vector<std::pair<std::string, const Pelvis::Hip*>> thighs;
    for (const Pelvis::Hip& hip : pelvis_.hips)
      if (PoseGroup* g = limbGroup(hip.thighPart, hip.centre)) thighs.emplace_back(g->name, &hip);
    if (!thighs.empty()) {
      const std::size_t frames = 1 + out.keyframes.size();
      std::vector<PoseTransform> pelvisT;
      double most = 0;
      for (std::size_t f = 0; f < frames; ++f) {
        double flexion = 0;
        for (const auto& [name, hip] : thighs) {
          const Eigen::Vector3d moved = perFrame(out, name)[f].isometry().linear() * hip->distal;
          const Eigen::Vector3d a = hip->distal - hip->distal.dot(hip->flexion) * hip->flexion;
          const Eigen::Vector3d b = moved - moved.dot(hip->flexion) * hip->flexion;
          flexion = std::max(flexion, std::atan2(a.cross(b).dot(hip->flexion), a.dot(b)) / kDeg);
        }
        pelvisT.push_back(turn(pelvis_.axis, pelvisTiltDeg(flexion), pelvis_.centre));
        most = std::max(most, pelvisTiltDeg(flexion));
      }
      PoseGroup pelvis;
      pelvis.name = unique(pelvis_.part + " (lumbopelvic rhythm)");
      pelvis.select.partNames = {pelvis_.part};
      pelvis.widen = kRhythmRings;
      pelvis.follows = torsoGroup;
      for (PoseGroup& g : out.groups) unselect(g, pelvis_.part, partLabels_);
      for (const auto& [name, hip] : thighs) {
        const std::vector<PoseTransform> thighT = perFrame(out, name);
        std::vector<PoseTransform> onPelvis;
        for (std::size_t f = 0; f < frames; ++f)
          onPelvis.push_back(onCarrier(thighT[f], pelvisT[f]));
        for (PoseGroup& g : out.groups)
          if (g.name == name) {
            if (!g.follows.empty() && g.follows != torsoGroup) pelvis.follows = g.follows;
            g.follows = pelvis.name;
          }
        setPerFrame(out, name, onPelvis);
      }
      out.groups.push_back(pelvis);
      setPerFrame(out, pelvis.name, pelvisT);
      if (notes)
        notes->push_back("lumbopelvic rhythm: " + pelvis_.part + " tilts back up to " +
                         degrees(most) + " deg about lumbosacral with the flexed hips");
    }
  }
  return out;
}

std::vector<std::string> jointRangeWarnings(const Pose& pose) {
  std::vector<std::string> out;
  auto check = [&](const std::string& axisName, double angle, const std::string& where) {
    const std::size_t dot = axisName.find('.');
    if (axisName.empty() || dot == std::string::npos) return;
    const std::string joint = axisName.substr(0, dot), axis = axisName.substr(dot + 1);
    const auto [lo, hi] = jointRangeDeg(joint, axis);
    if (angle < lo - 1e-9 || angle > hi + 1e-9)
      out.push_back("pose " + pose.name + ", " + where + ": " + axisName + " " + degrees(angle) +
                    " deg is beyond the joint's range of motion (" + degrees(lo) + " to " +
                    degrees(hi) + " deg, clinical goniometry)");
  };
  auto transform = [&](const PoseTransform& t, const std::string& where) {
    check(t.axisName, t.angleDeg, where);
    for (const PoseTurn& turn : t.then) check(turn.axisName, turn.angleDeg, where);
  };
  for (const PoseGroup& g : pose.groups)
    if (!g.fixed) transform(g.transform, "group \"" + g.name + "\"");
  for (const PoseKeyframe& k : pose.keyframes)
    for (const auto& [group, t] : k.transforms)
      transform(t, "keyframe \"" + k.name + "\", group \"" + group + "\"");
  return out;
}

}  // namespace repose
