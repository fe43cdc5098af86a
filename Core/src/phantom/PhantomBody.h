// The phantom's anatomy as data: the skeleton, the body-surface primitives of each segment and
// the internal structures (bones, organs) in priority order. Built once per PhantomOptions.
#pragma once

#include "PhantomShapes.h"

#include "repose/phantom/Phantom.h"

#include <array>
#include <vector>

namespace repose::phantom {

// One primitive of the body surface, owned by a body part.
struct Segment {
  RoundCone shape;
  std::uint8_t part = 0;
  // A limb root (upper arm, thigh) claims voxels only distal of the plane through its proximal
  // joint, so its big proximal cap does not swallow the shoulder or the hip into the limb; the
  // body stays the union of all primitives either way.
  // Beyond the plane the primitive's tissue belongs to cutOwner (the torso, or the foot for the
  // shank's distal cap).
  bool cut = false;
  std::uint8_t cutOwner = 0;
  Eigen::Vector3d cutPoint = Eigen::Vector3d::Zero(), cutNormal = Eigen::Vector3d::UnitZ();
  Box box;  // bounds grown by the blend radius: beyond it the segment cannot change a voxel
};

enum class StructureKind { Cone, Ellipsoid, Shell, Ribs };

// A bone or organ, applied only inside its own body part and below the skin and fat.
struct Structure {
  StructureKind kind = StructureKind::Ellipsoid;
  std::uint8_t label = 0, part = 0;
  RoundCone cone;
  Ellipsoid outer, inner;              // Ellipsoid uses outer; Shell is outer minus inner
  double zmin = -1e300, zmax = 1e300;  // clips the structure to a height range
  double innerZmin = -1e300;           // Shell: below this the inner part is bone (skull base)
  double depthMin = 0, depthMax = 0;   // Ribs: band of depth under the surface
  double period = 1, thickness = 0, slope = 0, gapX = 0;  // Ribs: spacing and midline gaps
  Box box;

  bool contains(const Eigen::Vector3d& p, double depth) const;
};

struct BodyModel {
  std::vector<Joint> joints;
  std::vector<Segment> segments;
  std::vector<Structure> structures;  // first match wins
  double blendMm = 10;                // smooth-union radius between segments
  double skinMm = 2;
  std::array<double, 15> fatMm{};  // subcutaneous fat thickness per part
  Box bounds;                      // of the body surface
};

BodyModel buildBody(const PhantomOptions& options);

}  // namespace repose::phantom
