// Soft labels encased in bone (pose/EncasedTissue.h): a cord in a ring of bone open at the back
// is encased and the tissue beside the ring or between two plates of bone is not, along whichever
// voxel axis the body's long axis runs; on the generated phantoms, the ICRP-labelled one on 8 mm
// slices and TotalSegmentator's example the spinal cord is encased and no other soft label; the
// rig moves it whole; near another body part it stays soft.
#include "TestPaths.h"

#include "repose/io/VolumeIO.h"
#include "repose/phantom/Phantom.h"
#include "repose/pose/EncasedTissue.h"
#include "repose/pose/PoseJob.h"
#include "repose/pose/PoseRig.h"
#include "repose/rig/LabelConvention.h"
#include "repose/volume/TissueTable.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <fstream>
#include <sstream>

using namespace repose;

namespace {

constexpr int kMuscle = 3, kBone = 7, kCord = 27, kVessel = 30, kPlate = 8;

// 2 mm voxels, n x n x m, the tube along the array axis `along` (0: i, 2: k); `toS` maps that axis
// to RAS S (else the grid is RAS-aligned). In the plane across the tube, centred: muscle within
// 40 mm, a ring of bone from 7 to 12 mm open 3 mm wide at the back (a lamina's gap), the cord
// within 5 mm; 25 mm to the right two plates of bone 12 mm apart in R with a vessel between.
Volume tubeBody(int along, bool toS) {
  const std::int64_t n = 60, m = 40;
  VolumeGeometry g;
  g.dims = along == 0 ? std::array<std::int64_t, 3>{m, n, n} : std::array<std::int64_t, 3>{n, n, m};
  Eigen::Matrix3d axes = Eigen::Matrix3d::Identity();
  if (along == 0 && toS) axes << 0, 1, 0, 0, 0, 1, 1, 0, 0;  // i -> S, j -> R, k -> A
  g.ijkToRas.topLeftCorner<3, 3>() = 2.0 * axes;
  Volume v(g, ScalarType::UInt8);
  v.setLabelMap(true);
  std::uint8_t* d = v.data<std::uint8_t>();
  for (std::int64_t c = 0; c < m; ++c)
    for (std::int64_t b = 0; b < n; ++b)
      for (std::int64_t a = 0; a < n; ++a) {
        const double x = 2.0 * (double(a) - 29.5), y = 2.0 * (double(b) - 29.5);
        const double r = std::hypot(x, y);
        std::uint8_t l = 0;
        if (r < 40) l = kMuscle;
        if (r >= 7 && r < 12 && !(y < 0 && std::fabs(x) < 1.5)) l = kBone;
        if (r < 5) l = kCord;
        if (y > -8 && y < 8 && x > 22 && x < 38) {
          if (x < 26 || x > 34)
            l = kPlate;
          else if (std::fabs(y) < 4)
            l = kVessel;
        }
        const std::int64_t at = along == 0 ? v.index(c, a, b) : v.index(a, b, c);
        d[at] = l;
      }
  return v;
}

// The labels encased at a share of 70 % of their voxels and at 5 %: the same one label, so it is
// encased in at least 70 % of its voxels and every other soft label in under 5 %.
std::vector<int> encasedAtBothShares(const Volume& organs, const std::vector<int>& rigid) {
  EncasedTissueOptions most, few;
  most.share = 0.7;
  few.share = 0.05;
  const std::vector<int> a = labelsEncasedInBone(organs, rigid, most);
  EXPECT_EQ(a, labelsEncasedInBone(organs, rigid, few));
  return a;
}

std::vector<int> rigidOf(const LabelConvention& c) {
  std::vector<int> out;
  for (const auto& [label, role] : c.roles)
    if (role.rigid) out.push_back(label);
  return out;
}

}  // namespace

TEST(EncasedTissue, ACordInARingOfBoneIsEncasedTheTissueBesideItIsNot) {
  EXPECT_EQ(labelsEncasedInBone(tubeBody(2, false), {kBone, kPlate}), std::vector<int>{kCord});
  // The plates alone wall the vessel on two sides of four.
  EXPECT_TRUE(labelsEncasedInBone(tubeBody(2, false), {kPlate}).empty());
  EXPECT_TRUE(labelsEncasedInBone(tubeBody(2, false), {}).empty());
  // A reach shorter than the ring's inner radius finds the cord's centre unwalled.
  EncasedTissueOptions near;
  near.reachMm = 2;
  EXPECT_TRUE(labelsEncasedInBone(tubeBody(2, false), {kBone, kPlate}, near).empty());
}

