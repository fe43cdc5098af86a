// `repose rig` and `repose pose` end to end, as a user brings a segmentation: the rig folder's
// four files, a pose by named joints with automatic contact separation (each cut in the report)
// and with separations drawn by hand (--no-auto-separate), the guard rail that names what drags
// the body when nothing is cut, bones run into each other by a pivot off the joint, and one-line
// errors for a segmentation with no limb bones (TotalSegmentator's CT example: a chest, no
// humerus or femur).
#include "CliTestFiles.h"
#include "CommandRunner.h"
#include "TestPaths.h"

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <filesystem>
#include <fstream>
#include <set>
#include <sstream>

using namespace repose::test;

TEST(RigCommand, RigsTheArmsRestingPhantomAndPosesItByNamedJointsWithAutomaticCuts) {
  ScratchDir dir;
  const std::string d = shellQuote(dir.path().string());
  ASSERT_EQ(runCommand("repose", "phantom --voxel 3 --arms-resting --out " + d).exitCode, 0);
  // Only G goes in: the phantom's own S and skeleton are moved away.
  std::filesystem::rename(dir.file("S.nii.gz"), dir.file("truth_S.nii.gz"));
  std::filesystem::rename(dir.file("skeleton.json"), dir.file("truth_skeleton.json"));
  const CommandResult rig =
      runCommand("repose", "rig --input " + shellQuote(dir.file("G.nii.gz")) + " --out " +
                               shellQuote(dir.file("rig")) + " --json");
  ASSERT_EQ(rig.exitCode, 0) << rig.err;
  for (const char* f : {"S.nii.gz", "skeleton.json", "tissues.csv", "rig.json"})
    EXPECT_TRUE(std::filesystem::exists(dir.file(std::string("rig/") + f))) << f;
  const nlohmann::json rigReport = nlohmann::json::parse(rig.out);
  EXPECT_EQ(rigReport, readJsonFile(dir.file("rig/rig.json")));
  EXPECT_EQ(rigReport["convention"], "phantom");
  const nlohmann::json skeleton = readJsonFile(dir.file("rig/skeleton.json"));
  EXPECT_GE(skeleton["joints"].size(), 13u);

  // The suite's arm raise names shoulder_left and its abduction axis; the skeleton beside S
  // resolves them.
  auto raise = [&](const std::string& out, const std::string& extra) {
    return runCommand("repose", "pose --input " + shellQuote(dir.file("G.nii.gz")) + " --parts " +
                                    shellQuote(dir.file("rig/S.nii.gz")) + " --pose " +
                                    shellQuote(suitePoseFile("arm_raise90")) + " --out " +
                                    shellQuote(dir.file(out)) + " --json" + extra);
  };
  const CommandResult pose = raise("raised", "");
  ASSERT_EQ(pose.exitCode, 0) << pose.err;
  const nlohmann::json report = nlohmann::json::parse(pose.out);
  EXPECT_TRUE(report["separations"]["automatic"].get<bool>());
  bool armFromTrunk = false;
  for (const auto& s : report["separations"]["made"]) {
    EXPECT_GT(s["contact_voxels"].get<int>(), 0);
    armFromTrunk = armFromTrunk || (s["parts"][0] == "torso" && s["parts"][1] == "upper_arm_left");
  }
  EXPECT_TRUE(armFromTrunk) << report["separations"].dump();
  EXPECT_LT(std::fabs(report["body"]["volume_change_percent"].get<double>()), 0.5);
  EXPECT_TRUE(report["quality"]["bones_rigid"]["met"].get<bool>());
  EXPECT_EQ(report["labels_lost"], 0);

  // Without the automatic cut the arm drags the trunk's side along: the body grows. The frame is
  // written all the same, and the exit status (4), the report and one line say it missed.
  const CommandResult uncut = raise("uncut", " --no-auto-separate");
  ASSERT_EQ(uncut.exitCode, 4) << uncut.err;
  const nlohmann::json u = nlohmann::json::parse(uncut.out);
  EXPECT_FALSE(u["targets"]["met"].get<bool>());
  EXPECT_FALSE(u["targets"]["missed"].empty());
  EXPECT_TRUE(std::filesystem::exists(dir.file("uncut/posed_G.nii.gz")));
  EXPECT_NE(uncut.err.find("frame arm_raise90 written, but it missed its targets"),
            std::string::npos)
      << uncut.err;
  EXPECT_FALSE(u["separations"]["automatic"].get<bool>());
  const double uncutBody = u["body"]["volume_change_percent"].get<double>();
  EXPECT_GT(std::fabs(uncutBody),
            2 * std::fabs(report["body"]["volume_change_percent"].get<double>()));
  // The guard rail saw it before any voxel was written: the posed mesh's prediction is near what
  // the voxels then measured, and one line on stderr names the trunk dragged by the left arm.
  const double predicted = u["predicted"]["body_change_percent"].get<double>();
  EXPECT_GT(std::fabs(predicted), 0.5);
  EXPECT_NEAR(predicted, uncutBody, 0.5 * std::fabs(uncutBody));
  // What is dragged is the body beside the arm (the trunk, or the thigh the hand rests on),
  // and what drags it is a part of the left arm.
  const std::string worst = u["predicted"]["worst_part"].get<std::string>();
  EXPECT_TRUE(worst == "torso" || worst == "thigh_left") << worst;
  EXPECT_NE(u["predicted"]["dragged_by"].get<std::string>().find("_left"), std::string::npos);
  const std::string line = "predicts a body volume change of";
  ASSERT_NE(uncut.err.find(line), std::string::npos) << uncut.err;
  const std::string said = uncut.err.substr(uncut.err.find(line));
  EXPECT_NE(said.substr(0, said.find('\n')).find(worst), std::string::npos) << said;
  // With the cut, nothing to warn of: the prediction is within the target, no bones collide.
  EXPECT_LT(std::fabs(report["predicted"]["body_change_percent"].get<double>()), 0.5);
  EXPECT_EQ(pose.err.find(line), std::string::npos) << pose.err;
  EXPECT_EQ(report["bone_collisions"]["voxels"], 0);
}

