// Generated volumes for tests: random label maps and images on oblique, anisotropic grids, and
// voxel-by-voxel comparison helpers.
#pragma once

#include "repose/volume/Volume.h"

#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <cstring>
#include <random>

namespace repose::test {

// An oblique, anisotropic grid (1.3 x 1.3 x 7.2 mm like the seed's MRI) so orientation bugs show.
inline VolumeGeometry obliqueGeometry(std::array<std::int64_t, 3> dims = {17, 11, 7}) {
  const Eigen::Matrix3d rot =
      Eigen::AngleAxisd(0.4, Eigen::Vector3d(0.2, -1, 0.5).normalized()).toRotationMatrix();
  return VolumeGeometry::make(dims, {1.3, 1.3, 7.2}, {-120.5, 33.25, -804.5}, rot);
}

// Voxels of any type filled with values of that type's range (labels 0..maxLabel for integers).
inline Volume randomVolume(ScalarType type, const VolumeGeometry& g, int maxLabel, unsigned seed,
                           int layers = 1) {
  Volume v(g, type, layers);
  std::mt19937 rng(seed);
  dispatchScalar(type, [&](auto* tag) {
    using T = std::remove_pointer_t<decltype(tag)>;
    for (int l = 0; l < layers; ++l) {
      T* d = v.data<T>(l);
      for (std::int64_t i = 0; i < v.numVoxels(); ++i) {
        if constexpr (std::is_floating_point_v<T>)
          d[i] = std::uniform_real_distribution<float>(-1000, 3000)(rng);
        else
          d[i] = static_cast<T>(std::uniform_int_distribution<int>(0, maxLabel)(rng));
      }
    }
  });
  return v;
}

inline bool sameVoxels(const Volume& a, const Volume& b) {
  return a.scalarType() == b.scalarType() && a.dims() == b.dims() && a.layers() == b.layers() &&
         a.bytes() == b.bytes();
}

inline double matrixDifference(const Eigen::Matrix4d& a, const Eigen::Matrix4d& b) {
  return (a - b).cwiseAbs().maxCoeff();
}

}  // namespace repose::test
