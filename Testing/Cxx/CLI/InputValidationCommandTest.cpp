// Validation on input and memory budgets (issue 10, items 3 and 6), as a user meets them: labels
// the label table does not name are warned about, sheared voxel axes are described and refused
// for posing, anisotropic voxels (the seed's 1.3 x 1.3 x 7.2 mm MRI) go through the whole chain,
// empty segmentations are refused naming the file, and every command that reads a volume in core
// estimates it first and refuses above --memory with the numbers, leaving no output.
#include "CommandRunner.h"
#include "TestPaths.h"

#include "repose/io/VolumeIO.h"
#include "repose/volume/LabelStatistics.h"

#include <Eigen/Geometry>
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <filesystem>
#include <map>

using namespace repose;
using namespace repose::test;

namespace {

void expectCleanFailure(const CommandResult& r, const std::string& file, const std::string& what) {
  EXPECT_EQ(r.exitCode, 1) << r.err;
  EXPECT_EQ(lineCount(r.err), 1) << r.err;
  EXPECT_NE(r.err.find(file), std::string::npos) << r.err;
  EXPECT_NE(r.err.find(what), std::string::npos) << r.err;
}

// A body of two named parts (a box and a ball) on `g`, plus label 7 in a corner if asked,
// which the table does not name.
Volume twoParts(const VolumeGeometry& g, bool unnamed) {
  Volume v(g, ScalarType::UInt8);
  v.setLabelMap(true);
  for (const auto& [value, name] : {std::pair<int, const char*>{1, "trunk"}, {2, "head"}}) {
    Label l;
    l.value = value, l.name = name;
    v.labels().set(l);
  }
  const auto [lo, hi] = g.rasBounds();
  const Eigen::Vector3d c = (lo + hi) / 2, half = (hi - lo) / 2;
  std::uint8_t* d = v.data<std::uint8_t>();
  for (std::int64_t k = 0; k < g.dims[2]; ++k)
    for (std::int64_t j = 0; j < g.dims[1]; ++j)
      for (std::int64_t i = 0; i < g.dims[0]; ++i) {
        const Eigen::Vector3d p = g.voxelToRas(double(i), double(j), double(k)) - c;
        const Eigen::Vector3d q = p.cwiseQuotient(half);
        if (q.cwiseAbs().maxCoeff() < 0.55 && q.z() < 0.2) d[v.index(i, j, k)] = 1;
        if ((q - Eigen::Vector3d(0, 0, 0.45)).norm() < 0.3) d[v.index(i, j, k)] = 2;
        if (unnamed && i < 3 && j < 3 && k < 3) d[v.index(i, j, k)] = 7;
      }
  return v;
}

}  // namespace

TEST(InputValidation, LabelsTheTableDoesNotNameAreWarnedAbout) {
  ScratchDir dir("unnamed");
  const std::string file = dir.file("parts.nii.gz");
  writeVolume(twoParts(VolumeGeometry::make({40, 40, 40}, {3, 3, 3}, {0, 0, 0}), true), file);
  const CommandResult j = runCommand("repose", "info " + shellQuote(file) + " --json");
  ASSERT_EQ(j.exitCode, 0) << j.err;
  EXPECT_EQ(nlohmann::json::parse(j.out)["labels_unnamed"], nlohmann::json::array({7}));
  const CommandResult t = runCommand("repose", "info " + shellQuote(file));
  EXPECT_NE(t.out.find("no name in the label table: [7]"), std::string::npos) << t.out;
  // Posing commands say so once on stderr and go on: the label is posed like the others.
  const CommandResult cage =
      runCommand("repose", "cage --parts " + shellQuote(file) + " --vertices 80 --out " +
                               shellQuote(dir.file("cage.obj")));
  ASSERT_EQ(cage.exitCode, 0) << cage.err;
  EXPECT_NE(cage.err.find("warning: " + file + ": label 7 has voxels but no name"),
            std::string::npos)
      << cage.err;
  // warp counts labels as it poses (out of core it never holds the volume) and says so too.
  const std::string cageFile = shellQuote(dir.file("cage.obj")), mesh = dir.file("tm.vtu");
  ASSERT_EQ(runCommand("repose", "mesh --parts " + shellQuote(file) + " --cage " + cageFile +
                                     " --out " + shellQuote(mesh))
                .exitCode,
            0);
  const CommandResult warp =
      runCommand("repose", "warp --input " + shellQuote(file) + " --mesh " + shellQuote(mesh) +
                               " --cage " + cageFile + " --posed-cage " + cageFile + " --out " +
                               shellQuote(dir.file("posed.nii.gz")) + " --json");
  ASSERT_EQ(warp.exitCode, 0) << warp.err;
  EXPECT_EQ(nlohmann::json::parse(warp.out)["labels_unnamed"], nlohmann::json::array({7}));
  EXPECT_NE(warp.err.find("repose warp: warning: " + file + ": label 7 has voxels but no name"),
            std::string::npos)
      << warp.err;
  // A named table has nothing to warn about; neither has a file with no table at all.
  writeVolume(twoParts(VolumeGeometry::make({40, 40, 40}, {3, 3, 3}, {0, 0, 0}), false),
              dir.file("named.nii.gz"));
  EXPECT_EQ(nlohmann::json::parse(
                runCommand("repose", "info " + shellQuote(dir.file("named.nii.gz")) + " --json")
                    .out)["labels_unnamed"],
            nlohmann::json::array());
}

