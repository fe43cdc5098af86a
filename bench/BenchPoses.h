// The drag the interaction benchmarks share: the right arm's cage (and the cage below 100 mm,
// kept as it is) as ARAP handles, the arm turned 60 degrees up about the shoulder.
#pragma once

#include "repose/cage/ArapDeformer.h"

#include <Eigen/Geometry>
#include <vector>

namespace repose::bench {

inline Eigen::MatrixX3d raiseRightArm60(const TriangleMesh& cage) {
  std::vector<int> handles;
  for (Eigen::Index v = 0; v < cage.vertices.rows(); ++v)
    if (cage.vertices(v, 0) > 150 || cage.vertices(v, 2) < 100)
      handles.push_back(static_cast<int>(v));
  ArapDeformer arap(cage);
  arap.setHandles(handles);
  const Eigen::Matrix3d R =
      Eigen::AngleAxisd(-60 * M_PI / 180, Eigen::Vector3d::UnitY()).toRotationMatrix();
  const Eigen::Vector3d pivot(110, 0, 1000);
  Eigen::MatrixX3d targets(handles.size(), 3);
  for (std::size_t h = 0; h < handles.size(); ++h) {
    const Eigen::Vector3d p = cage.vertices.row(handles[h]);
    targets.row(h) = (p.x() > 150 ? Eigen::Vector3d(R * (p - pivot) + pivot) : p).transpose();
  }
  return arap.solve(targets).positions;
}

}  // namespace repose::bench
