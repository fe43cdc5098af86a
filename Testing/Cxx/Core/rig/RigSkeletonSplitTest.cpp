// A coarse map (issue 65): the generated phantom with every bone in one label and every soft
// tissue in another (PhantomLabelling::Coarse: 1 body, 2 skeleton, 3 brain, 4 lungs, 5 liver, no
// names), rigged with no option. The rig recognises it by its shapes, splits the skeleton into
// bones by geometry (rig/RigSkeletonSplit.cpp) and fits the same joints as the full-label rig of
// the same body, each within 10 mm, on isotropic and thick-slice grids: the ICRP adult male's 8 mm
// slices (where the elbows and knees join and the skull breaks into pieces), the girdles touching
// across the sternum, arms held away from the trunk, and a spine the discs part into vertebrae. A
// CSV may name the kinds instead; a map with a skeleton and no body is refused in one line.
#include "repose/phantom/Phantom.h"
#include "repose/rig/Rig.h"
#include "repose/util/Error.h"

#include "TestPaths.h"

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <cmath>
#include <fstream>
#include <string>

using namespace repose;

namespace {

struct Body {
  const char* name;
  Eigen::Vector3d spacing;
  bool armsResting;
  double handGapMm;
  bool girdlesTouching;
  bool discs = false;  // the spine parted into vertebrae at discs, the sacrum from the lumbar spine
};

void PrintTo(const Body& b, std::ostream* os) {
  *os << b.name;
}

PhantomOptions options(const Body& b, PhantomLabelling labels) {
  PhantomOptions o;
  o.spacingMm = b.spacing;
  o.armsResting = b.armsResting;
  o.handGapMm = b.handGapMm;
  o.forearmGapMm = b.handGapMm > 0 ? 15 : 0;
  o.girdlesTouching = b.girdlesTouching;
  o.labels = labels;
  return o;
}

// The share of body voxels both rigs give the same part.
double sameParts(const Volume& a, const Volume& b) {
  std::int64_t body = 0, same = 0;
  for (std::int64_t i = 0; i < a.numVoxels(); ++i) {
    const double x = a.valueAsDouble(i);
    if (x <= 0) continue;
    ++body;
    same += b.valueAsDouble(i) == x;
  }
  return double(same) / double(std::max<std::int64_t>(1, body));
}

class CoarseMap : public ::testing::TestWithParam<Body> {};

// The arms-resting phantom at 4 mm as a coarse map (G only).
Volume coarseArmsResting4mm() {
  PhantomOptions o;
  o.voxelMm = 4;
  o.armsResting = true;
  o.labels = PhantomLabelling::Coarse;
  return Phantom(o).makeVolumes().first;
}

}  // namespace

TEST_P(CoarseMap, RigsWithNoOptionAndFitsTheFullLabelRigsJoints) {
  const Body& b = GetParam();
  const auto [full, parts] = Phantom(options(b, PhantomLabelling::Phantom)).makeVolumes();
  auto [coarse, same] = Phantom(options(b, PhantomLabelling::Coarse)).makeVolumes();
  if (b.discs) {
    // 5 mm discs every 30 mm from the lumbosacral one up to the neck, across the spine's column
    // (as a 1 mm map shows them): the spine falls into vertebrae and the pelvis comes apart.
    std::uint8_t* g = coarse.data<std::uint8_t>();
    const auto& d = coarse.geometry().dims;
    std::int64_t cut = 0;
    for (std::int64_t k = 0; k < d[2]; ++k)
      for (std::int64_t j = 0; j < d[1]; ++j)
        for (std::int64_t i = 0; i < d[0]; ++i) {
          const std::int64_t v = i + d[0] * (j + d[1] * k);
          const Eigen::Vector3d p = coarse.geometry().voxelToRas(double(i), double(j), double(k));
          const double disc = std::fmod(p.z() - 750 + 300, 30.0);
          if (g[v] == 2 && std::fabs(p.x()) < 35 && p.y() < -15 && p.y() > -90 && p.z() > 740 &&
              p.z() < 1160 && (disc <= 2.5 || disc >= 27.5))
            g[v] = 1, ++cut;
        }
    ASSERT_GT(cut, 300);
  }
  ASSERT_TRUE(coarse.labels().empty());  // no names: recognised by the labels' shapes
  RigOptions ro;
  ro.source = b.name;
  const RigResult labelled = rigBody(full, ro);
  const RigResult split = rigBody(coarse, ro);
  EXPECT_EQ(split.convention.name, "coarse (body and skeleton)");
  EXPECT_EQ(
      split.convention.detection.rfind("auto: a coarse map of 5 unnamed labels: 1 the body", 0), 0u)
      << split.convention.detection;
  // Every joint the full-label rig makes, within 10 mm, and said to come from the split.
  EXPECT_EQ(split.missing.size(), labelled.missing.size());
  const nlohmann::json report = nlohmann::json::parse(split.reportJson);
  for (const SkeletonJoint& j : labelled.skeleton.joints) {
    SCOPED_TRACE(j.name);
    const SkeletonJoint* k = split.skeleton.find(j.name);
    ASSERT_NE(k, nullptr);
    EXPECT_LT((k->centre - j.centre).norm(), 10.0);
    EXPECT_EQ(k->parts, j.parts);
    EXPECT_NE(k->method.find("(bones split from the skeleton label)"), std::string::npos)
        << k->method;
  }
  EXPECT_EQ(split.skeleton.joints.size(), labelled.skeleton.joints.size());
  EXPECT_GT(report["skeleton_split"]["pieces"].get<int>(), 10);
  // The body parts are the full-label rig's nearly everywhere (they differ where the split
  // gives a bone end to its neighbour across a joint).
  EXPECT_GE(sameParts(labelled.parts, split.parts), 0.97);
  // The skeleton is one rigid tissue, the bone "skeleton"; the rest is soft.
  ASSERT_TRUE(split.tissues.count(2));
  EXPECT_TRUE(split.tissues.at(2).rigid);
  EXPECT_EQ(split.tissues.at(2).bone, "skeleton");
  for (const int soft : {1, 3, 4, 5}) EXPECT_FALSE(split.tissues.at(soft).rigid) << soft;
}