TEST(InputValidation, ShearedAxesAreDescribedConvertedAndRefusedForPosing) {
  ScratchDir dir("sheared");
  // k leans 16.7 degrees towards j, as a CT series acquired with a tilted gantry.
  VolumeGeometry g = VolumeGeometry::make({30, 30, 30}, {3, 3, 3}, {-40, -40, -40});
  g.ijkToRas.block<3, 1>(0, 2) = Eigen::Vector3d(0, 0.9, 3);
  const std::string file = dir.file("sheared.nrrd");
  const Volume v = twoParts(g, false);
  writeVolume(v, file);
  const CommandResult info = runCommand("repose", "info " + shellQuote(file) + " --json");
  ASSERT_EQ(info.exitCode, 0) << info.err;
  const auto j = nlohmann::json::parse(info.out);
  EXPECT_NEAR(j["axis_skew_deg"].get<double>(), std::atan(0.3) * 180 / M_PI, 1e-6);
  // Volumes count the sheared voxel's true size, |det| = 3 x 3 x 3 = 27 mm3 (not 3 x 3 x 3.13).
  EXPECT_NEAR(j["voxel_volume_mm3"].get<double>(), 27, 1e-9);
  const std::vector<LabelCount> counts = countLabels(v);
  EXPECT_NEAR(j["labels"][0]["volume_ml"].get<double>(), counts[0].voxels * 0.027, 1e-9);
  EXPECT_NE(runCommand("repose", "info " + shellQuote(file)).out.find("not orthogonal"),
            std::string::npos);
  // Converted exactly (NIfTI's sform holds the shear).
  ASSERT_EQ(runCommand("repose",
                       "convert " + shellQuote(file) + " " + shellQuote(dir.file("sheared.nii.gz")))
                .exitCode,
            0);
  EXPECT_LT((readVolume(dir.file("sheared.nii.gz")).geometry().ijkToRas - g.ijkToRas).norm(), 1e-4);
  // Not posed: the cage and the mesh assume orthogonal axes.
  const std::string cage = dir.file("cage.obj");
  expectCleanFailure(
      runCommand("repose", "cage --parts " + shellQuote(file) + " --out " + shellQuote(cage)), file,
      "voxel axes are not orthogonal (sheared by 16.7 degrees");
  EXPECT_FALSE(std::filesystem::exists(cage));
}

TEST(InputValidation, AnisotropicVoxelsLikeTheSeedsMriGoThroughCageMeshAndWarp) {
  ScratchDir dir("aniso");
  // 1.3 x 1.3 x 7.2 mm, oblique: the seed's MRI voxels.
  const Eigen::Matrix3d R = Eigen::AngleAxisd(0.3, Eigen::Vector3d(1, 2, 3).normalized()).matrix();
  const VolumeGeometry g = VolumeGeometry::make({90, 90, 18}, {1.3, 1.3, 7.2}, {-60, -60, -65}, R);
  const Volume v = twoParts(g, false);
  const std::string parts = dir.file("parts.nii.gz"), cage = dir.file("cage.obj"),
                    mesh = dir.file("tm.vtu"), out = dir.file("posed.nii.gz");
  writeVolume(v, parts);
  ASSERT_EQ(runCommand("repose", "cage --parts " + shellQuote(parts) + " --vertices 80 --out " +
                                     shellQuote(cage))
                .exitCode,
            0);
  const CommandResult m = runCommand("repose", "mesh --parts " + shellQuote(parts) + " --cage " +
                                                   shellQuote(cage) + " --out " + shellQuote(mesh));
  ASSERT_EQ(m.exitCode, 0) << m.err;
  const CommandResult w =
      runCommand("repose", "warp --input " + shellQuote(parts) + " --mesh " + shellQuote(mesh) +
                               " --cage " + shellQuote(cage) + " --posed-cage " + shellQuote(cage) +
                               " --out " + shellQuote(out) + " --json");
  ASSERT_EQ(w.exitCode, 0) << w.err;
  // The rest pose gives the input back on the input's own grid (spacing and axes kept).
  const Volume posed = readVolume(out);
  EXPECT_LT((posed.geometry().spacing() - g.spacing()).norm(), 1e-4);
  EXPECT_LT((posed.geometry().directions() - g.directions()).norm(), 1e-4);
  std::map<int, double> before, after;
  for (const LabelCount& c : countLabels(v)) before[c.value] = c.volumeMm3;
  for (const LabelCount& c : countLabels(posed)) after[c.value] = c.volumeMm3;
  ASSERT_EQ(after.size(), before.size());
  for (const auto& [value, mm3] : before) EXPECT_NEAR(after[value] / mm3, 1.0, 0.01) << value;
}

