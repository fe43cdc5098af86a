// `repose rig` from the organ map alone (rig/Rig.h), checked against the generated phantom's own
// truth: its body-part map S on >= 95 % of body voxels and its joint centres within 5 mm, on the
// free-armed phantom, the arms-resting one (arms on the trunk, hands on the thighs, thighs
// touching) at 2 mm, its thick-slice variant (1.8 x 1.8 x 4.8 mm), its ICRP 110 labelling (no
// sides in the bone labels) and the ICRP adult male's 8 mm slices; a CSV convention gives the
// phantom's rig; a body without arms is rigged for its legs and says which joints it could not
// make; an organ segmentation (no skin, fat or muscle) gets its body from its CT.
#include "repose/phantom/Phantom.h"
#include "repose/rig/Rig.h"
#include "repose/util/Error.h"

#include "TestPaths.h"

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <algorithm>

#include <fstream>
#include <map>
#include <string>

using namespace repose;

namespace {

struct Variant {
  const char* name;
  Eigen::Vector3d spacing;
  bool armsResting;
  PhantomLabelling labels;
};

void PrintTo(const Variant& v, std::ostream* os) {
  *os << v.name;
}

class RigPhantom : public ::testing::TestWithParam<Variant> {};

// The phantom's own S has no girdles and no pelvis: where the rig makes them (parts 15-17), they
// are the phantom's torso.
double trunk(double part) {
  return part >= 15 && part <= 17 ? 2 : part;
}
std::string trunk(const std::string& part) {
  return part.rfind("shoulder_girdle", 0) == 0 || part == "pelvis" ? "torso" : part;
}

double agreement(const Volume& truth, const Volume& rigged) {
  std::int64_t body = 0, same = 0;
  for (std::int64_t i = 0; i < truth.numVoxels(); ++i) {
    const double t = truth.valueAsDouble(i);
    if (t <= 0) continue;
    ++body;
    same += trunk(rigged.valueAsDouble(i)) == trunk(t);
  }
  return double(same) / double(std::max<std::int64_t>(1, body));
}

}  // namespace

TEST_P(RigPhantom, ReproducesThePhantomsPartsAndJoints) {
  const Variant& v = GetParam();
  PhantomOptions o;
  o.spacingMm = v.spacing;
  o.armsResting = v.armsResting;
  o.labels = v.labels;
  const Phantom phantom(o);
  const auto [G, S] = phantom.makeVolumes();
  RigOptions ro;
  ro.source = v.name;
  const RigResult rig = rigBody(G, ro);
  // The free-armed phantom has no clavicles (the basic anatomy): its girdles stay with the torso,
  // and the rig says so; every other joint is made.
  for (const std::string& m : rig.missing)
    EXPECT_TRUE(!v.armsResting && m.rfind("sternoclavicular", 0) == 0) << m;
  if (v.armsResting) {
    for (const char* j : {"sternoclavicular_left", "sternoclavicular_right", "lumbosacral"})
      EXPECT_NE(rig.skeleton.find(j), nullptr) << j;
  }
  for (const std::string& w : rig.warnings)  // the phantom's margin leaves every bone whole
    EXPECT_EQ(w.find("edge cuts"), std::string::npos) << w;
  EXPECT_GE(agreement(S, rig.parts), 0.95);
  // The parts keep the phantom's names and numbers, so pose files written for it pose this rig.
  for (const Label& l : S.labels().labels())
    if (l.value > 0) {
      EXPECT_EQ(rig.parts.labels().find(l.value)->name, l.name);
    }
  const Skeleton truth = phantom.skeleton();
  int compared = 0;
  for (const SkeletonJoint& j : truth.joints) {
    if (j.parts[0].empty()) continue;  // the phantom's root ("pelvis") joins no two parts
    const SkeletonJoint* found = rig.skeleton.find(j.name);
    ASSERT_NE(found, nullptr) << j.name;
    EXPECT_LT((found->centre - j.centre).norm(), 5.0) << j.name;
    EXPECT_EQ(trunk(found->parts[0]), trunk(j.parts[0])) << j.name;
    EXPECT_EQ(found->parts[1], j.parts[1]) << j.name;
    ASSERT_NE(found->axis("flexion"), nullptr) << j.name;
    // The flexion axes agree in direction (within 25 degrees: a hinge fitted to the condyles).
    if (j.axis("flexion")) {
      EXPECT_GT(found->axis("flexion")->dot(*j.axis("flexion")), std::cos(25 * M_PI / 180))
          << j.name;
    }
    ++compared;
  }
  EXPECT_GE(compared, 13);
  // The tissue table marks the bones rigid and names which bone each is.
  int bones = 0;
  for (const auto& [value, t] : rig.tissues) bones += t.rigid;
  EXPECT_GE(bones, 10);
}

