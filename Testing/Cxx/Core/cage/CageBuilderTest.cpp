// Cage building on the phantom and on a real TotalSegmentator segmentation: valid cages near the
// requested size that enclose the body, an inset that passes between a hand and the hip it is
// glued to, and one-line errors for inputs that cannot give a cage.
#include "TestPaths.h"

#include "repose/cage/CageBuilder.h"
#include "repose/cage/WindingNumber.h"
#include "repose/io/VolumeIO.h"
#include "repose/phantom/Phantom.h"
#include "repose/util/Error.h"

#include <gtest/gtest.h>

using namespace repose;
using namespace repose::test;

namespace {

const Volume& phantomParts(bool armsTouching) {
  static std::map<bool, Volume> cache;
  auto it = cache.find(armsTouching);
  if (it != cache.end()) return it->second;
  PhantomOptions o;
  o.voxelMm = 4;
  o.armsTouching = armsTouching;
  return cache.emplace(armsTouching, Phantom(o).makeVolumes().second).first->second;
}

// Centres of voxels of label a face-adjacent to label b (and the reverse) inside the region.
Eigen::MatrixX3d interfaceVoxels(const Volume& s, int a, int b, const Region& region) {
  std::vector<Eigen::Vector3d> out;
  const auto& d = s.dims();
  const auto* v = s.data<std::uint8_t>();
  for (std::int64_t k = 1; k + 1 < d[2]; ++k)
    for (std::int64_t j = 1; j + 1 < d[1]; ++j)
      for (std::int64_t i = 1; i + 1 < d[0]; ++i) {
        const int l = v[s.index(i, j, k)];
        if (l != a && l != b) continue;
        const int other = l == a ? b : a;
        const std::int64_t n[6] = {s.index(i - 1, j, k), s.index(i + 1, j, k),
                                   s.index(i, j - 1, k), s.index(i, j + 1, k),
                                   s.index(i, j, k - 1), s.index(i, j, k + 1)};
        bool touches = false;
        for (std::int64_t x : n) touches = touches || v[x] == other;
        const Eigen::Vector3d p = s.geometry().voxelToRas(i, j, k);
        if (touches && region.contains(p)) out.push_back(p);
      }
  Eigen::MatrixX3d m(out.size(), 3);
  for (std::size_t r = 0; r < out.size(); ++r) m.row(r) = out[r];
  return m;
}

}  // namespace

TEST(CageBuilder, PhantomCageIsValidNearTheTargetSizeAndEnclosesTheBody) {
  for (int target : {100, 300}) {
    CageOptions o;
    o.targetVertices = target;
    const Cage cage = buildCage(phantomParts(false), o);
    EXPECT_TRUE(cage.report.valid());
    EXPECT_NEAR(cage.report.vertices, target, 0.1 * target);
    // Closed orientable surface: F = 2V - 4 + 4g. The dilated arms fuse with the hips, so each
    // arm leaves a loop: genus 2 is expected, not 0.
    const int genus4 = cage.report.faces - 2 * cage.report.vertices + 4;
    EXPECT_EQ(genus4 % 4, 0);
    EXPECT_LE(genus4 / 4, 2);
    EXPECT_GE(cage.report.enclosedFraction(), 0.95);
  }
}

