// `repose pose` as a user runs it on the 4 mm phantom: the suite's elbow flexion writes the posed
// maps, the transform and a report whose checks hold where they should; re-running through the
// saved scene is bit-identical; keyframes give one folder per frame; a bad pose file fails with
// one line naming the field and writes nothing.
#include "CliTestFiles.h"
#include "CommandRunner.h"
#include "TestPaths.h"

#include "repose/io/VolumeIO.h"
#include "repose/phantom/Phantom.h"

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <regex>

using namespace repose;
using namespace repose::test;
using json = nlohmann::json;

namespace {

std::string readFile(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  EXPECT_TRUE(in.good()) << path;
  return std::string(std::istreambuf_iterator<char>(in), {});
}

// The 4 mm phantom written into `dir`, and `repose pose`'s arguments for its elbow flexion.
std::string elbowJobOn4mmPhantom(const ScratchDir& dir) {
  EXPECT_EQ(
      runCommand("repose", "phantom --voxel 4 --out " + shellQuote(dir.path().string())).exitCode,
      0);
  return "pose --input " + shellQuote(dir.file("G.nii.gz")) + " --parts " +
         shellQuote(dir.file("S.nii.gz")) + " --pose " + shellQuote(suitePoseFile("elbow90")) +
         " --joint-rings 0";
}

}  // namespace