INSTANTIATE_TEST_SUITE_P(
    Variants, RigPhantom,
    ::testing::Values(
        Variant{"free_arms_2mm", Eigen::Vector3d(2, 2, 2), false, PhantomLabelling::Phantom},
        Variant{"arms_resting_2mm", Eigen::Vector3d(2, 2, 2), true, PhantomLabelling::Phantom},
        Variant{"arms_resting_thick", Eigen::Vector3d(1.8, 1.8, 4.8), true,
                PhantomLabelling::Phantom},
        Variant{"icrp110_thick", Eigen::Vector3d(1.8, 1.8, 4.8), true, PhantomLabelling::Icrp110},
        // The adult male reference phantom's grid (8 mm slices) and a coarse isotropic one: the
        // ends' fits must not shrink on a coarse grid.
        Variant{"icrp110_am_grid", Eigen::Vector3d(2.137, 2.137, 8.0), true,
                PhantomLabelling::Icrp110},
        Variant{"arms_resting_4mm", Eigen::Vector3d(4, 4, 4), true, PhantomLabelling::Phantom}),
    [](const auto& info) { return std::string(info.param.name); });

TEST(Rig, ACsvConventionGivesThePhantomsRig) {
  PhantomOptions o;
  o.voxelMm = 3;
  o.armsResting = true;
  const Phantom phantom(o);
  auto [G, S] = phantom.makeVolumes();
  const RigResult builtIn = rigBody(G);
  // The user's table: label, bone (and a side where the label has one).
  test::ScratchDir dir;
  std::ofstream csv(dir.file("bones.csv"));
  csv << "label,bone,side,name\n";
  for (const auto& [value, role] : builtIn.convention.roles)
    if (role.bone != BoneKind::None)
      csv << value << "," << boneKindName(role.bone) << ","
          << (role.side < 0   ? "left"
              : role.side > 0 ? "right"
                              : "")
          << "," << role.name << "\n";
  csv.close();
  RigOptions ro;
  ro.labels = dir.file("bones.csv");
  const RigResult fromCsv = rigBody(G, ro);
  EXPECT_GE(agreement(builtIn.parts, fromCsv.parts), 0.99);
  for (const SkeletonJoint& j : builtIn.skeleton.joints) {
    const SkeletonJoint* found = fromCsv.skeleton.find(j.name);
    ASSERT_NE(found, nullptr) << j.name;
    EXPECT_LT((found->centre - j.centre).norm(), 1.0) << j.name;
  }
}

// The girdles-touching variant (PhantomOptions::girdlesTouching, issue 64): the clavicles reach
// the midline over the manubrium, as on reference phantoms, so the two shoulder girdles the rig
// makes touch across the sternum (the contact both arms raised must cut); the anatomical phantom's
// girdles stand apart there. Either way each girdle has its sternoclavicular joint.
TEST(Rig, GirdlesThatMeetAcrossTheSternumAreRiggedTouching) {
  constexpr int kGirdleLeft = 15,
                kGirdleRight = 16;  // the rig's S: 15-16 shoulder_girdle_left/right
  auto girdleFaces = [](bool touching) {
    PhantomOptions o;
    o.spacingMm = Eigen::Vector3d(1.8, 1.8, 4.8);
    o.armsResting = true;
    o.girdlesTouching = touching;
    auto [G, S] = Phantom(o).makeVolumes();
    const RigResult rig = rigBody(G);
    for (const char* j : {"sternoclavicular_left", "sternoclavicular_right"})
      EXPECT_NE(rig.skeleton.find(j), nullptr) << j << (touching ? " (touching)" : "");
    const Volume& P = rig.parts;
    const auto d = P.dims();
    const std::int64_t step[3] = {1, d[0], d[0] * d[1]};
    std::int64_t faces = 0;
    for (std::int64_t k = 0; k + 1 < d[2]; ++k)
      for (std::int64_t j = 0; j + 1 < d[1]; ++j)
        for (std::int64_t i = 0; i + 1 < d[0]; ++i) {
          const std::int64_t v = P.index(i, j, k);
          for (const std::int64_t s : step) {
            const int a = int(P.valueAsDouble(v)), b = int(P.valueAsDouble(v + s));
            faces +=
                (a == kGirdleLeft && b == kGirdleRight) || (a == kGirdleRight && b == kGirdleLeft);
          }
        }
    return faces;
  };
  EXPECT_GE(girdleFaces(true), 20);
  EXPECT_EQ(girdleFaces(false), 0);
  PhantomOptions bad;
  bad.girdlesTouching = true;
  EXPECT_THROW(Phantom{bad}, Error);  // the girdle belongs to the arms-resting posture
}