TEST(CageBuilder, InsetSeparatesAHandGluedToTheHip) {
  const Volume& parts = phantomParts(true);
  Phantom phantom([] {
    PhantomOptions o;
    o.voxelMm = 4;
    o.armsTouching = true;
    return o;
  }());
  const Eigen::Vector3d hand =
      (phantom.joint("wrist_left").ras + phantom.joint("hand_tip_left").ras) / 2;
  Region region;
  region.shape = Region::Shape::Sphere;
  region.a = hand;
  region.b = Eigen::Vector3d(110, 0, 0);
  const Eigen::MatrixX3d contact = interfaceVoxels(parts, kPartHandLeft, kPartThighLeft, region);
  ASSERT_GT(contact.rows(), 4) << "the arms-touching phantom must press the hand on the thigh";

  CageOptions glued;
  const Cage plain = buildCage(parts, glued);
  const Eigen::VectorXd before = windingNumbers(plain.mesh, contact);
  EXPECT_GT((before.array() > 0.5).count(), 0.9 * contact.rows())
      << "without separation the cage wraps hand and hip together";

  CageOptions separated;
  separated.separations.push_back({kPartHandLeft, kPartThighLeft, region});
  const Cage inset = buildCage(parts, separated);
  EXPECT_TRUE(inset.report.valid());
  const Eigen::VectorXd after = windingNumbers(inset.mesh, contact);
  EXPECT_LT(after.maxCoeff(), 0.5) << "interface voxels must be outside the inset cage";
  EXPECT_GE(inset.report.enclosedFraction(), 0.95);
}

TEST(CageBuilder, RealSegmentationTouchingTheBorderIsPaddedNotRefused) {
  const Volume seg = readVolume(dataPath("totalsegmentator/example_seg.nii.gz"));
  const Cage cage = buildCage(seg, {});
  EXPECT_TRUE(cage.report.valid());
  EXPECT_GE(cage.report.enclosedFraction(), 0.95);
  // Padding: the cage extends beyond the volume where the body touches its border.
  const auto [lo, hi] = seg.geometry().rasBounds();
  const Eigen::Vector3d cageLo = cage.mesh.vertices.colwise().minCoeff(),
                        cageHi = cage.mesh.vertices.colwise().maxCoeff();
  EXPECT_TRUE((cageLo.array() < lo.array()).any() || (cageHi.array() > hi.array()).any());
}

TEST(CageBuilder, BadInputsGiveOneLineErrors) {
  auto expectError = [](const Volume& v, const CageOptions& o, const std::string& fragment) {
    try {
      buildCage(v, o);
      FAIL() << "no error, expected: " << fragment;
    } catch (const Error& e) {
      EXPECT_NE(std::string(e.what()).find(fragment), std::string::npos) << e.what();
      EXPECT_EQ(std::string(e.what()).find('\n'), std::string::npos);
    }
  };
  Volume empty(VolumeGeometry::make({20, 20, 20}, {2, 2, 2}, {0, 0, 0}), ScalarType::UInt8);
  expectError(empty, {}, "empty");
  const Volume& parts = phantomParts(false);
  CageOptions absent;
  absent.separations.push_back({kPartHandLeft, 99, Region::parse("sphere:0,0,0,50")});
  expectError(parts, absent, "label 99 is not present");
  CageOptions nowhere;
  nowhere.separations.push_back(
      {kPartHandLeft, kPartThighLeft, Region::parse("box:5000,5000,5000,5100,5100,5100")});
  expectError(parts, nowhere, "selects no voxel");
  CageOptions tooMany;
  tooMany.targetVertices = 5000;
  expectError(parts, tooMany, "between 50 and 2000");
  Volume image(VolumeGeometry::make({4, 4, 4}, {1, 1, 1}, {0, 0, 0}), ScalarType::Float32);
  expectError(image, {}, "label map");
}

TEST(Region, ParsesBoxesAndSpheresAndRefusesNonsense) {
  const Region box = Region::parse("box:10,0,0,-10,5,5");
  EXPECT_TRUE(box.contains({0, 1, 1}));
  EXPECT_FALSE(box.contains({0, 6, 1}));
  const Region sphere = Region::parse("sphere:1,2,3,4");
  EXPECT_TRUE(sphere.contains({1, 2, 6.9}));
  EXPECT_FALSE(sphere.contains({1, 2, 7.1}));
  for (const char* bad :
       {"box:1,2,3", "sphere:0,0,0,-1", "cube:1,2,3,4,5,6", "box:a,b,c,d,e,f", "sphere"})
    EXPECT_THROW(Region::parse(bad), Error) << bad;
}