TEST(PoseCommand, ElbowFlexionWritesPosedMapsTransformAndACheckedReport) {
  ScratchDir dir("pose");
  const std::string d = shellQuote(dir.path().string());
  ASSERT_EQ(runCommand("repose", "phantom --voxel 4 --out " + d).exitCode, 0);
  const std::string common = "pose --input " + shellQuote(dir.file("G.nii.gz")) + " --parts " +
                             shellQuote(dir.file("S.nii.gz")) + " --scene " +
                             shellQuote(dir.file("scene"));
  // The default joint width here: at 4 mm the forearm bones are below the report's 1000-voxel
  // check, so the test demands their rigid copy itself (the suite's one-ring elbow is the image
  // run below).
  const CommandResult first =
      runCommand("repose", common + " --pose " + shellQuote(suitePoseFile("elbow90")) +
                               " --joint-rings 0 --out " + shellQuote(dir.file("a")) + " --json");
  ASSERT_EQ(first.exitCode, 0) << first.err;
  const nlohmann::json report = nlohmann::json::parse(first.out);
  EXPECT_EQ(report, readJsonFile(dir.file("a/report.json")));
  for (const char* f : {"posed_G.nii.gz", "posed_S.nii.gz", "transform.nrrd"})
    EXPECT_TRUE(std::filesystem::exists(dir.file(std::string("a/") + f))) << f;
  EXPECT_FALSE(report["scene_reused"].get<bool>());
  EXPECT_FALSE(report["green_coordinates"]["read"].get<bool>());
  EXPECT_TRUE(std::filesystem::exists(dir.file("scene/tm.green")));
  EXPECT_EQ(report["labels_lost"], 0);
  EXPECT_EQ(report["joint_rings"], 0);
  // The forearm bones follow the forearm.
  bool forearm = false;
  for (const auto& t : report["rigid_tissues"])
    if (t["bone"] == "radius_ulna" && t["group"] == "left forearm and hand") {
      forearm = true;
      EXPECT_EQ(t["checked"].get<bool>(), t["voxels"].get<int>() >= 1000);
      EXPECT_GE(t["dice"].get<double>(), 0.95);
    }
  EXPECT_TRUE(forearm);
  EXPECT_TRUE(report["quality"]["bones_rigid"]["met"].get<bool>());
  // docs/QUALITY.md's target for the whole body.
  EXPECT_LT(std::fabs(report["body"]["volume_change_percent"].get<double>()), 0.5);
  EXPECT_TRUE(report["quality"]["body_within_half_percent"]["met"].get<bool>());
  EXPECT_GT(report["body"]["mass_before_kg"].get<double>(), 10.0);  // phantom tissue table
  int histogram = 0;
  for (const auto& bin : report["distortion"]["histogram"]) histogram += bin["tets"].get<int>();
  EXPECT_EQ(histogram, report["mesh"]["tets"].get<int>());

  // Through the saved scene: the same posed map, bit for bit.
  const CommandResult second =
      runCommand("repose", common + " --pose " + shellQuote(suitePoseFile("elbow90")) +
                               " --joint-rings 0 --out " + shellQuote(dir.file("b")) + " --json");
  ASSERT_EQ(second.exitCode, 0) << second.err;
  const nlohmann::json secondReport = nlohmann::json::parse(second.out);
  EXPECT_TRUE(secondReport["scene_reused"].get<bool>());
  // The Green coordinates were read from the scene, not computed.
  EXPECT_TRUE(secondReport["green_coordinates"]["read"].get<bool>())
      << secondReport["green_coordinates"];
  const Volume a = readVolume(dir.file("a/posed_G.nii.gz")),
               b = readVolume(dir.file("b/posed_G.nii.gz"));
  ASSERT_EQ(a.dims(), b.dims());
  EXPECT_EQ(
      0, std::memcmp(a.data<std::uint8_t>(), b.data<std::uint8_t>(), std::size_t(a.numVoxels())));
  // A scene whose coordinates are gone (written by an older version) or belong to another mesh:
  // computed again, the same map, and saved for the next run.
  for (const bool stale : {false, true}) {
    SCOPED_TRACE(stale ? "stale" : "missing");
    if (stale) {
      std::ofstream(dir.file("scene/tm.green"), std::ios::binary | std::ios::in | std::ios::out)
          .seekp(20)
          .put('\x5a');  // inside the key
    } else {
      std::filesystem::remove(dir.file("scene/tm.green"));
    }
    const std::string out = stale ? "green_stale" : "green_missing";
    const CommandResult again =
        runCommand("repose", common + " --pose " + shellQuote(suitePoseFile("elbow90")) +
                                 " --joint-rings 0 --out " + shellQuote(dir.file(out)) + " --json");
    ASSERT_EQ(again.exitCode, 0) << again.err;
    const nlohmann::json g = nlohmann::json::parse(again.out)["green_coordinates"];
    EXPECT_FALSE(g["read"].get<bool>());
    EXPECT_NE(
        g["note"].get<std::string>().find(stale ? "another transfer mesh or cage" : "no such file"),
        std::string::npos)
        << g;
    const Volume c = readVolume(dir.file(out + "/posed_G.nii.gz"));
    ASSERT_EQ(a.dims(), c.dims());
    EXPECT_EQ(
        0, std::memcmp(a.data<std::uint8_t>(), c.data<std::uint8_t>(), std::size_t(a.numVoxels())));
    const CommandResult next = runCommand(
        "repose", common + " --pose " + shellQuote(suitePoseFile("elbow90")) +
                      " --joint-rings 0 --out " + shellQuote(dir.file(out + "2")) + " --json");
    ASSERT_EQ(next.exitCode, 0) << next.err;
    EXPECT_TRUE(nlohmann::json::parse(next.out)["green_coordinates"]["read"].get<bool>());
  }

  // An image posed alongside: on the posed grid, its values those of the image at rest
  // (a ramp along S, the direction the flexed forearm turns across), background outside the body.
  {
    Volume G = readVolume(dir.file("G.nii.gz"));
    Volume ct(G.geometry(), ScalarType::Float32);
    for (std::int64_t k = 0; k < G.dims()[2]; ++k)
      for (std::int64_t j = 0; j < G.dims()[1]; ++j)
        for (std::int64_t i = 0; i < G.dims()[0]; ++i)
          ct.data<float>()[ct.index(i, j, k)] = 1000.0f + float(k);
    writeVolume(ct, dir.file("ct.nii.gz"));
    const CommandResult withImage = runCommand(
        "repose", common + " --pose " + shellQuote(suitePoseFile("elbow90")) + " --image " +
                      shellQuote(dir.file("ct.nii.gz")) + " --background -1000 --out " +
                      shellQuote(dir.file("img")) + " --json");
    ASSERT_EQ(withImage.exitCode, 0) << withImage.err;
    const Volume posedCt = readVolume(dir.file("img/posed_image.nii.gz"));
    const Volume posedG = readVolume(dir.file("img/posed_G.nii.gz"));
    ASSERT_EQ(posedCt.dims(), posedG.dims());
    // A ramp is reproduced exactly by trilinear interpolation, so each body voxel's value says
    // which rest S it came from. Where the body stays (all but the bent forearm) that is the S of
    // the same RAS point on G's grid; in the forearm it is not. A posed image that ignored the
    // pose, or mixed up the two grids, fails one count or the other.
    std::int64_t body = 0, stayed = 0, moved = 0, background = 0;
    for (std::int64_t k = 0; k < posedG.dims()[2]; ++k)
      for (std::int64_t j = 0; j < posedG.dims()[1]; ++j)
        for (std::int64_t i = 0; i < posedG.dims()[0]; ++i) {
          const std::int64_t v = posedG.index(i, j, k);
          const float value = posedCt.data<float>()[v];
          if (value == -1000) ++background;
          if (posedG.data<std::uint8_t>()[v] == 0) continue;
          ++body;
          const Eigen::Vector3d rest = G.geometry().rasToVoxel(
              posedG.geometry().voxelToRas(double(i), double(j), double(k)));
          const double error = std::abs(double(value) - (1000.0 + rest.z()));
          if (error < 0.05) ++stayed;
          if (error > 5) ++moved;  // more than 5 voxels (20 mm) along S
        }
    EXPECT_GT(stayed, body * 8 / 10) << body;
    EXPECT_GT(moved, body / 200) << body;
    EXPECT_LT(moved, body / 10) << body;
    EXPECT_GT(background, 0);
    const nlohmann::json r = nlohmann::json::parse(withImage.out);
    EXPECT_EQ(r["outputs"]["posed_image"], "posed_image.nii.gz");
    EXPECT_EQ(r["joint_rings"], 1);  // the pose file's
    EXPECT_TRUE(r["scene_reused"].get<bool>());
  }

  // Keyframes: one folder and one report per frame.
  const CommandResult walk =
      runCommand("repose", common + " --pose " + shellQuote(suitePoseFile("walk")) + " --out " +
                               shellQuote(dir.file("walk")) + " --json");
  ASSERT_EQ(walk.exitCode, 0) << walk.err;
  EXPECT_EQ(nlohmann::json::parse(walk.out)["frames"].size(), 7u);
  for (int k = 0; k < 7; ++k)
    EXPECT_TRUE(
        std::filesystem::exists(dir.file("walk/step" + std::to_string(k) + "/report.json")));

  // A bad pose file: one line naming the field, no output folder.
  std::ofstream(dir.file("bad.pose.json"))
      << R"({"format":"repose-pose","version":1,"groups":[{"name":"a","select":{"parts":[4]},)"
      << R"("rotation":{"angle_deg":"ninety"}}]})";
  const CommandResult bad =
      runCommand("repose", common + " --pose " + shellQuote(dir.file("bad.pose.json")) + " --out " +
                               shellQuote(dir.file("c")));
  EXPECT_NE(bad.exitCode, 0);
  EXPECT_NE(bad.err.find("groups[0].rotation.angle_deg: expected a number"), std::string::npos)
      << bad.err;
  EXPECT_EQ(std::count(bad.err.begin(), bad.err.end(), '\n'), 1);
  EXPECT_FALSE(std::filesystem::exists(dir.file("c")));
}

