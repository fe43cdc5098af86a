// The rig's stages and what they pass each other: bones found in G (by kind and side), the body's
// frame, the joints fitted to the bones' articular ends, and the part assignment.
#pragma once

#include "repose/skeleton/Skeleton.h"
#include "repose/rig/LabelConvention.h"
#include "repose/volume/Volume.h"

#include <Eigen/Core>

#include <array>
#include <cstdint>
#include <map>
#include <optional>
#include <string>
#include <vector>

namespace repose::rig {

using V = Eigen::Vector3d;

// A voxel grid's index <-> RAS arithmetic (G's geometry).
struct Grid {
  const VolumeGeometry* geometry = nullptr;
  std::array<std::int64_t, 3> dims{};
  V spacing = V::Ones();
  explicit Grid(const VolumeGeometry& g);
  V ras(std::int64_t index) const;
  std::int64_t count() const { return dims[0] * dims[1] * dims[2]; }
};

// Every voxel of one bone on one side (side 0: the axial skeleton), with its principal axis.
struct Bone {
  BoneKind kind = BoneKind::None;
  int side = 0;
  std::vector<std::int64_t> voxels;
  V centroid = V::Zero();
  V axis = V::UnitZ();           // principal direction (unit), sign arbitrary until oriented
  double length = 0;             // extent along the axis (mm)
  std::vector<V> boundary;       // centres of the bone's outer voxel faces: its surface
  std::vector<double> faceSize;  // per boundary point: the voxel's size along the face's normal
  V extreme(const V& towards) const;  // the boundary point furthest along `towards`
};

struct BodyFrame {
  V superior = V::UnitZ(), anterior = V::UnitY();
  V right() const { return anterior.cross(superior).normalized(); }
  double midlineX = 0;  // RAS x of the body's midline
  std::vector<std::string> warnings;
};

// G's bones by kind and side, sides from the labels or, for bones whose labels do not tell
// (ICRP 110's humeri are one ID for both arms), from each connected piece's side of the midline.
struct Bones {
  std::map<std::pair<BoneKind, int>, Bone> byKind;  // (kind, side)
  BodyFrame frame;
  double voxelMm = 1;  // the grid's largest spacing: the fits' resolution
  // The spine's voxels whose labels name the sacrum (ICRP 110's, TotalSegmentator's): where the
  // lumbosacral joint is, when known.
  std::vector<V> sacrum;  // their centres, RAS
  // How many pieces a skeleton given as one label was split from (0: the bones were labelled).
  int split = 0;
  std::vector<std::string> splitNotes;
  const Bone* find(BoneKind kind, int side) const;
};
Bones findBones(const Volume& organs, const LabelConvention& convention, const Grid& grid,
                const std::string& source);

// A skeleton given as one label (BoneKind::Skeleton) split into bones by geometry
// (RigSkeletonSplit.cpp): its voxels by (kind, side). Throws repose::Error, one line naming
// `source`, when it cannot be split (no piece across the midline, two bones joined across a
// joint).
struct SkeletonSplit {
  std::map<std::pair<BoneKind, int>, std::vector<std::int64_t>> bones;
  int pieces = 0;
  std::vector<std::string> notes;
};
SkeletonSplit splitSkeleton(const std::vector<std::int64_t>& voxels, const Grid& grid,
                            const std::string& source);

// One fitted joint: centre, how it was found, and the directions its part planes and axes use.
struct FittedJoint {
  std::string name;
  JointKind kind = JointKind::Neck;
  int side = 0;
  V centre = V::Zero();
  V distal = V::UnitZ();       // direction of the distal segment, away from the joint
  V planeNormal = V::UnitZ();  // the cut between the two parts, towards the distal part
  std::optional<V> flexion;    // from the condyles, when they say it
  V palmar = V::Zero();
  std::string method;
  double rms = -1;
  std::array<int, 2> parts{0, 0};  // labels of S: proximal, distal
  // The two parts meet all around the distal one, not across a plane (the shoulder girdle on the
  // trunk, the pelvis under the lumbar spine): radius_mm covers their whole interface.
  bool wholeInterface = false;
};
// Fits the joints the bones allow; `missing` gets one line per joint that could not be found.
std::vector<FittedJoint> fitJoints(const Bones& bones, std::vector<std::string>& missing);

// The body-part labels of S (the phantom's numbering, then the girdles and the pelvis) and their
// names.
constexpr int kPartGirdleLeft = 15, kPartGirdleRight = 16, kPartPelvis = 17;
int partOf(BoneKind kind, int side);
LabelTable rigPartLabels();

// S: bones keep their own part; soft tissue flows from the bones through the body (a watershed
// on the distance to the body's surface, so it crosses the narrow contact between an arm and the
// trunk last), is held to its region where the labels say it (ICRP's arm, leg, trunk tissue),
// and each limb is cut into segments by its joints' planes.
struct PartStats {
  std::int64_t unreached = 0;  // body voxels no bone's flood reached (taken as torso)
};
// `body` (optional): the body's voxels where G labels no tissue (bodyOutline), which any flood
// may cross.
Volume assignParts(const Volume& organs, const LabelConvention& convention, const Bones& bones,
                   const std::vector<FittedJoint>& joints, const Grid& grid, int threads,
                   PartStats& stats, const std::vector<std::uint8_t>* body = nullptr);

// The parts of the trunk that move of their own (after assignParts): the pelvis below the
// lumbosacral joint's plane, and each shoulder girdle (clavicle, scapula and the tissue around
// them), where the joints were fitted.
void assignGirdlesAndPelvis(Volume& parts, const Bones& bones,
                            const std::vector<FittedJoint>& joints, const Grid& grid, int threads);

// The body on G's grid from the scan G was segmented from (any grid over the same place): a CT
// above -300 HU (else the image above its Otsu threshold), its connected pieces that hold some of
// G's labels (not the table), with G's labels, and the holes of each slice filled (lungs, bowel
// gas). `how` says so, with the body
// found beyond G's labels. Throws repose::Error when the image covers less than half of G.
std::vector<std::uint8_t> bodyOutline(const Volume& image, const Volume& organs, const Grid& grid,
                                      std::string& how);

// The wrist and the ankle where the map has no hand or foot bones (RigOutlineJoints.cpp), from
// the outline of the forearm's and shank's parts (after assignParts): each joint is added with
// its method, the part beyond its plane becomes the hand or the foot (bones keep their part), and
// its line leaves `missing`.
void fitDistalJointsFromOutline(Volume& parts, const Volume& organs,
                                const LabelConvention& convention, const Bones& bones,
                                std::vector<FittedJoint>& joints, const Grid& grid,
                                std::vector<std::string>& missing);

// How far from its centre each joint's two parts meet across its plane (radius_mm).
double jointRadius(const Volume& parts, const FittedJoint& joint, const Grid& grid);

}  // namespace repose::rig
