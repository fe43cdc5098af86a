// Geometry of a voxel grid in RAS mm, and the LPS<->RAS flip used at file boundaries.
#include "repose/volume/VolumeGeometry.h"

#include "repose/util/Error.h"

#include <Eigen/LU>
#include <algorithm>
#include <cmath>
#include <limits>
#include <sstream>

namespace repose {

Eigen::Vector3d VolumeGeometry::spacing() const {
  return ijkToRas.block<3, 3>(0, 0).colwise().norm().transpose();
}

Eigen::Matrix3d VolumeGeometry::directions() const {
  Eigen::Matrix3d d = ijkToRas.block<3, 3>(0, 0);
  for (int c = 0; c < 3; ++c) d.col(c).normalize();
  return d;
}

double VolumeGeometry::voxelVolumeMm3() const {
  return std::fabs(ijkToRas.block<3, 3>(0, 0).determinant());
}

double VolumeGeometry::axisSkewDegrees() const {
  const Eigen::Matrix3d d = directions();
  double worst = 0;
  for (int a = 0; a < 3; ++a)
    for (int b = a + 1; b < 3; ++b)
      worst = std::max(
          worst, std::fabs(90.0 - std::acos(std::clamp(d.col(a).dot(d.col(b)), -1.0, 1.0)) * 180.0 /
                                      M_PI));
  return worst;
}

void VolumeGeometry::requireOrthogonalAxes(const std::string& context) const {
  const double skew = axisSkewDegrees();
  if (skew <= kMaxAxisSkewDegrees) return;
  std::ostringstream m;
  m.precision(3);
  m << "voxel axes are not orthogonal (sheared by " << skew
    << " degrees, as in a tilted-gantry CT): resample it onto an orthogonal grid first "
       "(e.g. with Slicer's Resample Scalar/Vector/DWI Volume)";
  throwFileError(context, m.str());
}

Eigen::Vector3d VolumeGeometry::voxelToRas(double i, double j, double k) const {
  return (ijkToRas * Eigen::Vector4d(i, j, k, 1.0)).head<3>();
}

Eigen::Vector3d VolumeGeometry::rasToVoxel(const Eigen::Vector3d& ras) const {
  return ijkToRas.block<3, 3>(0, 0).inverse() * (ras - origin());
}

std::string VolumeGeometry::axisCodes() const {
  // Same rule as nibabel's aff2axcodes: each voxel axis takes the RAS axis it is most aligned
  // with, without reusing an axis, and the letter of the direction it increases towards.
  static const char pos[3] = {'R', 'A', 'S'}, neg[3] = {'L', 'P', 'I'};
  const Eigen::Matrix3d d = directions();
  std::string codes(3, '?');
  bool used[3] = {false, false, false};
  // Assign the most confident axes first, so an oblique axis cannot steal a clean one.
  int order[3] = {0, 1, 2};
  auto strength = [&](int c) { return d.col(c).cwiseAbs().maxCoeff(); };
  std::sort(order, order + 3, [&](int a, int b) { return strength(a) > strength(b); });
  for (int c : order) {
    int best = -1;
    for (int r = 0; r < 3; ++r)
      if (!used[r] && (best < 0 || std::fabs(d(r, c)) > std::fabs(d(best, c)))) best = r;
    used[best] = true;
    codes[c] = d(best, c) >= 0 ? pos[best] : neg[best];
  }
  return codes;
}

std::pair<Eigen::Vector3d, Eigen::Vector3d> VolumeGeometry::rasBounds() const {
  Eigen::Vector3d lo = Eigen::Vector3d::Constant(std::numeric_limits<double>::max());
  Eigen::Vector3d hi = -lo;
  for (int corner = 0; corner < 8; ++corner) {
    const Eigen::Vector3d p =
        voxelToRas(corner & 1 ? dims[0] - 0.5 : -0.5, corner & 2 ? dims[1] - 0.5 : -0.5,
                   corner & 4 ? dims[2] - 0.5 : -0.5);
    lo = lo.cwiseMin(p);
    hi = hi.cwiseMax(p);
  }
  return {lo, hi};
}

void VolumeGeometry::validate(const std::string& context) const {
  for (int a = 0; a < 3; ++a)
    if (dims[a] <= 0)
      throwFileError(context, "dimension " + std::to_string(a) + " is " + std::to_string(dims[a]));
  if (!ijkToRas.allFinite()) throwFileError(context, "orientation matrix is not finite");
  const Eigen::Matrix3d lin = ijkToRas.block<3, 3>(0, 0);
  const Eigen::Vector3d s = spacing();
  if (s.minCoeff() <= 0 || std::fabs(lin.determinant()) < 1e-12 * s.prod())
    throwFileError(context, "orientation matrix is singular (zero spacing or parallel axes)");
}

VolumeGeometry VolumeGeometry::make(std::array<std::int64_t, 3> dims,
                                    const Eigen::Vector3d& spacing, const Eigen::Vector3d& origin,
                                    const Eigen::Matrix3d& directions) {
  VolumeGeometry g;
  g.dims = dims;
  g.ijkToRas.setIdentity();
  g.ijkToRas.block<3, 3>(0, 0) = directions * spacing.asDiagonal();
  g.ijkToRas.block<3, 1>(0, 3) = origin;
  return g;
}

Eigen::Matrix4d flipLpsRas(const Eigen::Matrix4d& m) {
  Eigen::Matrix4d f = Eigen::Matrix4d::Identity();
  f(0, 0) = -1;
  f(1, 1) = -1;
  return f * m;
}

}  // namespace repose