// `--memory` holds for the posed frame as for the reads (4 mm phantom: 2.5M input voxels, 4M
// output voxels at 14 bytes each beside the ~100 MB the rig holds). A budget the rig has used
// up refuses the frame before the work, in one line with the numbers, and leaves no output
// folder. A budget the posed volumes do not fit (what the refusal says is in use, and half the
// frame) makes the frame slab by slab (issue 56): the same files, byte for byte, and the same
// report as a budget that holds it whole; the same budget refuses the frame when a single-file
// output (--posed-labels) asks for it whole.
TEST(PoseCommand, AFrameBeyondTheMemoryBudgetIsMadeSlabBySlabOrRefusedWithTheNumbers) {
  ScratchDir dir("pose_budget");
  const std::string job = elbowJobOn4mmPhantom(dir);
  const CommandResult whole =
      runCommand("repose", job + " --memory 4G --out " + shellQuote(dir.file("enough")));
  ASSERT_EQ(whole.exitCode, 0) << whole.err;
  EXPECT_EQ(whole.out.find("slab by slab"), std::string::npos) << whole.out;
  const CommandResult refused =
      runCommand("repose", job + " --json --memory 64M --out " + shellQuote(dir.file("small")));
  EXPECT_EQ(refused.exitCode, 1);
  EXPECT_TRUE(refused.out.empty()) << refused.out;
  EXPECT_EQ(std::count(refused.err.begin(), refused.err.end(), '\n'), 1) << refused.err;
  for (const char* part : {"repose pose: error: ", "small: frame elbow90 needs ",
                           "for a slab of one slice", "more than the memory budget of 0.0625 GiB"})
    EXPECT_NE(refused.err.find(part), std::string::npos) << part << " in: " << refused.err;
  EXPECT_FALSE(std::filesystem::exists(dir.file("small")));

  // What the process holds beside the frame, as the refusal says it; a budget of that and half
  // what the posed volumes need does not hold the frame whole.
  std::smatch inUse;
  ASSERT_TRUE(
      std::regex_search(refused.err, inUse, std::regex(R"(beside the ([0-9.]+) GiB in use)")))
      << refused.err;
  const json enough = json::parse(readFile(dir.file("enough/report.json")));
  const auto dims = enough["grid"]["dims"];
  const double need = 14.0 * dims[0].get<double>() * dims[1].get<double>() * dims[2].get<double>();
  const std::string budget =
      std::to_string(long((std::stod(inUse[1]) * 1073741824.0 + need / 2) / 1048576)) + "M";
  const CommandResult streamed =
      runCommand("repose", job + " --memory " + budget + " --out " + shellQuote(dir.file("slabs")));
  ASSERT_EQ(streamed.exitCode, 0) << streamed.err;
  EXPECT_NE(streamed.out.find("made slab by slab"), std::string::npos) << streamed.out;
  for (const char* name : {"posed_G.nii.gz", "posed_S.nii.gz", "transform.nrrd"})
    EXPECT_EQ(readFile(dir.file(std::string("enough/") + name)),
              readFile(dir.file(std::string("slabs/") + name)))
        << name;
  json b = json::parse(readFile(dir.file("slabs/report.json")));
  EXPECT_GT(b["streamed"]["slabs"].get<int>(), 1);
  b.erase("streamed");
  EXPECT_EQ(enough.dump(), b.dump());

  const CommandResult whole1 =
      runCommand("repose", job + " --json --memory " + budget + " --posed-labels " +
                               shellQuote(dir.file("one.nii.gz")) + " --out " +
                               shellQuote(dir.file("single")));
  EXPECT_EQ(whole1.exitCode, 1);
  for (const char* part :
       {"single: frame elbow90 needs ", " output voxels", "the frame is made slab by slab"})
    EXPECT_NE(whole1.err.find(part), std::string::npos) << part << " in: " << whole1.err;
  EXPECT_FALSE(std::filesystem::exists(dir.file("single")));
}

