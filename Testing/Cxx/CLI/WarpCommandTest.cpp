// `repose warp` as a user runs it: phantom -> cage -> mesh -> a posed cage -> the posed label map
// and image. A whole-voxel translation of the cage must give the input shifted, voxel for voxel;
// bad requests fail with one line naming the problem and write nothing.
#include "CliTestFiles.h"
#include "CommandRunner.h"
#include "TestPaths.h"

#include "repose/io/MeshIO.h"
#include "repose/io/VolumeIO.h"
#include "repose/phantom/Phantom.h"
#include "repose/phantom/PhantomPoses.h"

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <filesystem>

using namespace repose;
using namespace repose::test;

namespace {

struct Prepared {
  ScratchDir dir{"warp"};
  std::string organs, parts, cage, mesh;
  explicit Prepared(double voxelMm = 4) {
    organs = dir.file("G.nii.gz"), parts = dir.file("S.nii.gz");
    cage = dir.file("cage.obj"), mesh = dir.file("tm.vtu");
    makePhantomRig(dir.path().string(), voxelMm, cage, mesh);
  }
  // The cage with the left elbow flexed by `degrees`, written beside the mesh; its path.
  std::string elbowFlexed(double voxelMm, double degrees) const {
    PhantomOptions po;
    po.voxelMm = voxelMm;
    TriangleMesh posed = readTriangleMesh(cage);
    posed.vertices = phantomElbowFlexion(Phantom(po), posed, degrees);
    const std::string path = dir.file("posed.obj");
    writeTriangleMesh(posed, path);
    return path;
  }
  std::string common(const std::string& posed) const {
    return "warp --input " + shellQuote(organs) + " --mesh " + shellQuote(mesh) + " --cage " +
           shellQuote(cage) + " --posed-cage " + shellQuote(posed);
  }
};

}  // namespace

TEST(WarpCommand, WholeVoxelTranslationGivesTheShiftedMapAndImage) {
  Prepared p;
  const Volume G = readVolume(p.organs);
  // Move the cage by (2, -3, 5) voxels of 4 mm.
  TriangleMesh cage = readTriangleMesh(p.cage);
  const Eigen::RowVector3d t(8, -12, 20);
  cage.vertices.rowwise() += t;
  const std::string posed = p.dir.file("posed.obj"), out = p.dir.file("posed.nii.gz"),
                    imageOut = p.dir.file("posed_image.nii.gz");
  writeTriangleMesh(cage, posed);
  const CommandResult r = runCommand(
      "repose", p.common(posed) + " --out " + shellQuote(out) + " --image " + shellQuote(p.organs) +
                    " --image-out " + shellQuote(imageOut) + " --json");
  ASSERT_EQ(r.exitCode, 0) << r.err;
  const auto j = nlohmann::json::parse(r.out);
  EXPECT_EQ(j["labels_lost"], 0);
  EXPECT_EQ(j["inverted_tets"], 0);
  for (const auto& l : j["labels"]) EXPECT_EQ(l["change_percent"].get<double>(), 0.0) << l;
  const Volume posedG = readVolume(out);
  const Volume posedI = readVolume(imageOut);
  std::int64_t differ = 0, imageDiffer = 0;
  const auto d = posedG.dims();
  for (std::int64_t k = 0; k < d[2]; ++k)
    for (std::int64_t jj = 0; jj < d[1]; ++jj)
      for (std::int64_t i = 0; i < d[0]; ++i) {
        const Eigen::Vector3d rest =
            G.geometry().rasToVoxel(posedG.geometry().voxelToRas(i, jj, k) - t.transpose());
        const Eigen::Vector3d r0 = rest.array().round();
        double expected = 0;
        if ((r0.array() >= 0).all() && r0.x() < G.dims()[0] && r0.y() < G.dims()[1] &&
            r0.z() < G.dims()[2])
          expected = G.valueAsDouble(
              G.index(std::int64_t(r0.x()), std::int64_t(r0.y()), std::int64_t(r0.z())));
        differ += posedG.valueAsDouble(posedG.index(i, jj, k)) != expected;
        imageDiffer += posedI.valueAsDouble(posedI.index(i, jj, k)) != expected;
      }
  EXPECT_EQ(differ, 0);
  EXPECT_EQ(imageDiffer, 0);  // an image on the same grid, moved by whole voxels, is exact too
}

TEST(WarpCommand, RefusesBadRequestsWithOneLineAndNoOutput) {
  Prepared p;
  TriangleMesh wrong = readTriangleMesh(p.cage);
  wrong.vertices.conservativeResize(wrong.vertices.rows() - 1, 3);
  wrong.faces.conservativeResize(1, 3);
  const std::string wrongCage = p.dir.file("wrong.obj");
  writeTriangleMesh(wrong, wrongCage);
  const std::string out = p.dir.file("never.nii.gz");
  for (const std::string& cmd :
       {p.common(wrongCage) + " --out " + shellQuote(out),
        p.common(p.cage) + " --out " + shellQuote(out) + " --memory 1K",
        p.common(p.cage) + " --out " + shellQuote(out) + " --image " + shellQuote(p.organs),
        p.common(p.cage) + " --out " + shellQuote(p.organs),
        p.common(p.cage) + " --out " + shellQuote(out) + " --background air",
        // Two outputs naming one file: the second would replace the first when both commit.
        p.common(p.cage) + " --out " + shellQuote(out) + " --image " + shellQuote(p.organs) +
            " --image-out " + shellQuote(out)}) {
    const CommandResult bad = runCommand("repose", cmd);
    EXPECT_NE(bad.exitCode, 0) << cmd;
    EXPECT_EQ(lineCount(bad.err), 1) << bad.err;
    EXPECT_FALSE(std::filesystem::exists(out));
  }
  const CommandResult memory =
      runCommand("repose", p.common(p.cage) + " --out " + shellQuote(out) + " --memory 1K");
  EXPECT_NE(memory.err.find("budget"), std::string::npos) << memory.err;
  EXPECT_NE(memory.err.find("never.nii.gz"), std::string::npos) << memory.err;
  const CommandResult background =
      runCommand("repose", p.common(p.cage) + " --out " + shellQuote(out) + " --background air");
  EXPECT_NE(background.err.find("--background expects a number or 'min', got 'air'"),
            std::string::npos)
      << background.err;
}

