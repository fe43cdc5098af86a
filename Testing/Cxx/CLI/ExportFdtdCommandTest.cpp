// `repose export-fdtd` as a user runs it: the phantom, an ICRP-coded body and a real
// TotalSegmentator segmentation become FDTD models whose report adds up; resampling reports the
// change; labels without a tissue, bad frequencies and bad names fail in one line, writing nothing.
#include "CliTestFiles.h"
#include "CommandRunner.h"
#include "TestPaths.h"

#include "repose/io/VolumeIO.h"
#include "repose/volume/LabelStatistics.h"

#include <gtest/gtest.h>

#include <filesystem>
#include <set>

using namespace repose;
using namespace repose::test;
namespace fs = std::filesystem;

namespace {

void expectNothingWritten(const ScratchDir& dir, const std::string& stem) {
  for (const char* ext : {".h5", ".csx.xml", ".json"})
    EXPECT_FALSE(fs::exists(dir.file(stem + ext))) << stem << ext;
}

void expectCleanFailure(const CommandResult& r, const std::string& says) {
  EXPECT_NE(r.exitCode, 0);
  EXPECT_EQ(lineCount(r.err), 1) << r.err;
  EXPECT_NE(r.err.find(says), std::string::npos) << r.err;
}

// The report's sums: each label's mass is density x volume, the materials' masses add up to the
// body's, and every label of G is listed once with its tissue.
void expectConsistentReport(const nlohmann::json& j, const std::string& g) {
  const Volume organs = readVolume(g);
  std::set<int> present;
  double materialMass = 0;
  for (const auto& m : j["materials"])
    if (m["index"].get<int>() > 0) materialMass += m["mass_kg"].get<double>();
  double labelMass = 0;
  for (const auto& l : j["labels"]) {
    labelMass += l["mass_kg"].get<double>();
    EXPECT_FALSE(l["tissue"].get<std::string>().empty());
    present.insert(l["label"].get<int>());
  }
  std::set<int> inG;
  for (const LabelCount& c : countLabels(organs)) inG.insert(c.value);
  EXPECT_EQ(present, inG);
  EXPECT_NEAR(materialMass, j["body"]["mass_kg"].get<double>(), 1e-9 * materialMass);
  EXPECT_NEAR(labelMass, materialMass, 1e-9 * materialMass);
  EXPECT_GT(materialMass, 0);
}

}  // namespace

TEST(ExportFdtdCommand, ThePhantomBecomesAModelWhoseReportAddsUp) {
  ScratchDir dir;
  ASSERT_EQ(
      runCommand("repose", "phantom --voxel 6 --out " + shellQuote(dir.path().string())).exitCode,
      0);
  const std::string g = dir.file("G.nii.gz"), model = dir.file("body.h5");
  const CommandResult r =
      runCommand("repose", "export-fdtd --input " + shellQuote(g) + " --out " + shellQuote(model) +
                               " --frequency 2.45GHz --json");
  ASSERT_EQ(r.exitCode, 0) << r.err;
  const nlohmann::json j = nlohmann::json::parse(r.out);
  EXPECT_EQ(j, readJsonFile(dir.file("body.json")));
  EXPECT_TRUE(fs::exists(model));
  EXPECT_TRUE(fs::exists(dir.file("body.csx.xml")));
  EXPECT_DOUBLE_EQ(j["frequency_hz"].get<double>(), 2.45e9);
  EXPECT_FALSE(j["grid"]["resampled"].get<bool>());
  EXPECT_DOUBLE_EQ(j["body"]["volume_change_percent"].get<double>(), 0.0);
  expectConsistentReport(j, g);
  // The phantom's own densities (Resources/Tissues/phantom.csv) and names drive the tissues.
  int muscleLabels = 0;
  for (const auto& l : j["labels"])
    if (l["name"] == "muscle") {
      EXPECT_EQ(l["tissue"], "Muscle");
      EXPECT_DOUBLE_EQ(l["density_kg_m3"].get<double>(), 1090);
      ++muscleLabels;
    }
  EXPECT_EQ(muscleLabels, 1);
  // Muscle at 2.45 GHz: IT'IS v5 gives 52.7295, 1.73879 S/m (DielectricTest).
  bool muscle = false;
  for (const auto& m : j["materials"])
    if (m["tissue"] == "Muscle") {
      muscle = true;
      EXPECT_NEAR(m["eps_r"].get<double>(), 52.7295, 1e-3);
      EXPECT_NEAR(m["sigma_s_m"].get<double>(), 1.73879, 1e-4);
    }
  EXPECT_TRUE(muscle);

  // Coarser cells: resampled, each tissue's change reported, the body within a few percent.
  const CommandResult coarse =
      runCommand("repose", "export-fdtd --input " + shellQuote(g) + " --out " +
                               shellQuote(dir.file("coarse.h5")) + " --spacing-mm 10 --json");
  ASSERT_EQ(coarse.exitCode, 0) << coarse.err;
  const nlohmann::json c = nlohmann::json::parse(coarse.out);
  EXPECT_TRUE(c["grid"]["resampled"].get<bool>());
  EXPECT_EQ(c["grid"]["spacing_mm"][0].get<double>(), 10.0);
  EXPECT_LT(std::abs(c["body"]["volume_change_percent"].get<double>()), 3.0);
  expectConsistentReport(c, g);
}