// DICOM SEG slab by slab (issue 56): `--output-format dcmseg --out-of-core` writes the posed maps
// in pieces, the voxels of the frame made whole; on a grid whose SEG would pass DICOM's 4 GiB of
// pixel data (0.25 mm: 17G output voxels), one line naming the file before the work, exit 1, no
// output folder.
TEST(PoseCommand, ADicomSegIsMadeSlabBySlabOrRefusedBeforeTheWorkBeyondFourGiB) {
  ScratchDir dir("pose_dcmseg");
  const std::string job = elbowJobOn4mmPhantom(dir);
  const CommandResult whole = runCommand("repose", job + " --out " + shellQuote(dir.file("whole")));
  ASSERT_EQ(whole.exitCode, 0) << whole.err;
  const CommandResult slabs =
      runCommand("repose", job + " --output-format dcmseg --out-of-core --out " +
                               shellQuote(dir.file("slabs")));
  ASSERT_EQ(slabs.exitCode, 0) << slabs.err;
  EXPECT_NE(slabs.out.find("made slab by slab"), std::string::npos) << slabs.out;
  for (const char* map : {"posed_G", "posed_S"}) {
    const Volume a = readVolume(dir.file(std::string("whole/") + map + ".nii.gz"));
    const Volume b = readVolume(dir.file(std::string("slabs/") + map + ".dcm"));
    ASSERT_EQ(a.dims(), b.dims()) << map;
    EXPECT_EQ(std::memcmp(a.layerData(), b.layerData(),
                          std::size_t(a.numVoxels()) * scalarSize(a.scalarType())),
              0)
        << map;
  }
  const CommandResult refused =
      runCommand("repose", job + " --output-format dcmseg --out-of-core --spacing-mm 0.25 --out " +
                               shellQuote(dir.file("fine")));
  EXPECT_EQ(refused.exitCode, 1);
  EXPECT_EQ(std::count(refused.err.begin(), refused.err.end(), '\n'), 1) << refused.err;
  for (const char* part : {"repose pose: error: ", "fine/posed_G.dcm: frame elbow90 as DICOM SEG",
                           "more than the 4 GiB a DICOM object's pixel data can hold"})
    EXPECT_NE(refused.err.find(part), std::string::npos) << part << " in: " << refused.err;
  EXPECT_FALSE(std::filesystem::exists(dir.file("fine")));
}