TEST(RigCommand, AForearmTurnedAboutAPivotOffTheElbowRunsIntoTheHumerusAndIsReported) {
  ScratchDir dir;
  const std::string d = shellQuote(dir.path().string());
  ASSERT_EQ(runCommand("repose", "phantom --voxel 3 --out " + d).exitCode, 0);
  const nlohmann::json skeleton = readJsonFile(dir.file("skeleton.json"));
  nlohmann::json elbow;
  for (const auto& j : skeleton["joints"])
    if (j["name"] == "elbow_left") elbow = j;
  ASSERT_FALSE(elbow.is_null());
  // The suite's elbow flexion about the skeleton's own centre, and about a pivot 20 mm behind
  // it (posterior is -y in RAS): the olecranon then swings into the humerus.
  auto pose = [&](const std::string& name, double back) {
    nlohmann::json p = readJsonFile(suitePoseFile("elbow90"));
    auto& rotation = p["groups"][0]["rotation"];
    rotation["axis"] = elbow["axes"]["flexion"];
    rotation["pivot"] = {elbow["ras"][0], elbow["ras"][1].get<double>() - back, elbow["ras"][2]};
    std::ofstream(dir.file(name + ".pose.json")) << p.dump();
    return runCommand("repose", "pose --input " + shellQuote(dir.file("G.nii.gz")) + " --parts " +
                                    shellQuote(dir.file("S.nii.gz")) + " --pose " +
                                    shellQuote(dir.file(name + ".pose.json")) + " --out " +
                                    shellQuote(dir.file(name)) + " --json");
  };
  const CommandResult ok = pose("centred", 0);
  ASSERT_EQ(ok.exitCode, 0) << ok.err;
  EXPECT_EQ(nlohmann::json::parse(ok.out)["bone_collisions"]["voxels"], 0);
  EXPECT_EQ(ok.err.find("run into each other"), std::string::npos) << ok.err;
  const CommandResult off = pose("behind", 20);
  // Written either way; the exit status says whether it met its targets, as the report does.
  ASSERT_TRUE(off.exitCode == 0 || off.exitCode == 4) << off.err;
  EXPECT_EQ(off.exitCode == 4, !nlohmann::json::parse(off.out)["targets"]["met"].get<bool>());
  const nlohmann::json c = nlohmann::json::parse(off.out)["bone_collisions"];
  ASSERT_GT(c["voxels"].get<int>(), 0) << c.dump();
  bool humerusAndForearm = false;
  for (const auto& pair : c["pairs"]) {
    const std::string a = pair["a"], b = pair["b"];
    humerusAndForearm =
        humerusAndForearm || ((a.find("humerus") == 0 && b.find("radius_ulna") == 0) ||
                              (b.find("humerus") == 0 && a.find("radius_ulna") == 0));
  }
  EXPECT_TRUE(humerusAndForearm) << c.dump();
  EXPECT_NE(off.err.find("rigid pieces run into each other"), std::string::npos) << off.err;
}