INSTANTIATE_TEST_SUITE_P(
    Grids, CoarseMap,
    ::testing::Values(Body{"arms_resting_2mm", Eigen::Vector3d(2, 2, 2), true, 0, false},
                      Body{"arms_resting_4mm", Eigen::Vector3d(4, 4, 4), true, 0, false},
                      Body{"gap_thick_girdles_touching", Eigen::Vector3d(1.8, 1.8, 4.8), true, 4,
                           true},
                      Body{"icrp_am_grid", Eigen::Vector3d(2.137, 2.137, 8), true, 3, true},
                      Body{"free_arms_3mm", Eigen::Vector3d(3, 3, 3), false, 0, false},
                      Body{"vertebrae_apart_3mm", Eigen::Vector3d(3, 3, 3), true, 0, false, true}),
    [](const auto& info) { return std::string(info.param.name); });

TEST(CoarseMap, ACsvNamesTheSkeletonAndTheBody) {
  const Volume G = coarseArmsResting4mm();
  const RigResult automatic = rigBody(G);
  test::ScratchDir dir;
  std::ofstream(dir.file("kinds.csv")) << "label,bone\n1,body\n2,skeleton\n";
  RigOptions ro;
  ro.labels = dir.file("kinds.csv");
  const RigResult named = rigBody(G, ro);
  EXPECT_EQ(named.convention.detection, "--labels " + dir.file("kinds.csv"));
  EXPECT_EQ(named.tissues.at(1).name, "body");
  ASSERT_EQ(named.skeleton.joints.size(), automatic.skeleton.joints.size());
  for (std::size_t i = 0; i < named.skeleton.joints.size(); ++i)
    EXPECT_LT((named.skeleton.joints[i].centre - automatic.skeleton.joints[i].centre).norm(), 1e-9)
        << named.skeleton.joints[i].name;
  // An unknown kind is named in the error with the kinds there are.
  std::ofstream(dir.file("bad.csv")) << "label,bone\n2,skeletons\n";
  ro.labels = dir.file("bad.csv");
  try {
    rigBody(G, ro);
    FAIL() << "took an unknown kind";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("skeleton: every bone in one label"), std::string::npos)
        << e.what();
  }
}

TEST(CoarseMap, ASkeletonWithoutABodyIsRefusedInOneLine) {
  Volume G = coarseArmsResting4mm();
  std::uint8_t* g = G.data<std::uint8_t>();
  for (std::int64_t i = 0; i < G.numVoxels(); ++i)
    if (g[i] != 2) g[i] = 0;  // the skeleton alone
  Label skeleton;
  skeleton.value = 2;
  skeleton.name = "skeleton";
  G.labels().set(skeleton);
  RigOptions ro;
  ro.source = "bones.nii.gz";
  try {
    rigBody(G, ro);
    FAIL() << "rigged bones with no body";
  } catch (const Error& e) {
    const std::string m = e.what();
    EXPECT_EQ(m.find('\n'), std::string::npos);
    EXPECT_EQ(m.rfind("bones.nii.gz: a skeleton label but no body outline", 0), 0u) << m;
  }
}

TEST(CoarseMap, ASkeletonThatIsNotUprightInItsFrameIsRefusedInOneLine) {
  // The same map with the array's slices along A instead of S (a file whose orientation says the
  // body lies head forwards): splitting it by "up" would make nonsense, so it is refused.
  Volume G = coarseArmsResting4mm();
  VolumeGeometry lying = G.geometry();
  const Eigen::Matrix4d upright = lying.ijkToRas;
  lying.ijkToRas.col(1) = upright.col(2);
  lying.ijkToRas.col(2) = upright.col(1);
  G.setGeometry(lying);
  RigOptions ro;
  ro.source = "lying.nii.gz";
  try {
    rigBody(G, ro);
    FAIL() << "split a skeleton lying along A";
  } catch (const Error& e) {
    const std::string m = e.what();
    EXPECT_EQ(m.find('\n'), std::string::npos);
    EXPECT_EQ(m.rfind("lying.nii.gz: the skeleton label is ", 0), 0u) << m;
    EXPECT_NE(m.find("along A-P: it can be split into bones only upright"), std::string::npos) << m;
  }
}
