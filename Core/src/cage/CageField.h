// The implicit function whose zero level set is the cage surface, sampled on a padded working
// grid: distance to the body minus the dilation, raised along the bisector of separated parts.
#pragma once

#include "repose/cage/CageBuilder.h"

#include <vector>

namespace repose::cage {

struct CageField {
  VolumeGeometry grid;          // padded working grid (RAS)
  std::vector<float> value;     // mm, negative inside the cage-to-be
  Eigen::Vector3d insidePoint;  // RAS point with a clearly negative value
  // Trilinear value at a point given in grid millimetres (i*sx, j*sy, k*sz), +dilation outside.
  double at(const Eigen::Vector3d& gridMm) const;
  Eigen::Vector3d spacing() const { return grid.spacing(); }
};

CageField makeCageField(const Volume& parts, const CageOptions& options, std::int64_t& bodyVoxels);

}  // namespace repose::cage
