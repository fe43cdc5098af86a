// Where a voxel grid sits in the patient: dimensions and the 4x4 IJK -> RAS matrix (mm).
// RAS is 3D Slicer's convention; file formats in LPS are converted at the file boundary.
#pragma once

#include <Eigen/Core>
#include <array>
#include <cstdint>
#include <string>

namespace repose {

// Axes closer than this to a right angle count as orthogonal: float32 sforms and six-decimal
// DICOM orientations round to well below it; 0.06 degrees shifts a voxel 0.5 mm across 500 mm.
constexpr double kMaxAxisSkewDegrees = 0.06;

struct VolumeGeometry {
  std::array<std::int64_t, 3> dims{0, 0, 0};
  Eigen::Matrix4d ijkToRas = Eigen::Matrix4d::Identity();

  std::int64_t numVoxels() const { return dims[0] * dims[1] * dims[2]; }
  // Voxel size along i, j, k in mm (the column norms of the linear part).
  Eigen::Vector3d spacing() const;
  // Unit direction of each voxel axis in RAS, as matrix columns.
  Eigen::Matrix3d directions() const;
  // A voxel's volume in mm^3: |det| of the linear part (the product of the spacings only when the
  // axes are orthogonal).
  double voxelVolumeMm3() const;
  // The largest departure of two voxel axes from a right angle, in degrees: 0 for the grids of
  // most scanners; a sheared grid (a tilted-gantry CT series, a sheared NIfTI sform) has more.
  double axisSkewDegrees() const;
  // Throws repose::Error "<context>: voxel axes are not orthogonal ..." when axisSkewDegrees()
  // exceeds kMaxAxisSkewDegrees: for the steps that assume orthogonal axes (cage and mesh
  // building from S). Reading, describing, converting and rasterizing take sheared grids.
  void requireOrthogonalAxes(const std::string& context) const;
  Eigen::Vector3d origin() const { return ijkToRas.block<3, 1>(0, 3); }
  Eigen::Vector3d voxelToRas(double i, double j, double k) const;
  Eigen::Vector3d rasToVoxel(const Eigen::Vector3d& ras) const;
  // Axis codes as nibabel's aff2axcodes: the letter each voxel axis points to, e.g. "LPS".
  std::string axisCodes() const;
  // Axis-aligned RAS bounds of the voxel corners: min (x,y,z), max (x,y,z).
  std::pair<Eigen::Vector3d, Eigen::Vector3d> rasBounds() const;
  // Throws repose::Error if dims are not positive or the matrix is singular / not finite.
  void validate(const std::string& context) const;
  static VolumeGeometry make(std::array<std::int64_t, 3> dims, const Eigen::Vector3d& spacing,
                             const Eigen::Vector3d& origin,
                             const Eigen::Matrix3d& directions = Eigen::Matrix3d::Identity());
};

// Flip between LPS and RAS (negate x and y) for a 4x4 matrix in one and out the other.
Eigen::Matrix4d flipLpsRas(const Eigen::Matrix4d& m);

}  // namespace repose