TEST(EncasedTissue, TheLongAxisIsTheVoxelAxisNearestS) {
  // The tube along i, and i is S: the same cord.
  EXPECT_EQ(labelsEncasedInBone(tubeBody(0, true), {kBone, kPlate}), std::vector<int>{kCord});
  // The tube along i but i is R: across the body, so the cord is not a canal's content.
  EXPECT_TRUE(labelsEncasedInBone(tubeBody(0, false), {kBone, kPlate}).empty());
}

TEST(EncasedTissue, OnlyTheSpinalCordIsEncasedInPhantomsAndARealSegmentation) {
  {
    PhantomOptions o;
    o.spacingMm = Eigen::Vector3d(1.8, 1.8, 4.8);
    o.armsResting = true;
    const auto [organs, parts] = Phantom(o).makeVolumes();
    const std::vector<int> rigid = rigidLabelsOf(phantomTissueTable());
    const std::vector<int> encased = encasedAtBothShares(organs, rigid);
    EXPECT_EQ(labelsEncasedInBone(organs, rigid), encased);
    ASSERT_EQ(encased.size(), 1u);
    EXPECT_EQ(organs.labels().find(encased[0])->name, "spinal_cord");
    // The rig moves it whole (as a piece in each part it lies in), unless organs bend.
    RigSettings s;
    s.rigidLabels = rigid;
    const std::vector<int> whole = labelsMovingWhole(organs, parts, s);
    EXPECT_TRUE(std::count(whole.begin(), whole.end(), encased[0]));
    s.wholeOrgans = false;
    EXPECT_EQ(labelsMovingWhole(organs, parts, s), rigid);
  }
  {
    PhantomOptions o;
    o.spacingMm = Eigen::Vector3d(2.137, 2.137, 8);
    o.armsResting = true;
    o.labels = PhantomLabelling::Icrp110;
    const auto [organs, parts] = Phantom(o).makeVolumes();
    const LabelConvention c = labelConvention(organs, "icrp110", "G");
    EXPECT_EQ(encasedAtBothShares(organs, rigidOf(c)), std::vector<int>{126});  // spinal cord
  }
  {
    // TotalSegmentator's example (3 mm, the abdomen and lower chest), its names from the TSV.
    Volume organs = readVolume(test::dataPath("totalsegmentator/example_seg.nii.gz"));
    std::ifstream tsv(test::dataPath("totalsegmentator/example_seg_labels.tsv"));
    std::string line;
    std::getline(tsv, line);
    int cord = 0;
    while (std::getline(tsv, line)) {
      std::istringstream row(line);
      Label l;
      std::string value;
      std::getline(row, value, '\t');
      std::getline(row, l.name, '\t');
      l.value = std::stoi(value);
      organs.labels().set(l);
      if (l.name == "spinal_cord") cord = l.value;
    }
    ASSERT_GT(cord, 0);
    const LabelConvention c = labelConvention(organs, "totalsegmentator", "example_seg.nii.gz");
    ASSERT_GE(rigidOf(c).size(), 10u);  // its vertebrae, ribs, hips and sacrum
    EXPECT_EQ(encasedAtBothShares(organs, rigidOf(c)), std::vector<int>{cord});
  }
}

TEST(EncasedTissue, NearAnotherBodyPartTheEncasedLabelStaysSoft) {
  const Volume organs = tubeBody(2, false);
  Volume parts(organs.geometry(), ScalarType::UInt8);
  std::uint8_t* p = parts.data<std::uint8_t>();
  const std::uint8_t* g = organs.data<std::uint8_t>();
  const auto& d = organs.dims();
  for (std::int64_t at = 0; at < organs.numVoxels(); ++at)
    if (g[at]) p[at] = at / (d[0] * d[1]) < 20 ? 1 : 2;  // the parts meet between k 19 and 20
  std::vector<std::uint16_t> piece(std::size_t(organs.numVoxels()));
  for (std::int64_t at = 0; at < organs.numVoxels(); ++at)
    piece[std::size_t(at)] = g[at] == kCord || g[at] == kBone ? g[at] : 0;
  softenEncasedNearOtherParts(organs, parts, {kCord}, 10, piece.data());
  for (std::int64_t at = 0; at < organs.numVoxels(); ++at) {
    const std::int64_t k = at / (d[0] * d[1]);
    // 10 mm is 5 voxels: slices 15-19 see part 2 at k 20, slices 20-24 part 1 at k 19.
    if (g[at] == kCord)
      EXPECT_EQ(piece[std::size_t(at)], k >= 15 && k <= 24 ? 0 : kCord) << "k " << k;
    else
      EXPECT_EQ(piece[std::size_t(at)], g[at] == kBone ? kBone : 0);  // the bone is untouched
  }
}