TEST(InputValidation, EmptySegmentationsAreDescribedButRefusedForPosing) {
  ScratchDir dir("empty");
  Volume v(VolumeGeometry::make({20, 20, 20}, {2, 2, 2}, {0, 0, 0}), ScalarType::UInt8);
  v.setLabelMap(true);
  const std::string file = dir.file("empty.nii.gz");
  writeVolume(v, file);
  const CommandResult info = runCommand("repose", "info " + shellQuote(file) + " --json");
  ASSERT_EQ(info.exitCode, 0) << info.err;
  EXPECT_EQ(nlohmann::json::parse(info.out)["labels_present"], 0);
  expectCleanFailure(runCommand("repose", "cage --parts " + shellQuote(file) + " --out " +
                                              shellQuote(dir.file("c.obj"))),
                     file, "the segmentation is empty");
  const std::string pose = std::string(REPOSE_SOURCE_DIR) + "/bench/poses/elbow90.pose.json";
  expectCleanFailure(runCommand("repose", "pose --input " + shellQuote(file) + " --parts " +
                                              shellQuote(file) + " --pose " + shellQuote(pose) +
                                              " --out " + shellQuote(dir.file("frames"))),
                     file, "the segmentation is empty");
  EXPECT_FALSE(std::filesystem::exists(dir.file("c.obj")));
  EXPECT_FALSE(std::filesystem::exists(dir.file("frames")));
}

TEST(InputValidation, EveryReaderRefusesAVolumeAboveTheMemoryBudgetWithTheNumbers) {
  ScratchDir dir("budget");
  // 200^3 uint8 = 7.6 MiB in core (15.3 MiB with teem's copy for NRRD): above a budget the
  // process itself has already used up.
  const Volume v = twoParts(VolumeGeometry::make({200, 200, 200}, {1, 1, 1}, {0, 0, 0}), false);
  for (const char* name : {"big.nii.gz", "big.nrrd", "big.seg.nrrd"}) {
    const std::string file = dir.file(name);
    writeVolume(v, file);
    SCOPED_TRACE(name);
    expectCleanFailure(runCommand("repose", "info " + shellQuote(file) + " --memory 1M"), file,
                       "reading it needs ");
    EXPECT_NE(runCommand("repose", "info " + shellQuote(file) + " --memory 1M")
                  .err.find(std::string("MiB (8000000 voxels x ") +
                            (name[4] == 'n' && name[5] == 'i' ? "1 bytes)" : "2 bytes)")),
              std::string::npos);
    expectCleanFailure(runCommand("repose", "convert " + shellQuote(file) + " " +
                                                shellQuote(dir.file("out.nii")) + " --memory 1M"),
                       file, "the memory budget is already used up");
    EXPECT_FALSE(std::filesystem::exists(dir.file("out.nii")));
    EXPECT_EQ(runCommand("repose", "info " + shellQuote(file) + " --memory 2G").exitCode, 0);
  }
  const std::string pose = std::string(REPOSE_SOURCE_DIR) + "/bench/poses/elbow90.pose.json";
  const std::string big = dir.file("big.nii.gz");
  expectCleanFailure(
      runCommand("repose", "pose --input " + shellQuote(big) + " --parts " + shellQuote(big) +
                               " --pose " + shellQuote(pose) + " --out " +
                               shellQuote(dir.file("frames")) + " --memory 1M"),
      big, "reading it needs");
  EXPECT_FALSE(std::filesystem::exists(dir.file("frames")));
  // DICOM: staged as float32, then int16.
  const std::string dicom = dataPath("totalsegmentator/example_ct_dicom_uncompressed");
  expectCleanFailure(runCommand("repose", "info " + shellQuote(dicom) + " --memory 1M"), dicom,
                     "voxels x 8 bytes");
}