TEST(Rig, ABodyWithoutArmsIsRiggedForItsLegsAndSaysSo) {
  PhantomOptions o;
  o.voxelMm = 3;
  const Phantom phantom(o);
  auto [G, S] = phantom.makeVolumes();
  ASSERT_EQ(G.scalarType(), ScalarType::UInt8);
  // The arms' bones become muscle: a scan whose arms were cropped or not segmented.
  const RigResult full = rigBody(G);
  int muscle = 0;
  for (const Label& l : G.labels().labels())
    if (l.name == "muscle") muscle = l.value;
  ASSERT_GT(muscle, 0);
  std::map<int, bool> armBone;
  for (const auto& [value, role] : full.convention.roles)
    armBone[value] = role.bone == BoneKind::Humerus || role.bone == BoneKind::Forearm ||
                     role.bone == BoneKind::Hand;
  for (std::int64_t i = 0; i < G.numVoxels(); ++i)
    if (armBone[int(G.valueAsDouble(i))]) G.data<std::uint8_t>()[i] = std::uint8_t(muscle);
  const RigResult legs = rigBody(G);
  for (const char* j : {"hip_left", "knee_right", "ankle_left"})
    EXPECT_NE(legs.skeleton.find(j), nullptr) << j;
  EXPECT_EQ(legs.skeleton.find("elbow_left"), nullptr);
  bool said = false;
  for (const std::string& m : legs.missing) said = said || m.find("humerus") != std::string::npos;
  EXPECT_TRUE(said) << "no line names the missing humerus";
}

TEST(Rig, NoLimbBonesIsAOneLineErrorNamingThem) {
  PhantomOptions o;
  o.voxelMm = 4;
  auto [G, S] = Phantom(o).makeVolumes();
  int muscle = 0;
  for (const Label& l : G.labels().labels())
    if (l.name == "muscle") muscle = l.value;
  const RigResult full = rigBody(G);
  for (std::int64_t i = 0; i < G.numVoxels(); ++i) {
    const auto it = full.convention.roles.find(int(G.valueAsDouble(i)));
    if (it != full.convention.roles.end() &&
        (it->second.bone == BoneKind::Humerus || it->second.bone == BoneKind::Femur))
      G.data<std::uint8_t>()[i] = std::uint8_t(muscle);
  }
  RigOptions ro;
  ro.source = "trunk.nii.gz";
  try {
    rigBody(G, ro);
    FAIL() << "rigged a body without humeri and femora";
  } catch (const Error& e) {
    const std::string m = e.what();
    EXPECT_EQ(m.find('\n'), std::string::npos);
    EXPECT_NE(m.find("trunk.nii.gz"), std::string::npos) << m;
    EXPECT_NE(m.find("humerus"), std::string::npos) << m;
    EXPECT_NE(m.find("femur"), std::string::npos) << m;
  }
}