TEST(ExportFdtdCommand, AnIcrpCodedBodyAndARealTotalSegmentatorMapGetEveryLabelATissue) {
  ScratchDir dir;
  ASSERT_EQ(runCommand("repose", "phantom --voxel 8 --labels icrp110 --arms-resting --out " +
                                     shellQuote(dir.path().string()))
                .exitCode,
            0);
  const CommandResult icrp =
      runCommand("repose", "export-fdtd --input " + shellQuote(dir.file("G.nii.gz")) + " --out " +
                               shellQuote(dir.file("icrp.h5")) + " --json");
  ASSERT_EQ(icrp.exitCode, 0) << icrp.err;
  const nlohmann::json j = nlohmann::json::parse(icrp.out);
  expectConsistentReport(j, dir.file("G.nii.gz"));
  int cortical = 0;
  for (const auto& l : j["labels"]) {
    EXPECT_EQ(l["density_source"].get<std::string>().rfind("icrp110", 0), 0u) << l.dump();
    if (l["name"].get<std::string>().find("cortical") != std::string::npos) {
      EXPECT_EQ(l["tissue"], "Bone (Cortical)") << l.dump();
      ++cortical;
    }
  }
  EXPECT_GE(cortical, 5);  // humeri, femora, ... by ICRP 110's organ names

  const std::string seg = dataPath("totalsegmentator/example_seg.nii.gz");
  const CommandResult ts =
      runCommand("repose", "export-fdtd --input " + shellQuote(seg) + " --out " +
                               shellQuote(dir.file("ts.h5")) + " --frequency 64MHz --json");
  ASSERT_EQ(ts.exitCode, 0) << ts.err;
  const nlohmann::json t = nlohmann::json::parse(ts.out);
  EXPECT_EQ(t["labels"].size(), 41u);
  expectConsistentReport(t, seg);
  int liver = 0;
  for (const auto& l : t["labels"])
    if (l["name"] == "liver") {
      EXPECT_EQ(l["tissue"], "Liver");
      ++liver;
    }
  EXPECT_EQ(liver, 1);
}

TEST(ExportFdtdCommand, FailuresAreOneLineAndWriteNothing) {
  ScratchDir dir;
  // A user's segmentation with a label no rule knows.
  Volume v(VolumeGeometry::make({6, 5, 4}, {2, 2, 2}, {0, 0, 0}), ScalarType::UInt8);
  v.setLabelMap(true);
  for (std::int64_t n = 0; n < v.numVoxels(); ++n) v.data<std::uint8_t>()[n] = std::uint8_t(n % 3);
  Label liver, tumour;
  liver.value = 1;
  liver.name = "liver";
  tumour.value = 2;
  tumour.name = "tumour";
  v.labels().set(liver);
  v.labels().set(tumour);
  const std::string g = dir.file("g.nii.gz");
  writeVolume(v, g);
  const std::string out = " --out " + shellQuote(dir.file("m.h5"));
  expectCleanFailure(
      runCommand("repose", "export-fdtd --input " + shellQuote(g) + out + " --labels phantom"),
      "2 (tumour)");
  expectNothingWritten(dir, "m");
  expectCleanFailure(
      runCommand("repose", "export-fdtd --input " + shellQuote(g) + out + " --frequency 50GHz"),
      "outside 10 Hz to 20 GHz");
  expectCleanFailure(runCommand("repose", "export-fdtd --input " + shellQuote(g) + " --out " +
                                              shellQuote(dir.file("m.vtk"))),
                     "name it MODEL.h5");
  expectNothingWritten(dir, "m");
  // 0.01 mm cells over G's 12 x 10 x 8 mm: 960M cells, refused before they are allocated.
  expectCleanFailure(runCommand("repose", "export-fdtd --input " + shellQuote(g) + out +
                                              " --labels phantom --default-tissue Muscle "
                                              "--spacing-mm 0.01 --memory 300M"),
                     "more than the memory budget leaves");
  expectNothingWritten(dir, "m");

  // With a map for the unknown label it goes through; the map's line is the rule.
  const std::string map = dir.file("map.csv");
  std::ofstream(map) << "label,tissue\n2,Liver\n";
  const CommandResult ok =
      runCommand("repose", "export-fdtd --input " + shellQuote(g) + out +
                               " --labels phantom --tissue-map " + shellQuote(map) + " --json");
  ASSERT_EQ(ok.exitCode, 0) << ok.err;
  const nlohmann::json j = nlohmann::json::parse(ok.out);
  // Background and two of liver: the phantom's liver density (1079) and, for the label the
  // convention does not know, the density of soft tissue (1050).
  ASSERT_EQ(j["materials"].size(), 3u);
  EXPECT_EQ(j["materials"][1]["tissue"], "Liver");
  EXPECT_EQ(j["materials"][2]["tissue"], "Liver");
  EXPECT_NE(j["materials"][1]["density_kg_m3"], j["materials"][2]["density_kg_m3"]);
  EXPECT_EQ(j["labels"][1]["rule"], map);
}