TEST(RigCommand, SeparationsDrawnByHandPoseTheArmsTouchingPhantom) {
  ScratchDir dir;
  const std::string d = shellQuote(dir.path().string());
  ASSERT_EQ(runCommand("repose", "phantom --voxel 3 --arms-touching --out " + d).exitCode, 0);
  ASSERT_EQ(runCommand("repose", "rig --input " + shellQuote(dir.file("G.nii.gz")) + " --out " +
                                     shellQuote(dir.file("rig")))
                .exitCode,
            0);
  const CommandResult pose =
      runCommand("repose", "pose --input " + shellQuote(dir.file("G.nii.gz")) + " --parts " +
                               shellQuote(dir.file("rig/S.nii.gz")) + " --pose " +
                               shellQuote(suitePoseFile("hand_from_hip")) + " --out " +
                               shellQuote(dir.file("out")) + " --json --no-auto-separate");
  ASSERT_EQ(pose.exitCode, 0) << pose.err;
  const nlohmann::json report = nlohmann::json::parse(pose.out);
  EXPECT_FALSE(report["separations"]["automatic"].get<bool>());
  EXPECT_EQ(report["separations"]["manual"].size(), 4u);
  EXPECT_LT(std::fabs(report["body"]["volume_change_percent"].get<double>()), 0.5);
  EXPECT_TRUE(report["quality"]["bones_rigid"]["met"].get<bool>());
  EXPECT_EQ(report["labels_lost"], 0);
}

TEST(RigCommand, ASegmentationWithoutLimbBonesIsAOneLineErrorAndWritesNothing) {
  // TotalSegmentator's CT example (a chest) and its MR one (an abdomen, the total_mr task's
  // names: one bone, the vertebrae): both told by their names, both without limb bones.
  for (const char* file : {"example_seg.nii.gz", "example_seg_mr.nii.gz"}) {
    const std::string seg = std::string(REPOSE_DATA_DIR) + "/totalsegmentator/" + file;
    ASSERT_TRUE(std::filesystem::exists(seg)) << seg << " not found (../shared/data)";
    ScratchDir dir;
    const CommandResult r = runCommand(
        "repose", "rig --input " + shellQuote(seg) + " --out " + shellQuote(dir.file("rig")));
    EXPECT_NE(r.exitCode, 0) << file;
    EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
    EXPECT_NE(r.err.find(file), std::string::npos) << r.err;
    EXPECT_NE(r.err.find("humerus"), std::string::npos) << r.err;
    EXPECT_NE(r.err.find("femur"), std::string::npos) << r.err;
    EXPECT_FALSE(std::filesystem::exists(dir.file("rig")));
  }
}

TEST(RigCommand, ARealOrganSegmentationTakesItsBodyFromItsCtSeries) {
  // TotalSegmentator's segmentation of a real 20-slice CT (both humeral heads in it), rigged
  // without and with the DICOM series it was made from (LPS, rows flipped against the NIfTI).
  const std::string data = std::string(REPOSE_DATA_DIR) + "/totalsegmentator/";
  const std::string seg = data + "example_seg_dicom.nii.gz";
  const std::string ct = data + "example_ct_dicom_uncompressed";
  ASSERT_TRUE(std::filesystem::exists(seg) && std::filesystem::exists(ct))
      << seg << " or " << ct << " not found (../shared/data)";
  ScratchDir dir;
  const CommandResult bare = runCommand(
      "repose", "rig --input " + shellQuote(seg) + " --out " + shellQuote(dir.file("bare")));
  ASSERT_EQ(bare.exitCode, 0) << bare.err;
  EXPECT_NE(bare.err.find("no skin, fat or muscle"), std::string::npos) << bare.err;
  const CommandResult withCt =
      runCommand("repose", "rig --input " + shellQuote(seg) + " --image " + shellQuote(ct) +
                               " --out " + shellQuote(dir.file("ct")) + " --json");
  ASSERT_EQ(withCt.exitCode, 0) << withCt.err;
  EXPECT_EQ(withCt.err.find("no skin, fat or muscle"), std::string::npos) << withCt.err;
  // The 40 mm slab cuts both humeri: their shoulder fits are said to be guesses.
  for (const char* side : {"left", "right"})
    EXPECT_NE(withCt.err.find(std::string("the scan's edge cuts the ") + side + " humerus"),
              std::string::npos)
        << withCt.err;
  const nlohmann::json a = readJsonFile(dir.file("bare/rig.json")),
                       b = nlohmann::json::parse(withCt.out);
  EXPECT_EQ(b["body_outline"]["image"], ct);
  auto partMl = [](const nlohmann::json& r, const std::string& name) {
    for (const auto& p : r["parts"])
      if (p["part"] == name) return p["volume_ml"].get<double>();
    return 0.0;
  };
  // Bare, an upper arm is its humerus alone; with the CT, the arm's flesh too (several times
  // the bone), and the trunk's unlabelled fat and muscle join the torso.
  for (const char* arm : {"upper_arm_left", "upper_arm_right"}) {
    EXPECT_GT(partMl(a, arm), 10) << arm;
    EXPECT_GT(partMl(b, arm), 4 * partMl(a, arm)) << arm;
  }
  EXPECT_GT(partMl(b, "torso"), 1.5 * partMl(a, "torso"));
  EXPECT_EQ(b["unreached_voxels"], 0);
}

