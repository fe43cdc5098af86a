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
  // The head and the neck are divided by the neck plane (BodyModel::neck*), not by distance.
  bool neckSplit = false;
  // The smooth unions the segment takes part in (bits: kBlendMain, kBlendArmLeft,
  // kBlendArmRight); the body is the plain minimum of them. A forearm and hand held off the body
  // (PhantomOptions::handGapMm) blend only with their own arm, so a gap of a few millimetres
  // stays open instead of being bridged by the blend.
  std::uint8_t blends = 1;
  Box box;  // bounds grown by the blend radius: beyond it the segment cannot change a voxel
};

constexpr std::uint8_t kBlendMain = 1, kBlendArmLeft = 2, kBlendArmRight = 4;

// Distances to the body as the smooth unions of Segment::blends combine them.
struct BlendedDistance {
  double acc[3] = {1e300, 1e300, 1e300};
  void add(const Segment& s, double d, double blendMm);
  double value() const { return std::min({acc[0], acc[1], acc[2]}); }
};

enum class StructureKind { Cone, Ellipsoid, Shell, Ribs };

// A bone or organ, applied only inside its own body part and below the skin and fat. A limb bone
// claims its voxels for its own part wherever they are (its articular end reaches across the
// joint plane, as a humeral head does), and a vessel runs through any part.
struct Structure {
  StructureKind kind = StructureKind::Ellipsoid;
  std::uint8_t label = 0, part = 0;
  bool claimsPart = false;  // a limb bone: its voxels are its part's
  bool anyPart = false;     // a vessel: applied in every part (its label follows the region)
  std::vector<std::pair<Eigen::Vector3d, double>> holes;  // balls cut out (a joint's socket)
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
  // Joint -> the direction of its distal segment (for the axes), the body parts it connects and
  // the radius within which they meet.
  struct JointInfo {
    JointKind kind;
    int side = 0;  // +1 right, -1 left
    Eigen::Vector3d distal = Eigen::Vector3d::UnitZ(), palmar = Eigen::Vector3d::Zero();
    std::uint8_t proximal = 0, distalPart = 0;
    double radiusMm = 0;
  };
  std::vector<std::pair<std::string, JointInfo>> jointInfo;
  Eigen::Vector3d neckCentre = Eigen::Vector3d::Zero(), neckNormal = Eigen::Vector3d::UnitZ();
  Eigen::Vector3d spacing = Eigen::Vector3d::Constant(2);  // the grid's, for the skin layer
  std::vector<Segment> segments;
  std::vector<Structure> structures;  // first match wins
  double blendMm = 10;                // smooth-union radius between segments
  double skinMm = 2;
  std::array<double, 15> fatMm{};  // subcutaneous fat thickness per part
  Box bounds;                      // of the body surface
};

BodyModel buildBody(const PhantomOptions& options);

}  // namespace repose::phantom