TEST(Rig, AnOrganSegmentationIsGivenItsBodyByTheScanItWasMadeFrom) {
  // TotalSegmentator-like: the arms-resting phantom's organs and bones only (skin, fat, muscle
  // and vessels erased to 0), and the CT of the whole phantom.
  PhantomOptions o;
  o.voxelMm = 4;
  o.armsResting = true;
  const Phantom phantom(o);
  const auto [G, S] = phantom.makeVolumes();
  const Volume ct = syntheticCT(G);
  Volume organs = G;
  std::int64_t erased = 0;
  for (std::int64_t i = 0; i < organs.numVoxels(); ++i) {
    const Label* l = G.labels().find(int(G.valueAsDouble(i)));
    const std::string name = l ? l->name : "";
    if (name == "skin" || name == "subcutaneous_fat" || name == "muscle" ||
        name.rfind("blood_vessels", 0) == 0) {
      organs.data<std::uint8_t>()[i] = 0;
      ++erased;
    }
  }
  ASSERT_GT(erased, G.numVoxels() / 10);
  RigOptions ro;
  ro.source = "organs";
  // Without the scan: S is the organs alone, and the rig says the tissue between is missing.
  const RigResult bare = rigBody(organs, ro);
  EXPECT_TRUE(std::any_of(bare.warnings.begin(), bare.warnings.end(), [](const std::string& w) {
    return w.find("no skin, fat or muscle") != std::string::npos &&
           w.find("--image") != std::string::npos;
  }));
  // With it: the body's outline is the phantom's, and its parts are the phantom's own on >= 95 %
  // of the body (the arm resting on the trunk still goes to the arm).
  ro.image = &ct;
  const RigResult rig = rigBody(organs, ro);
  EXPECT_TRUE(std::none_of(rig.warnings.begin(), rig.warnings.end(), [](const std::string& w) {
    return w.find("no skin, fat or muscle") != std::string::npos;
  }));
  std::int64_t body = 0, inOutline = 0;
  for (std::int64_t i = 0; i < S.numVoxels(); ++i)
    if (S.valueAsDouble(i) > 0) ++body, inOutline += rig.parts.valueAsDouble(i) > 0;
  EXPECT_GE(double(inOutline) / double(body), 0.98);
  EXPECT_GE(agreement(S, rig.parts), 0.95);
  EXPECT_NE(nlohmann::json::parse(rig.reportJson)["body_outline"]["method"].get<std::string>().find(
                "CT above -300 HU"),
            std::string::npos);
  // A scan of somewhere else is refused by name.
  Volume elsewhere = ct;
  VolumeGeometry far = ct.geometry();
  far.ijkToRas(2, 3) += 5000;
  elsewhere.setGeometry(far);
  ro.image = &elsewhere;
  ro.imageSource = "CT.nii.gz";
  try {
    rigBody(organs, ro);
    FAIL() << "a scan that misses G was taken";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("CT.nii.gz: the image covers 0 %"), std::string::npos)
        << e.what();
  }
}

// TotalSegmentator's `total` task labels the humerus and the femur but no radius, ulna, hand,
// tibia, fibula or foot bones (issue 65 item 2): the elbow and the knee are fitted from the
// humeral and femoral condyles alone, within 10 mm of the full-label rig's (on this phantom the
// same places: the full rig's fits are the condyles' too), rig.json says so per joint, and the
// forearm and shank are the limb beyond their planes; the wrist and the ankle are fitted from
// the outline of those parts, which the hand and the foot beyond them are then cut from. Before,
// the rig made neither the elbow nor the knee, and then no wrist or ankle.
TEST(Rig, AMapWithoutForearmAndShankBonesFitsElbowAndKneeFromTheHumerusAndFemur) {
  PhantomOptions o;
  o.voxelMm = 4;
  o.armsResting = true;
  const Phantom phantom(o);
  const auto [G, S] = phantom.makeVolumes();
  RigOptions ro;
  ro.source = "total";
  const RigResult full = rigBody(G, ro);
  Volume organs = G;
  int muscle = 0;
  for (const Label& l : G.labels().labels())
    if (l.name == "muscle") muscle = l.value;
  ASSERT_GT(muscle, 0);
  std::int64_t relabelled = 0;
  for (std::int64_t i = 0; i < organs.numVoxels(); ++i) {
    const Label* l = G.labels().find(int(G.valueAsDouble(i)));
    const std::string name = l ? l->name : "";
    if (name.rfind("radius_ulna", 0) == 0 || name.rfind("tibia_fibula", 0) == 0 ||
        name == "hand_bones" || name == "foot_bones") {
      organs.data<std::uint8_t>()[i] = std::uint8_t(muscle);
      ++relabelled;
    }
  }
  ASSERT_GT(relabelled, 1000);
  const RigResult rig = rigBody(organs, ro);
  // The wrists and ankles come from the outline of the forearm's and shank's parts
  // (RigOutlineJoints): each ankle between the shank's narrowest section and the foot's widening,
  // within 10 mm of the full rig's talar dome; each wrist at 77 % of the humerus's length from the
  // elbow (adults' radius to humerus), within 20 mm of the full rig's carpals (15 mm here: the
  // phantom's forearm is 83 % of its humerus). rig.json says how per joint; nothing is missing.
  for (const std::string name : {"elbow_left", "elbow_right", "knee_left", "knee_right",
                                 "wrist_left", "wrist_right", "ankle_left", "ankle_right"}) {
    SCOPED_TRACE(name);
    const SkeletonJoint* a = full.skeleton.find(name);
    const SkeletonJoint* b = rig.skeleton.find(name);
    ASSERT_NE(a, nullptr);
    ASSERT_NE(b, nullptr);
    EXPECT_LT((a->centre - b->centre).norm(), name[0] == 'w' ? 20.0 : 10.0);
    const char* said =
        name[0] == 'e' || name[0] == 'k'
            ? "labelled: the segment beyond taken along"
            : (name[0] == 'a' ? "(no foot bones labelled)" : "(no hand bones labelled)");
    EXPECT_NE(b->method.find(said), std::string::npos) << b->method;
    if (name[0] == 'w' || name[0] == 'a') EXPECT_EQ(b->method.rfind("outline: ", 0), 0u);
  }
  EXPECT_TRUE(rig.missing.empty()) << rig.missing.front();
  // The forearm and hand, and the shank and foot, are where the full rig puts them, between them
  // (here 96 % of the forearm and hand, 99.7 % of the shank and foot).
  auto part = [&](const std::string& name) {
    for (const Label& l : full.parts.labels().labels())
      if (l.name == name) return l.value;
    ADD_FAILURE() << "no part " << name;
    return -1;
  };
  for (const std::string side : {"_left", "_right"}) {
    const int upper = part("upper_arm" + side), forearm = part("forearm" + side),
              hand = part("hand" + side), shank = part("shank" + side), foot = part("foot" + side);
    std::int64_t distal = 0, same = 0, leg = 0, legSame = 0, upperArm = 0, upperSame = 0;
    for (std::int64_t i = 0; i < S.numVoxels(); ++i) {
      const int f = int(full.parts.valueAsDouble(i)), r = int(rig.parts.valueAsDouble(i));
      if (f == forearm || f == hand) ++distal, same += r == forearm || r == hand;
      if (f == shank || f == foot) ++leg, legSame += r == shank || r == foot;
      if (f == upper) ++upperArm, upperSame += r == upper;
    }
    EXPECT_GT(distal, 1000);
    EXPECT_GE(double(same) / double(distal), 0.95) << side;
    EXPECT_GE(double(legSame) / double(leg), 0.95) << side;
    EXPECT_GE(double(upperSame) / double(upperArm), 0.95) << side;
  }
}

