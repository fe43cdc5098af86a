// Why a bent forearm is not a rigid copy (docs/ARCHITECTURE.md, "Known limits"): the wrist and
// mid-forearm under a 90-degree elbow flexion of the 4 mm phantom, Green coordinates of the cage
// against the rigidly rotated points, for whole-body cages of several sizes and dilations and for
// a cage of the arm alone. Cage vertices nearest the forearm or hand bone of the skeleton turn
// about the elbow, the others stay. Prints JSON.
//
//   ReposeForearmBench
#include "repose/cage/CageBuilder.h"
#include "repose/cage/GreenCoordinates.h"
#include "repose/phantom/Phantom.h"

#include <nlohmann/json.hpp>

#include <Eigen/Geometry>
#include <algorithm>
#include <iostream>
#include <map>

namespace {

using namespace repose;

double segmentDistance(const Eigen::Vector3d& p, const Eigen::Vector3d& a,
                       const Eigen::Vector3d& b) {
  const Eigen::Vector3d ab = b - a;
  const double t = std::clamp((p - a).dot(ab) / ab.squaredNorm(), 0.0, 1.0);
  return (p - (a + t * ab)).norm();
}

}  // namespace

int main() {
  PhantomOptions po;
  po.voxelMm = 4;
  const Phantom phantom(po);
  const auto [organs, parts] = phantom.makeVolumes();
  Volume armOnly = parts;
  for (std::int64_t v = 0; v < armOnly.numVoxels(); ++v) {
    std::uint8_t& l = armOnly.data<std::uint8_t>()[v];
    if (l != kPartUpperArmLeft && l != kPartForearmLeft && l != kPartHandLeft) l = 0;
  }
  std::map<std::string, Eigen::Vector3d> joint;
  std::map<std::string, std::string> parent;
  for (const Joint& j : phantom.joints()) joint[j.name] = j.ras, parent[j.name] = j.parent;
  const Eigen::Vector3d elbow = joint["elbow_left"], wrist = joint["wrist_left"];
  const Eigen::Matrix3d R =
      Eigen::AngleAxisd(M_PI / 2, Eigen::Vector3d::UnitX()).toRotationMatrix();
  Eigen::MatrixX3d points(2, 3);
  points.row(0) = wrist.transpose();
  points.row(1) = (0.5 * (wrist + elbow)).transpose();

  struct Case {
    const char* name;
    const Volume* s;
    int vertices;
    double dilateMm;
  };
  const Case cases[] = {{"whole body", &parts, 300, 10},
                        {"whole body", &parts, 800, 10},
                        {"whole body", &parts, 2000, 10},
                        {"whole body", &parts, 800, 6},
                        {"arm alone", &armOnly, 300, 10}};
  nlohmann::json out = nlohmann::json::array();
  for (const Case& c : cases) {
    CageOptions co;
    co.targetVertices = c.vertices;
    co.dilateMm = c.dilateMm;
    const TriangleMesh cage = buildCage(*c.s, co).mesh;
    Eigen::MatrixX3d posed = cage.vertices;
    int moved = 0;
    for (Eigen::Index v = 0; v < cage.vertices.rows(); ++v) {
      const Eigen::Vector3d p = cage.vertices.row(v);
      std::string nearest;
      double best = 1e300;
      for (const auto& [name, par] : parent) {
        if (par.empty()) continue;
        const double d = segmentDistance(p, joint[par], joint[name]);
        if (d < best) best = d, nearest = name;
      }
      if (nearest == "wrist_left" || nearest == "hand_tip_left")
        posed.row(v) = (R * (p - elbow) + elbow).transpose(), ++moved;
    }
    const Eigen::MatrixX3d got =
        applyGreenCoordinates(computeGreenCoordinates(cage, points, 0), cage, posed);
    auto error = [&](int r) {
      const Eigen::Vector3d p = points.row(r);
      return (got.row(r).transpose() - (R * (p - elbow) + elbow)).norm();
    };
    out.push_back({{"cage", c.name},
                   {"dilate_mm", c.dilateMm},
                   {"cage_vertices", cage.vertices.rows()},
                   {"turned_vertices", moved},
                   {"wrist_error_mm", error(0)},
                   {"mid_forearm_error_mm", error(1)}});
    std::cerr << out.back().dump() << "\n";
  }
  std::cout << out.dump(2) << "\n";
}