// Out of core under a budget the in-core run would exceed: the same voxels, a peak resident set
// under the budget (measured by /usr/bin/time), and the JSON says which path ran.
TEST(WarpCommand, OutOfCoreStaysUnderTheBudgetAndEqualsInCore) {
  Prepared p(2);
  const std::string posed = p.elbowFlexed(2, 60);
  const std::string inCoreOut = p.dir.file("in.nii.gz"), outOfCoreOut = p.dir.file("out.nii.gz");
  const CommandResult inCore = runCommand(
      "repose", p.common(posed) + " --out " + shellQuote(inCoreOut) + " --memory 4G --json", true);
  ASSERT_EQ(inCore.exitCode, 0) << inCore.err;
  EXPECT_FALSE(nlohmann::json::parse(inCore.out)["out_of_core"].get<bool>());
  ASSERT_GT(inCore.peakRssKb, 0);
  // 85 % of what the in-core run took; under AddressSanitizer, whose overhead the command does not
  // plan for, half of what the volumes need on top of what the mesh and cage took.
  const auto inCoreJson = nlohmann::json::parse(inCore.out);
  const long budgetKb =
      kPeakRssIsMeaningful
          ? inCore.peakRssKb * 85 / 100
          : long((inCoreJson["memory_in_use_before_volumes_bytes"].get<double>() +
                  inCoreJson["memory_volumes_need_in_core_bytes"].get<double>() / 2) /
                 1024);
  const CommandResult outOfCore =
      runCommand("repose",
                 p.common(posed) + " --out " + shellQuote(outOfCoreOut) + " --memory " +
                     std::to_string(budgetKb) + "K --json",
                 true);
  ASSERT_EQ(outOfCore.exitCode, 0) << outOfCore.err;
  const auto j = nlohmann::json::parse(outOfCore.out);
  EXPECT_TRUE(j["out_of_core"].get<bool>());
  if (kPeakRssIsMeaningful) {
    EXPECT_LT(outOfCore.peakRssKb, budgetKb) << "in core: " << inCore.peakRssKb << " KB";
  }
  EXPECT_EQ(readVolume(inCoreOut).bytes(), readVolume(outOfCoreOut).bytes());
  EXPECT_EQ(j["labels"], nlohmann::json::parse(inCore.out)["labels"]);
}

// `repose mesh` writes the Green coordinates beside the mesh (tm.vtu -> tm.green) and `repose warp`
// reads them: the same posed map, byte for byte, as when they are computed; coordinates of
// another mesh are not used, with a note on stderr, and give the same map too.
TEST(WarpCommand, ReadsTheMeshsSavedGreenCoordinatesAndRecomputesStaleOnes) {
  Prepared p;
  const std::string coordinates = p.dir.file("tm.green");
  ASSERT_TRUE(std::filesystem::exists(coordinates));
  const std::string posed = p.elbowFlexed(4, 60);
  const auto warp = [&](const std::string& out, const std::string& extra) {
    const CommandResult r = runCommand(
        "repose", p.common(posed) + " --out " + shellQuote(p.dir.file(out)) + extra + " --json");
    EXPECT_EQ(r.exitCode, 0) << r.err;
    return r;
  };
  const CommandResult read = warp("read.nii.gz", "");
  const auto readJson = nlohmann::json::parse(read.out);
  EXPECT_TRUE(readJson["green_coordinates"]["read"].get<bool>()) << readJson["green_coordinates"];
  const CommandResult computed =
      warp("computed.nii.gz", " --coordinates " + shellQuote(p.dir.file("none.green")));
  const auto computedJson = nlohmann::json::parse(computed.out);
  EXPECT_FALSE(computedJson["green_coordinates"]["read"].get<bool>());
  EXPECT_EQ(computed.err.find("note:"), std::string::npos) << "no file is not worth a note";
  EXPECT_EQ(fileBytes(p.dir.file("read.nii.gz")), fileBytes(p.dir.file("computed.nii.gz")));
  EXPECT_LT(readJson["deformation_seconds"].get<double>(),
            computedJson["deformation_seconds"].get<double>());

  // Coordinates of another mesh (a finer one, meshed from the same S and cage) beside this one.
  ASSERT_EQ(
      runCommand("repose", "mesh --parts " + shellQuote(p.parts) + " --cage " + shellQuote(p.cage) +
                               " --size-mm 30 --out " + shellQuote(p.dir.file("other.vtu")))
          .exitCode,
      0);
  std::filesystem::copy_file(p.dir.file("other.green"), coordinates,
                             std::filesystem::copy_options::overwrite_existing);
  const CommandResult stale = warp("stale.nii.gz", "");
  const auto staleJson = nlohmann::json::parse(stale.out);
  EXPECT_FALSE(staleJson["green_coordinates"]["read"].get<bool>());
  EXPECT_NE(stale.err.find("note: Green coordinates computed again: " + coordinates +
                           ": written for another transfer mesh or cage"),
            std::string::npos)
      << stale.err;
  EXPECT_EQ(fileBytes(p.dir.file("read.nii.gz")), fileBytes(p.dir.file("stale.nii.gz")));
}