// 3D Slicer hands a CLI module its label maps as plain NRRD, without names: S's values are named
// as the rig names them only when S has no table and every value is one of the rig's parts.
TEST(Rig, AnUnnamedBodyPartMapIsNamedByTheRigsConventionOnlyWhenItFits) {
  VolumeGeometry g;
  g.dims = {4, 4, 4};
  Volume s(g, ScalarType::UInt8);
  s.data<std::uint8_t>()[0] = 4;
  s.data<std::uint8_t>()[1] = 14;
  s.setLabelMap(true);
  Volume plain = s;
  EXPECT_NE(nameBodyPartsByRigConvention(plain, "S.nrrd").find("S.nrrd"), std::string::npos);
  ASSERT_NE(plain.labels().find(4), nullptr);
  EXPECT_EQ(plain.labels().find(4)->name, "forearm_left");
  EXPECT_EQ(plain.labels().find(14)->name, "foot_right");
  // A value outside the convention: left alone.
  Volume other = s;
  other.data<std::uint8_t>()[2] = 18;
  EXPECT_EQ(nameBodyPartsByRigConvention(other, "S.nrrd"), "");
  EXPECT_TRUE(other.labels().empty());
  // A map with its own names: left alone.
  Volume named = s;
  Label l;
  l.value = 4, l.name = "lower arm";
  named.labels().set(l);
  EXPECT_EQ(nameBodyPartsByRigConvention(named, "S.nrrd"), "");
  EXPECT_EQ(named.labels().find(4)->name, "lower arm");
}

