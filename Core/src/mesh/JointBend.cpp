#include "repose/mesh/JointBend.h"

#include <Eigen/Geometry>

#include <algorithm>
#include <cmath>

namespace repose {
namespace {

constexpr double kPi = 3.14159265358979323846;

double smoothstep(double t) {
  t = std::clamp(t, 0.0, 1.0);
  return t * t * (3 - 2 * t);
}
double smoothstepSlope(double t) {
  return t <= 0 || t >= 1 ? 0 : 6 * t * (1 - t);
}

}  // namespace

Eigen::Vector3d bendPoint(const Eigen::Vector3d& p, const Eigen::Vector3d& centre,
                          const Eigen::Vector3d& axis, const Eigen::Vector3d& distal, double angle,
                          double* share) {
  const Eigen::Vector3d a = axis.normalized();
  Eigen::Vector3d d = distal - distal.dot(a) * a;
  if (d.norm() < 1e-9) d = a.unitOrthogonal();
  d.normalize();
  const Eigen::Vector3d e = a.cross(d);
  const Eigen::Vector3d u = p - centre;
  const double z = u.dot(a);
  const Eigen::Vector3d w = u - z * a;
  const double rho = w.norm();
  const double phi = std::atan2(w.dot(e), w.dot(d));
  // The share of the turn falls from 1 (along the distal part) to 0 (along the proximal) over a
  // band of angle around the joint plane (|phi| = 90 degrees), centred on it and wide enough
  // that phi + angle * s(phi) keeps rising: smoothstep's steepest slope is 1.5 over the width.
  const double width = std::min(kPi - 0.1, 1.5 * std::fabs(angle) + 0.35);
  const double from = 0.5 * (kPi - width);
  const double t = (std::fabs(phi) - from) / width;
  // Past ~115 degrees the band cannot widen further: part of the smoothstep gives way to a
  // straight ramp (slope 1 over the width), keeping the steepest slope 0.9 / |angle|, so the
  // angle still rises monotonically up to 160 degrees.
  const double linear =
      std::clamp((1.5 - 0.9 * width / std::max(1e-9, std::fabs(angle))) / 0.5, 0.0, 1.0);
  const double ramp = std::clamp(t, 0.0, 1.0), rampSlope = t <= 0 || t >= 1 ? 0.0 : 1.0;
  const double s = 1 - ((1 - linear) * smoothstep(t) + linear * ramp);
  if (share) *share = s;
  const double slope =
      -((1 - linear) * smoothstepSlope(t) + linear * rampSlope) / width * (phi < 0 ? -1.0 : 1.0);
  const double stretch = std::max(0.05, 1 + angle * slope);  // dphi'/dphi
  const double phi2 = phi + angle * s;
  const double rho2 = rho / std::sqrt(stretch);  // the plane's areas kept
  return centre + z * a + rho2 * (std::cos(phi2) * d + std::sin(phi2) * e);
}

JointBends::JointBends(const TransferMesh& mesh, const std::vector<RigidHandle>& handles,
                       const std::vector<BendJoint>& joints) {
  const Eigen::Index nv = mesh.vertices.rows();
  // Per vertex: the single body part of its tets (-1 where several meet), and whether a whole
  // piece uses it.
  std::vector<int> part(std::size_t(nv), -2);
  std::vector<char> piece(std::size_t(nv), 0);
  for (Eigen::Index t = 0; t < mesh.tets.rows(); ++t)
    for (int k = 0; k < 4; ++k) {
      int& p = part[std::size_t(mesh.tets(t, k))];
      p = p == -2 ? mesh.labels[t] : (p == mesh.labels[t] ? p : -1);
      if (!mesh.rigid.empty() && mesh.rigid[std::size_t(t)])
        piece[std::size_t(mesh.tets(t, k))] = 1;
    }
  auto groupOf = [&](int label) { return handleGroupOfPart(handles, label); };
  for (const BendJoint& j : joints) {
    Joint out;
    out.joint = j;
    out.proximalGroup = groupOf(j.proximalPart);
    out.distalGroup = groupOf(j.distalPart);
    if (out.proximalGroup < 0 || out.distalGroup < 0 || out.proximalGroup == out.distalGroup ||
        !(j.radiusMm > 0))
      continue;
    // A vertex where the two parts meet belongs to both: its tets' parts are then mixed (-1), so
    // it is recognised by having only these two parts around it.
    std::vector<int> proximal{j.proximalPart};
    for (const int p : j.proximalAlso)
      if (groupOf(p) == out.proximalGroup) proximal.push_back(p);
    std::vector<char> mixedOk(std::size_t(nv), 1);
    for (Eigen::Index t = 0; t < mesh.tets.rows(); ++t)
      if (mesh.labels[t] != j.distalPart &&
          std::find(proximal.begin(), proximal.end(), mesh.labels[t]) == proximal.end())
        for (int k = 0; k < 4; ++k) mixedOk[std::size_t(mesh.tets(t, k))] = 0;
    const double reach = j.radiusMm * std::max(j.proximalReach, j.distalReach);
    for (Eigen::Index v = 0; v < nv; ++v) {
      if (piece[std::size_t(v)] || !mixedOk[std::size_t(v)] || part[std::size_t(v)] == -2) continue;
      if ((Eigen::Vector3d(mesh.vertices.row(v)) - j.centre).norm() <= reach)
        out.vertices.push_back(int(v));
    }
    if (!out.vertices.empty()) joints_.push_back(out);
  }
}

bool JointBends::turns(const Joint& j, const std::vector<RigidHandle>& frame) const {
  const Eigen::Isometry3d relative = frame[std::size_t(j.proximalGroup)].motion.inverse() *
                                     frame[std::size_t(j.distalGroup)].motion;
  if (std::fabs(Eigen::AngleAxisd(relative.rotation()).angle()) < 1e-6)
    return false;  // the blend is one rigid motion already
  // A turn about an axis through the centre: the centre stays put.
  const Eigen::Vector3d& c = j.joint.centre;
  return (relative * c - c).norm() <= 0.02 * j.joint.radiusMm;
}

std::vector<char> JointBends::zone(const std::vector<RigidHandle>& frame,
                                   Eigen::Index vertexCount) const {
  std::vector<char> out(std::size_t(vertexCount), 0);
  for (const Joint& j : joints_)
    if (turns(j, frame))
      for (const int v : j.vertices) out[std::size_t(v)] = 1;
  return out;
}

std::vector<char> JointBends::reachTets(const TransferMesh& mesh,
                                        const std::vector<RigidHandle>& frame) const {
  std::vector<char> out(std::size_t(mesh.tets.rows()), 0);
  for (const Joint& j : joints_) {
    if (!turns(j, frame)) continue;
    const double reach = j.joint.radiusMm * std::max(j.joint.proximalReach, j.joint.distalReach);
    for (Eigen::Index t = 0; t < mesh.tets.rows(); ++t) {
      Eigen::Vector3d centre = Eigen::Vector3d::Zero();
      for (int k = 0; k < 4; ++k) centre += mesh.vertices.row(mesh.tets(t, k)).transpose() / 4;
      if ((centre - j.joint.centre).norm() <= reach) out[std::size_t(t)] = 1;
    }
  }
  return out;
}

JointBendReport JointBends::apply(const TransferMesh& mesh, const std::vector<RigidHandle>& frame,
                                  Eigen::MatrixX3d& deformed) const {
  JointBendReport report;
  for (const Joint& j : joints_) {
    if (!turns(j, frame)) continue;
    const Eigen::Isometry3d& proximal = frame[std::size_t(j.proximalGroup)].motion;
    const Eigen::Isometry3d relative =
        proximal.inverse() * frame[std::size_t(j.distalGroup)].motion;
    const Eigen::AngleAxisd turn(relative.rotation());
    const Eigen::Vector3d& c = j.joint.centre;
    for (const int v : j.vertices) {
      const Eigen::Vector3d rest = mesh.vertices.row(v);
      double s = 0;
      const Eigen::Vector3d bent =
          proximal * bendPoint(rest, c, turn.axis(), j.joint.distal, turn.angle(), &s);
      const double reach = j.joint.radiusMm * (j.joint.proximalReach +
                                               s * (j.joint.distalReach - j.joint.proximalReach));
      // Into the blended frame over the outer 30% of the joint's reach; on the trunk's side of
      // a root joint also outside the limb's cross-section (the pelvis beside a hip, the chest
      // beside a shoulder), faded by the share so the two sides agree at the joint plane.
      const Eigen::Vector3d d = j.joint.distal.normalized(), u = rest - c;
      const double offAxis = (u - u.dot(d) * d).norm(), limb = 0.5 * j.joint.radiusMm;
      const double inLimb = j.joint.proximalReach < j.joint.distalReach
                                ? smoothstep((1.3 * limb - offAxis) / (0.3 * limb))
                                : 1.0;
      const double h = smoothstep((reach - u.norm()) / (0.3 * reach)) * (inLimb + s * (1 - inLimb));
      deformed.row(v) += h * (bent.transpose() - deformed.row(v));
    }
    ++report.joints;
    report.vertices += int(j.vertices.size());
  }
  return report;
}

}  // namespace repose
