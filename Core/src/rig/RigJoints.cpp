// The rig's joints, fitted to the bones' articular ends. At each joint one bone ends in a convex
// surface centred on the joint's axis or centre: the humeral and femoral heads (spheres: the
// shoulder and the hip), the humeral and femoral condyles (a roll about the flexion axis: the
// elbow and the knee), the carpals' proximal row (the wrist) and the talar dome (the ankle). The
// centre is fitted to that surface, so a limb turned about it keeps its bones congruent; a fit
// that fails falls back to the middle of the gap between the two bones, and says so.
#include "RigInternal.h"

#include "repose/util/Error.h"

#include <Eigen/Dense>

#include <algorithm>
#include <cmath>
#include <sstream>

namespace repose::rig {
namespace {

constexpr double kPi = 3.14159265358979323846;

std::string sideName(int side) {
  return side < 0 ? "_left" : "_right";
}

// A point of a bone's surface and how far it may lie from the true surface (the voxel's size
// along the face's normal: a face of an 8 mm slice says four times less than one of 2 mm pixels).
struct Surface {
  V p;
  double size;
};

// Algebraic sphere fit, |p|^2 = 2 c.p + (r^2 - |c|^2), each point weighted by 1 / its size.
bool sphereFit(const std::vector<Surface>& pts, V& c, double& r) {
  if (pts.size() < 8) return false;
  Eigen::MatrixXd A(pts.size(), 4);
  Eigen::VectorXd b(pts.size());
  V mean = V::Zero();
  for (const Surface& s : pts) mean += s.p;
  mean /= double(pts.size());
  for (std::size_t i = 0; i < pts.size(); ++i) {
    const V p = pts[i].p - mean;
    const double w = 1 / pts[i].size;
    A.row(Eigen::Index(i)) << w * 2 * p.x(), w * 2 * p.y(), w * 2 * p.z(), w;
    b[Eigen::Index(i)] = w * p.squaredNorm();
  }
  const Eigen::Vector4d x = A.colPivHouseholderQr().solve(b);
  c = mean + x.head<3>();
  const double r2 = x[3] + x.head<3>().squaredNorm();
  if (!(r2 > 0) || !c.allFinite()) return false;
  r = std::sqrt(r2);
  return true;
}

// Circle fit in the plane perpendicular to `axis`, weighted likewise: the centre on the plane
// through the points' mean.
bool circleFit(const std::vector<Surface>& pts, const V& axis, V& c, double& r) {
  if (pts.size() < 8) return false;
  const V e1 = axis.unitOrthogonal(), e2 = axis.cross(e1);
  V mean = V::Zero();
  for (const Surface& s : pts) mean += s.p;
  mean /= double(pts.size());
  Eigen::MatrixXd A(pts.size(), 3);
  Eigen::VectorXd b(pts.size());
  for (std::size_t i = 0; i < pts.size(); ++i) {
    const V d = pts[i].p - mean;
    const double u = d.dot(e1), v = d.dot(e2), w = 1 / pts[i].size;
    A.row(Eigen::Index(i)) << w * 2 * u, w * 2 * v, w;
    b[Eigen::Index(i)] = w * (u * u + v * v);
  }
  const Eigen::Vector3d x = A.colPivHouseholderQr().solve(b);
  c = mean + x[0] * e1 + x[1] * e2;
  const double r2 = x[2] + x[0] * x[0] + x[1] * x[1];
  if (!(r2 > 0) || !c.allFinite()) return false;
  r = std::sqrt(r2);
  return true;
}

// The geometric fit from an algebraic start: Gauss-Newton on the distances to the surface,
// sum w_i (|p_i - c| - r)^2, with |.| in the plane across `axis` for a circle. The algebraic fit
// alone shrinks the radius of a partial arc measured on a coarse grid (the humeral condyles seen
// only on their distal side, in 4 to 8 mm voxels), moving the centre towards the tip; the
// geometric one does not. For the round ends (heads, condyles); the carpals and the talar dome,
// flatter than a circle across, keep the algebraic centre, which stays inside them.
void refineGeometric(const std::vector<Surface>& pts, const V* axis, V& c, double& r) {
  for (int it = 0; it < 30; ++it) {
    Eigen::Matrix4d JtJ = Eigen::Matrix4d::Zero();
    Eigen::Vector4d Jtr = Eigen::Vector4d::Zero();
    for (const Surface& s : pts) {
      V d = s.p - c;
      if (axis) d -= d.dot(*axis) * *axis;
      const double n = d.norm();
      if (!(n > 1e-9)) continue;
      const double w = 1 / (s.size * s.size);
      Eigen::Vector4d J;
      J << -d / n, -1;  // d(|p - c| - r) / d(c, r)
      JtJ += w * J * J.transpose();
      Jtr += w * J * (n - r);
    }
    if (axis) {  // the centre moves only across the axis
      const Eigen::Vector4d a(axis->x(), axis->y(), axis->z(), 0);
      JtJ += 1e6 * JtJ.trace() * a * a.transpose();
    }
    const Eigen::Vector4d step = JtJ.ldlt().solve(-Jtr);
    if (!step.allFinite()) return;
    c += step.head<3>();
    r += step[3];
    if (step.head<3>().norm() < 1e-6 && std::fabs(step[3]) < 1e-6) return;
  }
}

struct EndFit {
  V centre = V::Zero();
  double radius = 0, rms = -1;
  int points = 0;
  bool ok = false;
};

// Fits the articular end of a bone: its surface points within `reach` of `tip`, then again on
// the points within a tolerance of the surface found (their own voxel size, or a tenth of the
// radius) and no further up the shaft (`inward`) than `shaft` radii, until it settles. A sphere,
// or with `axis` a roll about that axis (centred between the end's extremes along it, measured
// at the level of the centre so a tilted end counts both its sides).
EndFit fitEnd(const Bone& bone, const V& tip, const V& inward, double reach, const V* axis,
              double voxel, double shaft = 0.35, bool geometric = true) {
  EndFit f;
  std::vector<Surface> pts;
  for (std::size_t i = 0; i < bone.boundary.size(); ++i)
    if ((bone.boundary[i] - tip).norm() <= reach)
      pts.push_back({bone.boundary[i], bone.faceSize[i]});
  auto distance = [&](const V& p) {
    if (!axis) return (p - f.centre).norm();
    const V d = p - f.centre;
    return (d - d.dot(*axis) * *axis).norm();
  };
  auto fit = [&](const std::vector<Surface>& q) {
    if (!(axis ? circleFit(q, *axis, f.centre, f.radius) : sphereFit(q, f.centre, f.radius)))
      return false;
    if (geometric) refineGeometric(q, axis, f.centre, f.radius);
    return f.radius > 0 && f.centre.allFinite();
  };
  if (!fit(pts)) return f;
  for (int it = 0; it < 10; ++it) {
    std::vector<Surface> keep;
    for (std::size_t i = 0; i < bone.boundary.size(); ++i) {
      const V& p = bone.boundary[i];
      if ((p - tip).norm() > 1.5 * reach) continue;
      const double tol = std::max(0.75 * bone.faceSize[i], 0.1 * f.radius);
      if (std::fabs(distance(p) - f.radius) > tol) continue;
      if ((p - f.centre).dot(inward) > shaft * f.radius) continue;
      keep.push_back({p, bone.faceSize[i]});
    }
    if (keep.size() < 8) break;
    const V before = f.centre;
    if (!fit(keep)) return f;
    pts.swap(keep);
    if ((f.centre - before).norm() < 0.01 * voxel) break;
  }
  if (axis) {  // along the axis: the middle of the end's extent at the centre's level
    const V level = inward - inward.dot(*axis) * *axis;
    double lo = 1e300, hi = -1e300;
    for (const V& p : bone.boundary) {
      const V d = p - f.centre;
      if ((p - tip).norm() > 1.5 * reach) continue;
      if (level.norm() > 0 && std::fabs(d.dot(level.normalized())) > 0.5 * f.radius) continue;
      if ((d - d.dot(*axis) * *axis).norm() > 1.5 * f.radius) continue;
      lo = std::min(lo, d.dot(*axis)), hi = std::max(hi, d.dot(*axis));
    }
    if (hi >= lo) f.centre += 0.5 * (lo + hi) * *axis;
  }
  double sum = 0, weight = 0;
  for (const Surface& s : pts) {
    const double w = 1 / (s.size * s.size);
    sum += w * std::pow(distance(s.p) - f.radius, 2), weight += w;
  }
  f.points = int(pts.size());
  f.rms = weight > 0 ? std::sqrt(sum / weight) : -1;
  f.ok = f.radius > 0.75 * voxel && f.radius < std::max(60.0, reach) && f.points >= 8;
  return f;
}

// The condyles' line: the widest direction of the bone's end across its axis, when the end is
// clearly wider one way (a ratio of the principal spreads of at least 1.3).
std::optional<V> condylarAxis(const std::vector<V>& boundary, const V& tip, const V& axis,
                              double reach) {
  std::vector<V> pts;
  for (const V& p : boundary)
    if ((p - tip).norm() <= reach) pts.push_back(p - (p - tip).dot(axis) * axis);
  if (pts.size() < 12) return std::nullopt;
  V mean = V::Zero();
  for (const V& p : pts) mean += p;
  mean /= double(pts.size());
  Eigen::Matrix3d cov = Eigen::Matrix3d::Zero();
  for (const V& p : pts) cov += (p - mean) * (p - mean).transpose();
  Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eig(cov);
  const Eigen::Vector3d l = eig.eigenvalues();  // ascending; l[0] ~ 0 (along the axis)
  if (!(l[1] > 0) || std::sqrt(l[2] / l[1]) < 1.3) return std::nullopt;
  return V(eig.eigenvectors().col(2).normalized());
}

V orientedAway(const V& axis, const V& from, const V& to) {
  return (to - from).dot(axis) >= 0 ? axis : V(-axis);
}

// A hinge (the elbow, the knee): the proximal bone's condyles roll about their line at the
// joint; the line from the condyles when they say it, else the body's left-right line. Without
// a distal bone (a map that labels the humerus and femur but not the forearm and shank bones, as
// TotalSegmentator's `total` task does) the fit is the condyles' alone, the distal segment taken
// along the proximal bone (`distalAxis` = `along`), and the method says so.
FittedJoint fitHinge(const Bone& proximal, const V& along, const Bone* distal, const V& distalAxis,
                     JointKind kind, const V& anterior, const V& superior, int side, double voxel,
                     double minReach, const std::string& condyleName, const std::string& boneName,
                     const std::string& partnerName) {
  FittedJoint j;
  const V tip = proximal.extreme(along);
  const double reach = std::max(0.15 * proximal.length, minReach);
  const std::optional<V> condyles = condylarAxis(proximal.boundary, tip, along, reach);
  const V flexion = jointAxes(kind, distalAxis, anterior, superior, side)[0].second;
  V axis = condyles ? *condyles : flexion;
  if (axis.dot(flexion) < 0) axis = -axis;
  const EndFit e = fitEnd(proximal, tip, -along, reach, &axis, voxel);
  // Without a fit: the gap to the distal bone, else the proximal bone's end.
  j.centre = e.ok ? e.centre
                  : (distal ? V(0.5 * (proximal.extreme(along) + distal->extreme(-along))) : tip);
  std::ostringstream method;
  if (e.ok)
    method << (condyles ? "roll of the " + condyleName + " about their line"
                        : "roll of the distal " + boneName + " about the body's left-right line")
           << " (radius " << std::lround(e.radius * 10) / 10.0 << " mm, " << e.points << " points)";
  else if (distal)
    method << "middle of the gap between " << boneName << " and " << partnerName;
  else
    method << "the distal end of the " << boneName;
  if (!distal)
    method << "; no " << partnerName << " labelled: the segment beyond taken along the "
           << boneName;
  j.method = method.str();
  j.rms = e.ok ? e.rms : -1;
  if (condyles) j.flexion = axis;
  j.distal = distalAxis;
  j.planeNormal = (along + distalAxis).normalized();
  return j;
}

}  // namespace

int partOf(BoneKind kind, int side) {
  const int s = side < 0 ? 0 : 3;  // the phantom's numbering: left parts, then right (+3)
  switch (kind) {
    case BoneKind::Skull:
    case BoneKind::Mandible:
    case BoneKind::Teeth:
      return 1;
    case BoneKind::Humerus:
      return 3 + s;
    case BoneKind::Forearm:
      return 4 + s;
    case BoneKind::Hand:
      return 5 + s;
    case BoneKind::Femur:
      return 9 + s;
    case BoneKind::Shank:
    case BoneKind::Patella:
      return 10 + s;
    case BoneKind::Foot:
      return 11 + s;
    default:
      return 2;  // spine, ribs, sternum, clavicles, scapulae, pelvis: the torso
  }
}

std::vector<FittedJoint> fitJoints(const Bones& bones, std::vector<std::string>& missing) {
  std::vector<FittedJoint> out;
  const BodyFrame& f = bones.frame;
  const V up = f.superior, ant = f.anterior, right = f.right();
  const double voxel = bones.voxelMm;
  const Bone* spine = bones.find(BoneKind::Spine, 0);
  const Bone* skull = bones.find(BoneKind::Skull, 0);
  const Bone* pelvis = bones.find(BoneKind::Pelvis, 0);
  // Where the shoulders hang from: the top of the spine (or the body's top).
  const V spineTop = spine ? spine->extreme(up) : V(f.midlineX, 0, 1e4);
  const V hipsFrom =
      pelvis ? pelvis->centroid : (spine ? spine->extreme(-up) : V(f.midlineX, 0, -1e4));

  auto add = [&](FittedJoint j, JointKind kind, const std::string& name, int side, int proximal,
                 int distal) {
    j.kind = kind;
    j.name = name;
    j.side = side;
    j.parts = {proximal, distal};
    out.push_back(j);
  };
  auto gap = [&](const Bone& a, const V& towardsB, const Bone& b) {
    return V(0.5 * (a.extreme(towardsB) + b.extreme(-towardsB)));
  };
  auto describeFit = [](const char* what, const EndFit& e) {
    std::ostringstream s;
    s << what << " (radius " << std::lround(e.radius * 10) / 10.0 << " mm, " << e.points
      << " points)";
    return s.str();
  };

  if (spine && skull) {
    FittedJoint j;
    const V top = spine->extreme(up);
    double best = 1e300;
    for (const V& p : skull->boundary) best = std::min(best, (p - top).norm());
    V nearest = V::Zero();
    int count = 0;
    for (const V& p : skull->boundary)
      if ((p - top).norm() <= best + voxel) nearest += p, ++count;
    nearest /= double(count);
    j.centre = 0.5 * (top + nearest);
    j.method = "middle of the gap between the spine's top and the skull";
    j.distal = up;
    const double tilt = 15 * kPi / 180;  // the jaw line: lower in front
    j.planeNormal = (std::cos(tilt) * up + std::sin(tilt) * ant).normalized();
    add(j, JointKind::Neck, "neck", 0, 2, 1);
  } else {
    missing.push_back(std::string("neck: no ") + (skull ? "spine" : "skull") + " found");
  }

  // The pelvis under the lumbar spine: the lumbosacral joint at the top of the sacrum where its
  // labels say it, else on the spine a quarter of the pelvis's height below the iliac crests
  // (L5/S1 lies about there).
  bool lumbosacral = false;
  if (spine && pelvis) {
    FittedJoint j;
    const double top = pelvis->extreme(up).dot(up), bottom = pelvis->extreme(-up).dot(up);
    double level = top - 0.25 * (top - bottom);
    std::string how = "on the spine a quarter of the pelvis's height below the iliac crests";
    if (!bones.sacrum.empty()) {
      double highest = -1e300;
      for (const V& p : bones.sacrum) highest = std::max(highest, p.dot(up));
      level = highest;
      how = "the top of the sacrum";
    }
    // The spine's axis at that level: its boundary in a slab about it, widened when the level
    // falls in a disc (soft tissue between two vertebrae, no spine voxel in the thin slab).
    V centre = V::Zero();
    int count = 0;
    for (double slab = std::max(1.5 * voxel, 4.0); count == 0 && slab <= 40; slab *= 2)
      for (const V& p : spine->boundary)
        if (std::fabs(p.dot(up) - level) <= slab) centre += p, ++count;
    if (count > 0) {
      centre /= double(count);
      j.centre = centre + (level - centre.dot(up)) * up;
      j.method = how;
      j.distal = -up;
      j.planeNormal = -up;
      j.wholeInterface = true;
      add(j, JointKind::Lumbosacral, "lumbosacral", 0, 2, kPartPelvis);
      lumbosacral = true;
    }
  }
  if (!lumbosacral)
    missing.push_back(std::string("lumbosacral: no ") + (spine ? "pelvis" : "spine") +
                      " found (the pelvis stays with the torso)");

  for (const int side : {-1, +1}) {
    const std::string sfx = sideName(side), sideWord = side < 0 ? "left" : "right";
    const V medial = -double(side) * right;
    const Bone* H = bones.find(BoneKind::Humerus, side);
    const Bone* F = bones.find(BoneKind::Forearm, side);
    const Bone* Hd = bones.find(BoneKind::Hand, side);
    const Bone* Fe = bones.find(BoneKind::Femur, side);
    const Bone* T = bones.find(BoneKind::Shank, side);
    const Bone* Ft = bones.find(BoneKind::Foot, side);

    // A ball joint at a long bone's proximal end (shoulder, hip): a sphere fit of its head over
    // `reach` of its length, else a point just inside the end.
    auto ballJoint = [&](const Bone& b, const V& u, double reach, const std::string& head,
                         const std::string& bone) {
      FittedJoint j;
      const V tip = b.extreme(-u);
      const EndFit e = fitEnd(b, tip, u, reach * b.length, nullptr, voxel);
      j.centre = e.ok ? e.centre : V(tip + 0.05 * b.length * u);
      j.method = e.ok ? describeFit(("sphere fit of the " + head).c_str(), e)
                      : "the " + bone + "'s proximal end (the head could not be fitted)";
      j.rms = e.ok ? e.rms : -1;
      j.distal = u;
      return j;
    };

    // ---- the shoulder girdle: the clavicle's medial end beside the sternum ----
    int girdle = 2;  // the shoulder's proximal part: the girdle when there is one, else the torso
    if (const Bone* Cl = bones.find(BoneKind::Clavicle, side)) {
      FittedJoint j;
      const V end = Cl->extreme(medial);
      j.centre = end;
      j.method = "the clavicle's medial end";
      if (const Bone* St = bones.find(BoneKind::Sternum, 0)) {
        V nearest = St->centroid;
        double best = 1e300;
        for (const V& p : St->boundary)
          if ((p - end).norm() < best) best = (p - end).norm(), nearest = p;
        if (best < 40) {
          j.centre = 0.5 * (end + nearest);
          j.method = "between the clavicle's medial end and the sternum";
        }
      }
      j.distal = (Cl->extreme(-medial) - end).normalized();
      j.planeNormal = j.distal;
      j.wholeInterface = true;
      girdle = side < 0 ? kPartGirdleLeft : kPartGirdleRight;
      add(j, JointKind::Sternoclavicular, "sternoclavicular" + sfx, side, 2, girdle);
    } else if (H) {
      missing.push_back("sternoclavicular" + sfx + ": no " + sideWord +
                        " clavicle found (the shoulder girdle stays with the torso)");
    }

    // ---- the arm ----
    V uh = V::Zero(), uf = V::Zero();
    if (H) {
      // Distal: towards the forearm bones, else away from the top of the spine.
      uh = F ? orientedAway(H->axis, H->centroid, F->centroid)
             : orientedAway(H->axis, spineTop, H->centroid);
      if (!F && (H->extreme(uh) - spineTop).norm() < (H->extreme(-uh) - spineTop).norm()) uh = -uh;
      FittedJoint j = ballJoint(*H, uh, 0.25, "humeral head", "humerus");
      j.planeNormal = uh;
      add(j, JointKind::Shoulder, "shoulder" + sfx, side, girdle, partOf(BoneKind::Humerus, side));
    } else {
      missing.push_back("shoulder" + sfx + ", elbow" + sfx + ", wrist" + sfx + ": no " + sideWord +
                        " humerus found (the " + sideWord + " arm stays with the torso)");
    }
    if (H && F) {
      uf = orientedAway(F->axis, H->centroid, F->centroid);
      add(fitHinge(*H, uh, F, uf, JointKind::Elbow, ant, up, side, voxel, 20.0, "humeral condyles",
                   "humerus", "forearm bones"),
          JointKind::Elbow, "elbow" + sfx, side, partOf(BoneKind::Humerus, side),
          partOf(BoneKind::Forearm, side));
    } else if (H) {
      // The elbow from the humerus alone; the forearm (and the hand, without a wrist) is the arm
      // beyond its plane.
      add(fitHinge(*H, uh, nullptr, uh, JointKind::Elbow, ant, up, side, voxel, 20.0,
                   "humeral condyles", "humerus", "radius or ulna"),
          JointKind::Elbow, "elbow" + sfx, side, partOf(BoneKind::Humerus, side),
          partOf(BoneKind::Forearm, side));
      missing.push_back("wrist" + sfx + ": no " + sideWord +
                        " radius or ulna found (the elbow is fitted from the humerus alone; the "
                        "hand stays with the forearm)");
    }
    if (F && Hd) {
      const V uhd = orientedAway(Hd->axis, F->centroid, Hd->centroid);
      FittedJoint j;
      const V tip = Hd->extreme(-uhd);
      // The carpals' end is an ellipsoid more than a ball (the radiocarpal joint is condyloid):
      // the algebraic fit's centre stays inside it where the geometric one is drawn along it.
      const EndFit e =
          fitEnd(*Hd, tip, uhd, std::max(0.3 * Hd->length, 15.0), nullptr, voxel, 0.35, false);
      j.centre = e.ok ? e.centre : gap(*F, uhd, *Hd);
      j.method = e.ok ? describeFit("sphere fit of the proximal carpals", e)
                      : "middle of the gap between forearm and hand bones";
      j.rms = e.ok ? e.rms : -1;
      j.distal = uhd;
      j.planeNormal = (uf.norm() > 0 ? V((uf + uhd).normalized()) : uhd);
      // The palm: the hand's thinnest direction, towards the midline when the palm faces the
      // thigh (its thin side is closer to left-right), else forward.
      Eigen::Matrix3d cov = Eigen::Matrix3d::Zero();
      for (const V& p : Hd->boundary) cov += (p - Hd->centroid) * (p - Hd->centroid).transpose();
      V thin = Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d>(cov).eigenvectors().col(0);
      const V towards = std::fabs(thin.dot(right)) > std::fabs(thin.dot(ant)) ? medial : ant;
      j.palmar = thin.dot(towards) >= 0 ? thin : V(-thin);
      add(j, JointKind::Wrist, "wrist" + sfx, side, partOf(BoneKind::Forearm, side),
          partOf(BoneKind::Hand, side));
    } else if (F) {
      missing.push_back("wrist" + sfx + ": no " + sideWord +
                        " hand bones found (the hand stays with the forearm)");
    }

    // ---- the leg ----
    V ufe = V::Zero(), ut = V::Zero();
    if (Fe) {
      ufe = T ? orientedAway(Fe->axis, Fe->centroid, T->centroid)
              : orientedAway(Fe->axis, hipsFrom, Fe->centroid);
      FittedJoint j = ballJoint(*Fe, ufe, 0.2, "femoral head", "femur");
      // The groin runs obliquely, 30 degrees lower towards the crotch than at the hip's side.
      const V inward = (medial - medial.dot(ufe) * ufe).normalized();
      j.planeNormal = (std::cos(kPi / 6) * ufe - std::sin(kPi / 6) * inward).normalized();
      add(j, JointKind::Hip, "hip" + sfx, side, lumbosacral ? kPartPelvis : 2,
          partOf(BoneKind::Femur, side));
    } else {
      missing.push_back("hip" + sfx + ", knee" + sfx + ", ankle" + sfx + ": no " + sideWord +
                        " femur found (the " + sideWord + " leg stays with the torso)");
    }
    if (Fe && T) {
      ut = orientedAway(T->axis, Fe->centroid, T->centroid);
      add(fitHinge(*Fe, ufe, T, ut, JointKind::Knee, ant, up, side, voxel, 25.0, "femoral condyles",
                   "femur", "tibia"),
          JointKind::Knee, "knee" + sfx, side, partOf(BoneKind::Femur, side),
          partOf(BoneKind::Shank, side));
    } else if (Fe) {
      add(fitHinge(*Fe, ufe, nullptr, ufe, JointKind::Knee, ant, up, side, voxel, 25.0,
                   "femoral condyles", "femur", "tibia or fibula"),
          JointKind::Knee, "knee" + sfx, side, partOf(BoneKind::Femur, side),
          partOf(BoneKind::Shank, side));
      missing.push_back("ankle" + sfx + ": no " + sideWord +
                        " tibia or fibula found (the knee is fitted from the femur alone; the "
                        "foot stays with the shank)");
    }
    if (T && Ft) {
      V ufoot = Ft->axis.dot(ant) >= 0 ? Ft->axis : V(-Ft->axis);  // heel to toes
      FittedJoint j;
      const V bottom = T->extreme(ut);
      V tip = Ft->centroid;
      double best = 1e300;
      for (const V& p : Ft->boundary)
        if ((p - bottom).norm() < best) best = (p - bottom).norm(), tip = p;
      V axis = right;  // the talar dome rolls about the line between the malleoli
      // Only the dome itself: the foot's other bones leave the talus below its centre.
      const EndFit e =
          fitEnd(*Ft, tip, ut, std::max(0.1 * T->length, 20.0), &axis, voxel, 0.0, false);
      j.centre = e.ok ? e.centre : V(0.5 * (bottom + tip));
      j.method = e.ok ? describeFit("roll of the talar dome about the left-right line", e)
                      : "middle of the gap between tibia and foot bones";
      j.rms = e.ok ? e.rms : -1;
      j.distal = ufoot;
      j.planeNormal = ut;
      add(j, JointKind::Ankle, "ankle" + sfx, side, partOf(BoneKind::Shank, side),
          partOf(BoneKind::Foot, side));
    } else if (T) {
      missing.push_back("ankle" + sfx + ": no " + sideWord +
                        " foot bones found (the foot stays with the shank)");
    }
  }
  return out;
}

LabelTable rigPartLabels() {
  static const char* names[] = {"",
                                "head",
                                "torso",
                                "upper_arm_left",
                                "forearm_left",
                                "hand_left",
                                "upper_arm_right",
                                "forearm_right",
                                "hand_right",
                                "thigh_left",
                                "shank_left",
                                "foot_left",
                                "thigh_right",
                                "shank_right",
                                "foot_right",
                                "shoulder_girdle_left",
                                "shoulder_girdle_right",
                                "pelvis"};
  LabelTable t;
  for (int v = 1; v <= kPartPelvis; ++v) {
    Label l;
    l.value = v;
    l.name = names[v];
    l.color = LabelTable::defaultColor(v);
    l.colorGenerated = true;
    t.set(l);
  }
  return t;
}

}  // namespace repose::rig
