// A procedural whole-body mannequin for tests and benchmarks: an organ map G, a body-part map S
// and a skeleton of named joints in RAS mm, all defined analytically so tests can pose it exactly.
#pragma once

#include "repose/util/Progress.h"
#include "repose/volume/Volume.h"

#include <Eigen/Core>
#include <memory>
#include <string>
#include <vector>

namespace repose {

struct PhantomOptions {
  double voxelMm = 2.0;       // isotropic voxel size; 1 mm gives ~160M voxels (1.3 m child)
  bool armsTouching = false;  // hands pressed against the hips (the limb-separation case)
  double marginMm = 10.0;     // empty border around the body
  int threads = 0;            // 0: all cores
};

struct Joint {
  std::string name;    // e.g. "elbow_left"
  std::string parent;  // empty for the root ("pelvis")
  Eigen::Vector3d ras = Eigen::Vector3d::Zero();
};

// Body-part labels of S (stable numbers; tests and pose files rely on them).
enum PhantomPart : std::uint8_t {
  kPartBackground = 0,
  kPartHead = 1,
  kPartTorso = 2,
  kPartUpperArmLeft = 3,
  kPartForearmLeft = 4,
  kPartHandLeft = 5,
  kPartUpperArmRight = 6,
  kPartForearmRight = 7,
  kPartHandRight = 8,
  kPartThighLeft = 9,
  kPartShankLeft = 10,
  kPartFootLeft = 11,
  kPartThighRight = 12,
  kPartShankRight = 13,
  kPartFootRight = 14,
};

class Phantom {
 public:
  explicit Phantom(const PhantomOptions& options = {});
  ~Phantom();

  const PhantomOptions& options() const;
  // The grid G and S share: RAS-aligned axes, voxelMm spacing, body centred with the margin.
  const VolumeGeometry& geometry() const;
  const std::vector<Joint>& joints() const;
  const Joint& joint(const std::string& name) const;  // throws repose::Error if unknown
  LabelTable organLabels() const;  // >= 15 tissues: skin, fat, muscle, bones, organs...
  LabelTable partLabels() const;   // the PhantomPart values with names

  // Organ label and body part at a RAS point (0, 0 outside the body).
  void classify(const Eigen::Vector3d& ras, std::uint8_t& organ, std::uint8_t& part) const;
  // Fills k-slices [k0, k1) of both maps (dims[0]*dims[1]*(k1-k0) voxels each), in parallel.
  void fillSlices(std::int64_t k0, std::int64_t k1, std::uint8_t* organ, std::uint8_t* part) const;

  // In-core maps (G then S), with label tables; for tests and small sizes.
  std::pair<Volume, Volume> makeVolumes(const ProgressFn& progress = {}) const;
  // Skeleton as JSON text: {"units":"mm","space":"RAS","joints":[{"name","parent","ras"}...]}.
  std::string skeletonJson() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

// A CT-like image of the phantom's organ map G (int16, Hounsfield units): each tissue at a
// typical value (air -1000, lung -820, fat -100, soft tissue 5..60, bone 550..1100) plus a
// +-12 HU noise that depends only on the voxel index. What the slice views show under the labels
// and what `--image` paths pose alongside G.
Volume syntheticCT(const Volume& organs);
// The same for `count` voxels of G starting at voxel index `firstVoxel` (a slab).
void syntheticCTVoxels(const std::uint8_t* organs, std::int16_t* ct, std::int64_t count,
                       std::int64_t firstVoxel);
// The value a label of G has in the synthetic CT before noise (0 for an unknown label).
std::int16_t phantomHounsfield(int organLabel);

struct PhantomFiles {
  std::string organs, parts, skeleton;
  std::string image;  // <prefix>CT<ext> when asked for, else empty
};

// Streams G and S to outDir (as <prefix>G<ext>, <prefix>S<ext>, <prefix>skeleton.json) slab by
// slab with bounded memory, so a 1G-voxel phantom never needs to fit in memory. ext is ".nii.gz"
// or ".nii". Outputs are atomic.
// With `image`, also <prefix>CT<ext>: the syntheticCT of G, streamed the same way.
PhantomFiles writePhantom(const Phantom& phantom, const std::string& outDir,
                          const std::string& ext = ".nii.gz", const ProgressFn& progress = {},
                          const std::string& prefix = "", bool image = false);

}  // namespace repose