TEST(RigCommand, AThickSliceBodyPosedOntoAFinerGridKeepsEveryBone) {
  // An ICRP adult male-like grid, coarser still (2.4 x 2.4 x 6 mm), posed onto 1.2 mm: a bone that
  // moves rigidly keeps its volume within 0.5 % of its resampling floor, moving or not, and one
  // that does not move keeps exactly its volume. (Soft
  // tissue beside a bone once judged the bone's voxels moved in output voxels, so on a finer
  // grid every bone lost 1-2 %, the unmoved femur 2.2 %.)
  ScratchDir dir;
  const std::string d = shellQuote(dir.path().string());
  ASSERT_EQ(runCommand("repose", "phantom --spacing 2.4,2.4,6 --arms-resting --out " + d).exitCode,
            0);
  ASSERT_EQ(runCommand("repose", "rig --input " + shellQuote(dir.file("G.nii.gz")) + " --out " +
                                     shellQuote(dir.file("rig")))
                .exitCode,
            0);
  const CommandResult pose =
      runCommand("repose", "pose --input " + shellQuote(dir.file("G.nii.gz")) + " --parts " +
                               shellQuote(dir.file("rig/S.nii.gz")) + " --pose " +
                               shellQuote(suitePoseFile("elbow90")) + " --spacing-mm 1.2 --out " +
                               shellQuote(dir.file("out")) + " --json");
  ASSERT_EQ(pose.exitCode, 0) << pose.err;
  const nlohmann::json report = nlohmann::json::parse(pose.out);
  std::set<int> bones;
  std::ifstream tissues(dir.file("rig/tissues.csv"));
  for (std::string line; std::getline(tissues, line);) {
    if (line.empty() || line[0] == '#' || line.rfind("label", 0) == 0) continue;
    std::stringstream row(line);
    std::string field[4];
    for (std::string& f : field) std::getline(row, f, ',');
    if (field[3] == "1") bones.insert(std::stoi(field[0]));
  }
  int checked = 0, subdivided = 0;
  for (const auto& l : report["labels"]) {
    if (!bones.count(l["value"].get<int>())) continue;
    if (l["voxels_before"].get<int>() >= 1000) {
      EXPECT_LT(std::fabs(l["change_beyond_floor_percent"].get<double>()), 0.5) << l.dump();
      ++checked;
    }
    // 1.2 mm divides 2.4 and 6 mm: the output grid subdivides each input voxel into 2 x 2 x 5
    // (no output centre on an input voxel's face), so a bone that stays or turns by a quarter
    // turn about a voxel corner has exactly 20 voxels for each of its own. With the centres on
    // the input's centres plus whole output voxels, every other centre along x and y was a tie
    // and no bone came out exact.
    subdivided +=
        l["voxels_after"].get<std::int64_t>() == 20 * l["voxels_before"].get<std::int64_t>();
  }
  EXPECT_GE(checked, 10);
  EXPECT_GE(subdivided, 12);
  // The bones' voxel staircases at the bent elbow no longer meet where a tie put them (19 voxels).
  EXPECT_EQ(report["bone_collisions"]["voxels"].get<int>(), 0) << report["bone_collisions"].dump();
}
