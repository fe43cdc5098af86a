// A coarse map end to end as a dosimetry user brings one (issue 65): the whole skeleton as one
// label inside a body label, a few organs, no label names, and the body touching the grid's edge
// (hands and feet on its faces). `repose rig` takes it with no option and `repose pose` raises an
// arm beyond the input grid: the output grid grows to hold it, no label is lost, every target
// holds.
#include "CliTestFiles.h"
#include "CommandRunner.h"
#include "TestPaths.h"

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <algorithm>
#include <filesystem>
#include <fstream>

using namespace repose::test;

TEST(CoarseMapCommand, RigsWithNoOptionAndPosesAnArmBeyondTheInputGrid) {
  ScratchDir dir;
  const std::string d = shellQuote(dir.path().string());
  ASSERT_EQ(runCommand("repose",
                       "phantom --voxel 4 --arms-resting --gap-mm 4,15 --margin 0 "
                       "--labels coarse --out " +
                           d)
                .exitCode,
            0);
  std::filesystem::remove(dir.file("S.nii.gz"));
  std::filesystem::remove(dir.file("skeleton.json"));
  const CommandResult rig =
      runCommand("repose", "rig --input " + shellQuote(dir.file("G.nii.gz")) + " --out " +
                               shellQuote(dir.file("rig")) + " --json");
  ASSERT_EQ(rig.exitCode, 0) << rig.err;
  const nlohmann::json rigReport = nlohmann::json::parse(rig.out);
  EXPECT_EQ(rigReport["convention"], "coarse (body and skeleton)");
  EXPECT_GT(rigReport["skeleton_split"]["pieces"].get<int>(), 10);
  EXPECT_EQ(rigReport["missing"].size(), 0u) << rigReport["missing"].dump();
  const nlohmann::json inputGrid = nlohmann::json::parse(
      runCommand("repose", "info " + shellQuote(dir.file("G.nii.gz")) + " --json").out);

  const CommandResult pose =
      runCommand("repose", "pose --input " + shellQuote(dir.file("G.nii.gz")) + " --parts " +
                               shellQuote(dir.file("rig/S.nii.gz")) + " --pose " +
                               shellQuote(suitePoseFile("arm_raise90")) + " --out " +
                               shellQuote(dir.file("raised")) + " --json");
  ASSERT_EQ(pose.exitCode, 0) << pose.err;
  const nlohmann::json report = nlohmann::json::parse(pose.out);
  // The raised arm reaches beyond the input grid's side: the output grid is wider.
  EXPECT_GT(report["grid"]["dims"][0].get<int>(), inputGrid["dimensions"][0].get<int>() + 20)
      << report["grid"].dump() << inputGrid.dump();
  EXPECT_EQ(report["labels_lost"], 0);
  EXPECT_TRUE(report["quality"]["all_met"].get<bool>()) << report["quality"].dump();
  for (const auto& l : report["labels"])
    EXPECT_LT(std::fabs(l["change_beyond_floor_percent"].get<double>()), 1.0) << l.dump();
}

TEST(CoarseMapCommand, ARealChestSegmentationsSkeletonIsNotSplitIntoLimbs) {
  // 3D Slicer's sample chest segmentation (ribs, cervical, thoracic and lumbar columns, lungs,
  // tissue; 340 mm along S): no convention names it, and the error says how to name a skeleton
  // and a body. Named so, its ribs are not taken for arms: a skeleton of part of a body is
  // refused in one line, and nothing is written.
  ScratchDir dir;
  const std::string seg = std::string(REPOSE_DATA_DIR) + "/slicer_seg/Segmentation.seg.nrrd";
  const CommandResult unnamed = runCommand(
      "repose", "rig --input " + shellQuote(seg) + " --out " + shellQuote(dir.file("a")));
  EXPECT_NE(unnamed.exitCode, 0);
  EXPECT_NE(unnamed.err.find("bone skeleton for a label holding every bone, body for the body's"),
            std::string::npos)
      << unnamed.err;
  {
    std::ofstream csv(dir.file("chest.csv"));
    csv << "label,bone\n1,skeleton\n2,skeleton\n3,skeleton\n4,skeleton\n7,body\n";
  }
  const CommandResult named = runCommand("repose", "rig --input " + shellQuote(seg) + " --labels " +
                                                       shellQuote(dir.file("chest.csv")) +
                                                       " --out " + shellQuote(dir.file("b")));
  EXPECT_NE(named.exitCode, 0);
  EXPECT_NE(named.err.find("the skeleton label spans 330 mm along S: it is split into bones only "
                           "in a whole body"),
            std::string::npos)
      << named.err;
  EXPECT_EQ(std::count(named.err.begin(), named.err.end(), '\n'), 1) << named.err;
  EXPECT_FALSE(std::filesystem::exists(dir.file("b")));
}
