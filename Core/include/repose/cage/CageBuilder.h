// Builds the control cage from a segmentation: dilation by an exact distance, optional inset
// separation of two body parts inside a region, restricted Delaunay surface, QEM simplification.
#pragma once

#include "repose/cage/TriangleMesh.h"
#include "repose/util/Progress.h"
#include "repose/util/Error.h"
#include "repose/volume/Volume.h"

#include <string>
#include <vector>

namespace repose {

// A region of space in RAS mm: an axis-aligned box [min, max], a sphere (centre, radius),
// everything outside a sphere (a contact away from the joint at the sphere's centre), or all of
// space.
struct Region {
  enum class Shape { Box, Sphere, OutsideSphere, Everywhere } shape = Shape::Box;
  Eigen::Vector3d a = Eigen::Vector3d::Zero();  // box min, or sphere centre
  Eigen::Vector3d b = Eigen::Vector3d::Zero();  // box max; b.x() is the sphere radius
  bool contains(const Eigen::Vector3d& p) const;
  // "box:x0,y0,z0,x1,y1,z1", "sphere:cx,cy,cz,r", "outside:cx,cy,cz,r" or "everywhere";
  // throws repose::Error on bad text.
  static Region parse(const std::string& text);
};

// Separate body parts labelA and labelB of S inside `region`: the cage passes between them there.
struct LimbSeparation {
  int labelA = 0, labelB = 0;
  Region region;
};

struct CageOptions {
  int targetVertices = 300;   // 50..2000
  double dilateMm = 10.0;     // exact Euclidean dilation of the body
  double workingVoxelMm = 0;  // 0: chosen from the dilation and the input spacing
  std::vector<LimbSeparation> separations;
  int threads = 0;
  ProgressFn progress;
};

struct CageReport {
  int vertices = 0, faces = 0;
  int denseVertices = 0;  // restricted Delaunay surface before simplification
  double workingVoxelMm = 0;
  std::string
      simplification;      // quadric policy that gave the cage: garland-heckbert or lindstrom-turk
  int frozenVertices = 0;  // dense vertices kept to undo a self-intersecting simplification
  bool closed = false, manifold = false, outward = false, selfIntersectionFree = false;
  std::int64_t bodyVoxels = 0;      // voxels of S != 0
  std::int64_t enclosedVoxels = 0;  // of those, inside the cage
  double enclosedFraction() const { return bodyVoxels ? double(enclosedVoxels) / bodyVoxels : 0; }
  bool valid() const { return closed && manifold && outward && selfIntersectionFree; }
};

struct Cage {
  TriangleMesh mesh;  // RAS mm, outward
  CageReport report;
};

// "300 vertices, 10 mm": how messages and reports name a cage's setting.
std::string describeCageSetting(int vertices, double dilateMm);

// A cage that failed its checks (closed, manifold, outward, no self-intersection): `failed` says
// which, e.g. "self-intersecting" (CageLadder.h tries other settings on this one only).
class CageCheckError : public Error {
 public:
  CageCheckError(const std::string& message, std::string failedChecks)
      : Error(message), failed(std::move(failedChecks)) {}
  std::string failed;
};

// parts: S (body-part labels, or any label map: non-zero is body). Throws repose::Error naming
// the problem for an empty mask, absent labels or a region that selects nothing, and
// CageCheckError for a cage that fails its checks.
Cage buildCage(const Volume& parts, const CageOptions& options = {});

}  // namespace repose