// A real ICRP 110 file holds organ ID 141 (the skin of its first and last slices) beside 1-140,
// and a user's copy may carry a label of its own. Neither may cost the user the rig: auto-detection
// takes the file for ICRP 110, 141 is ICRP's skin, and the unknown label is soft tissue, listed in
// rig.json and named in one warning line.
TEST(Rig, ARealIcrp110LabelSetWith141AndAnUnknownLabelRigsWithoutAnOption) {
  PhantomOptions o;
  o.spacingMm = Eigen::Vector3d(2.137, 2.137, 8.0);
  o.armsResting = true;
  o.labels = PhantomLabelling::Icrp110;
  const Phantom phantom(o);
  const auto [G, S] = phantom.makeVolumes();
  const RigResult plain = rigBody(G);
  Volume real = G;
  std::uint8_t* g = real.data<std::uint8_t>();
  const auto& d = real.dims();
  // The body's first and last slices: their skin (IDs 122-125) becomes 141, as in ICRP's files.
  std::int64_t kLo = d[2], kHi = -1;
  for (std::int64_t i = 0; i < real.numVoxels(); ++i)
    if (g[i]) kLo = std::min(kLo, i / (d[0] * d[1])), kHi = std::max(kHi, i / (d[0] * d[1]));
  ASSERT_LT(kLo, kHi);
  std::int64_t skin141 = 0, unknown = 0;
  for (std::int64_t i = 0; i < real.numVoxels(); ++i) {
    const std::int64_t k = i / (d[0] * d[1]);
    if ((k == kLo || k == kHi) && g[i] >= 122 && g[i] <= 125) g[i] = 141, ++skin141;
  }
  // An ID ICRP does not have: a block of the trunk's muscle (ID 107) in the belly.
  const Eigen::Vector3d belly = phantom.joint("spine").ras + Eigen::Vector3d(0, 40, -60);
  for (std::int64_t i = 0; i < real.numVoxels(); ++i) {
    const Eigen::Vector3d p = real.geometry().voxelToRas(
        double(i % d[0]), double((i / d[0]) % d[1]), double(i / (d[0] * d[1])));
    if (g[i] == 107 && (p - belly).norm() < 40) g[i] = 201, ++unknown;
  }
  ASSERT_GT(skin141, 0);
  ASSERT_GT(unknown, 50);

  for (const char* labels : {"auto", "icrp110"}) {
    RigOptions ro;
    ro.labels = labels;
    ro.source = "icrp_am.nii.gz";
    const RigResult rig = rigBody(real, ro);
    EXPECT_EQ(rig.convention.name.rfind("icrp110", 0), 0u) << rig.convention.name;
    EXPECT_EQ(rig.convention.unknown, std::vector<int>{201});
    ASSERT_TRUE(rig.convention.roles.count(141));
    EXPECT_EQ(rig.convention.roles.at(141).name, "Skin at top and bottom");
    EXPECT_FALSE(rig.convention.roles.at(141).rigid);
    ASSERT_TRUE(rig.convention.roles.count(201));
    EXPECT_FALSE(rig.convention.roles.at(201).rigid);
    EXPECT_EQ(rig.convention.roles.at(201).bone, BoneKind::None);
    EXPECT_EQ(rig.convention.roles.at(201).region, BodyRegion::Unknown);
    // One warning line names it, and only it.
    int lines = 0;
    for (const std::string& w : rig.warnings)
      if (w.find("201") != std::string::npos) {
        ++lines;
        EXPECT_EQ(w.find('\n'), std::string::npos);
        EXPECT_EQ(w.find("141"), std::string::npos) << w;
      }
    EXPECT_EQ(lines, 1);
    const nlohmann::json report = nlohmann::json::parse(rig.reportJson);
    ASSERT_EQ(report["unknown_labels"].size(), 1u);
    EXPECT_EQ(report["unknown_labels"][0]["label"], 201);
    EXPECT_EQ(report["unknown_labels"][0]["taken_as"], "soft tissue");
    // The tissue table has every label, soft where unknown; the rig is the plain file's.
    ASSERT_TRUE(rig.tissues.count(201) && rig.tissues.count(141));
    EXPECT_FALSE(rig.tissues.at(201).rigid);
    EXPECT_GE(agreement(plain.parts, rig.parts), 0.99);
    for (const SkeletonJoint& j : plain.skeleton.joints) {
      const SkeletonJoint* found = rig.skeleton.find(j.name);
      ASSERT_NE(found, nullptr) << j.name;
      EXPECT_LT((found->centre - j.centre).norm(), 1.0) << j.name;
    }
  }
  // Labels that are mostly not ICRP IDs are still not taken for ICRP 110.
  Volume foreign = real;
  std::uint8_t* f = foreign.data<std::uint8_t>();
  for (std::int64_t i = 0; i < foreign.numVoxels(); ++i)
    if (f[i] >= 100 && f[i] <= 141) f[i] = std::uint8_t(f[i] + 100);
  EXPECT_THROW(rigBody(foreign), Error);
}
