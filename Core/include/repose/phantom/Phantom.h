// A procedural whole-body mannequin for tests and benchmarks: an organ map G, a body-part map S
// and a skeleton of named joints in RAS mm, all defined analytically so tests can pose it exactly.
#pragma once

#include "repose/skeleton/Skeleton.h"
#include "repose/util/Progress.h"
#include "repose/volume/Volume.h"

#include <Eigen/Core>
#include <memory>
#include <string>
#include <vector>

namespace repose {

// How G's voxels are numbered: the phantom's own labels (with names in the file), or the organ
// IDs of the ICRP 110 adult reference phantoms (bones split by region and tissue but not by side,
// skin, muscle, adipose and vessels split by body region) on ICRP's array order (columns from
// the body's right to its left, rows front to back, slices feet to head) and without a label
// table, as a user's converted ICRP file arrives. Or a coarse map as most dosimetry users have
// one (issue 65): 1 body (every soft tissue), 2 skeleton (every bone, marrow included), 3 brain,
// 4 lungs, 5 liver, without a label table.
enum class PhantomLabelling { Phantom, Icrp110, Coarse };

struct PhantomOptions {
  double voxelMm = 2.0;  // isotropic voxel size; 1 mm gives ~160M voxels (1.3 m child)
  // Voxel size per array axis (columns, rows, slices), e.g. 1.8 x 1.8 x 4.8 mm for thick
  // slices; zero: voxelMm on every axis.
  Eigen::Vector3d spacingMm = Eigen::Vector3d::Zero();
  bool armsTouching = false;  // hands pressed against the hips (the limb-separation case)
  // Real anatomy's contacts and scales: the arms rest against the trunk along their length, the
  // hands on the thighs, the thighs touch; the long bones are cortical shells around marrow and
  // blood vessels of a few millimetres run through the limbs (labels 28-34).
  bool armsResting = false;
  // With armsResting, the near contacts of real reference phantoms instead of contacts: each hand
  // stands handGapMm off its thigh and each forearm forearmGapMm off the trunk and hip (the upper
  // arm still rests on the chest wall). Across these gaps the body's surfaces do not blend, so
  // the air between stays air however thin. Zero: the hands and forearms press on the body.
  double handGapMm = 0, forearmGapMm = 0;
  // With armsResting, the diameter of every limb vessel (the arms' and legs' arteries, through
  // the axilla, the elbow's crease, the groin and the back of the knee) instead of their
  // anatomical 4-10 mm: about one voxel on a reference phantom's grid, where a crease squeezes
  // them hardest (issue 64). Zero: anatomical.
  double limbVesselMm = 0;
  // With armsResting, the clavicles' medial ends meet over the manubrium instead of standing a
  // joint beside it, as on reference phantoms whose clavicles reach the midline: the two shoulder
  // girdles a rig makes then touch across the sternum, and both arms raised pull them apart
  // there (a contact the cage must cut, issue 64).
  bool girdlesTouching = false;
  PhantomLabelling labels = PhantomLabelling::Phantom;
  double marginMm = 10.0;  // empty border around the body
  int threads = 0;         // 0: all cores
  Eigen::Vector3d spacing() const {
    return spacingMm.isZero() ? Eigen::Vector3d::Constant(voxelMm) : spacingMm;
  }
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
  // The joints with their anatomical axes (pose files name them), the body parts each connects
  // and how far from its centre they meet.
  Skeleton skeleton() const;
  // skeleton.json (docs/FORMATS.md): the Skeleton and how the phantom was made.
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