// A body that fills its grid (no margin: the hands a voxel from the grid's sides, as in maps cut
// to the body's box) with its left arm raised 90 degrees sideways: the hand ends far beyond the
// input grid, and the output grid grows to hold it, so nothing is clipped (issue 65, item 4).
TEST(PoseCommand, ABodyFillingItsGridIsPosedOntoAGrownGridThatHoldsEveryVoxel) {
  ScratchDir dir("pose_edge");
  ASSERT_EQ(
      runCommand("repose", "phantom --voxel 4 --margin 0 --out " + shellQuote(dir.path().string()))
          .exitCode,
      0);
  const Volume rest = readVolume(dir.file("S.nii.gz"));
  // The input grid's box in RAS (voxel centres), and the rest body reaching its sides.
  Eigen::Vector3d lo = Eigen::Vector3d::Constant(1e300), hi = -lo;
  for (const std::int64_t i : {std::int64_t(0), rest.dims()[0] - 1})
    for (const std::int64_t j : {std::int64_t(0), rest.dims()[1] - 1})
      for (const std::int64_t k : {std::int64_t(0), rest.dims()[2] - 1}) {
        lo = lo.cwiseMin(rest.geometry().voxelToRas(i, j, k));
        hi = hi.cwiseMax(rest.geometry().voxelToRas(i, j, k));
      }
  const CommandResult pose =
      runCommand("repose", "pose --input " + shellQuote(dir.file("G.nii.gz")) + " --parts " +
                               shellQuote(dir.file("S.nii.gz")) + " --pose " +
                               shellQuote(suitePoseFile("arm_raise90")) + " --out " +
                               shellQuote(dir.file("out")) + " --json");
  ASSERT_EQ(pose.exitCode, 0) << pose.err;
  const json report = json::parse(pose.out);
  EXPECT_TRUE(report["targets"]["met"].get<bool>()) << report["targets"].dump();
  EXPECT_EQ(report["labels_lost"], 0);
  const Volume posed = readVolume(dir.file("out/posed_S.nii.gz"));
  EXPECT_GT(posed.numVoxels(), rest.numVoxels());
  // The raised hand: its voxels lie beyond the input grid's box, by more than a hand's length.
  std::int64_t handVoxels = 0, beyond = 0;
  double furthestMm = 0;
  for (std::int64_t k = 0; k < posed.dims()[2]; ++k)
    for (std::int64_t j = 0; j < posed.dims()[1]; ++j)
      for (std::int64_t i = 0; i < posed.dims()[0]; ++i) {
        if (posed.valueAsDouble(posed.index(i, j, k)) != kPartHandLeft) continue;
        ++handVoxels;
        const Eigen::Vector3d x = posed.geometry().voxelToRas(i, j, k);
        const double out = (lo - x).cwiseMax(x - hi).maxCoeff();
        if (out > 0) ++beyond, furthestMm = std::max(furthestMm, out);
      }
  EXPECT_GT(handVoxels, 100);
  EXPECT_EQ(beyond, handVoxels) << "the whole raised hand is outside the input grid";
  EXPECT_GT(furthestMm, 150) << "the arm's length beyond the grid's side";
  // Nothing of the body is clipped at the grid's old sides: it keeps its volume.
  EXPECT_LT(std::fabs(report["body"]["volume_change_percent"].get<double>()), 0.5);
}
