// `repose warp --mpi` as a user runs it under mpirun: the output grid's slabs spread over the
// ranks and written with MPI-IO give the serial out-of-core file byte for byte (.nii and .nii.gz,
// 1, 2 and 3 ranks, more slabs than ranks); a failure on the ranks is reported once, by rank 0,
// and leaves no output and no temporary folder.
#include "CliTestFiles.h"
#include "CommandRunner.h"
#include "TestPaths.h"

#include "repose/io/MeshIO.h"
#include "repose/phantom/Phantom.h"
#include "repose/phantom/PhantomPoses.h"

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <filesystem>
#include <fstream>
#include <iterator>

using namespace repose;
using namespace repose::test;
namespace fs = std::filesystem;

namespace {

// The 4 mm phantom's left forearm flexed 60° at the elbow, warped to 1.5 mm output voxels
// (289 x 164 x 871: enough slabs for three ranks under the budget below).
struct Elbow {
  ScratchDir dir{"warp-mpi"};
  std::string organs = dir.file("G.nii.gz"), parts = dir.file("S.nii.gz"),
              cage = dir.file("cage.obj"), mesh = dir.file("tm.vtu"), posed = dir.file("posed.obj");
  Elbow() {
    makePhantomRig(dir.path().string(), 4, cage, mesh);
    PhantomOptions po;
    po.voxelMm = 4;
    TriangleMesh c = readTriangleMesh(cage);
    c.vertices = phantomElbowFlexion(Phantom(po), c, 60);
    writeTriangleMesh(c, posed);
  }
  std::string warp(const std::string& posedCage) const {
    return "warp --input " + shellQuote(organs) + " --mesh " + shellQuote(mesh) + " --cage " +
           shellQuote(cage) + " --posed-cage " + shellQuote(posedCage) + " --spacing-mm 1.5";
  }
};

}  // namespace

TEST(WarpMpiCommand, SlabsOverRanksWriteTheSerialOutOfCoreFileByteForByte) {
  ASSERT_TRUE(fs::exists("/usr/bin/mpirun")) << "scripts/install-deps.sh installs openmpi-bin";
  // As for the sweep: sanitized ranks under mpirun are not yet checked (docs/RELIABILITY.md).
  if (kAddressSanitizer) GTEST_SKIP() << "mpirun under AddressSanitizer (docs/RELIABILITY.md)";
  Elbow e;
  // A budget that leaves three quarters of what the volumes need beyond what the mesh and the
  // deformation take: out of core, in slabs of one or two gzip pieces (4 MiB each) on every rank.
  const CommandResult probe =
      runCommand("repose", e.warp(e.posed) + " --out " + shellQuote(e.dir.file("in.nii.gz")) +
                               " --memory 8G --json");
  ASSERT_EQ(probe.exitCode, 0) << probe.err;
  const auto inCore = nlohmann::json::parse(probe.out);
  const long budgetKb = long((inCore["memory_in_use_before_volumes_bytes"].get<double>() +
                              inCore["memory_volumes_need_in_core_bytes"].get<double>() * 3 / 4) /
                             1024);
  const std::string budget = " --memory " + std::to_string(budgetKb) + "K --json";
  for (const std::string ext : {".nii.gz", ".nii"}) {
    const std::string serial = e.dir.file("serial" + ext);
    const CommandResult s =
        runCommand("repose", e.warp(e.posed) + " --out " + shellQuote(serial) + budget);
    ASSERT_EQ(s.exitCode, 0) << s.err;
    const auto sj = nlohmann::json::parse(s.out);
    ASSERT_TRUE(sj["out_of_core"].get<bool>()) << "the budget must force the out-of-core path";
    EXPECT_EQ(sj["labels"], inCore["labels"]);
    const std::string expected = fileBytes(serial);
    ASSERT_GT(expected.size(), 1000u);
    for (const int ranks : {1, 2, 3}) {
      if (ranks == 3 && ext == ".nii") continue;
      const std::string out = e.dir.file("mpi" + std::to_string(ranks) + ext);
      const std::string args = e.warp(e.posed) + " --mpi --out " + shellQuote(out) + budget;
      // One rank: started without mpirun (MPI's singleton start).
      const CommandResult m = ranks == 1 ? runCommand("repose", args)
                                         : runCommand("/usr/bin/mpirun", mpirunArgs(ranks) + args);
      ASSERT_EQ(m.exitCode, 0) << m.err << m.out;
      const auto mj = nlohmann::json::parse(m.out);
      EXPECT_EQ(mj["mpi"]["ranks"], ranks);
      EXPECT_GT(mj["mpi"]["slabs"].get<int>(), ranks) << "every rank writes, some more than once";
      EXPECT_TRUE(fileBytes(out) == expected) << ranks << " ranks, " << ext;
      EXPECT_EQ(mj["labels"], sj["labels"]);
      EXPECT_EQ(mj["voxels_inside_tets"], sj["voxels_inside_tets"]);
      EXPECT_EQ(mj["voxels_in_shell"], sj["voxels_in_shell"]);
    }
  }
}

TEST(WarpMpiCommand, AFailureOnTheRanksIsReportedOnceAndLeavesNothing) {
  ASSERT_TRUE(fs::exists("/usr/bin/mpirun")) << "scripts/install-deps.sh installs openmpi-bin";
  if (kAddressSanitizer) GTEST_SKIP() << "mpirun under AddressSanitizer (docs/RELIABILITY.md)";
  Elbow e;
  TriangleMesh wrong = readTriangleMesh(e.cage);
  wrong.vertices.conservativeResize(wrong.vertices.rows() - 1, 3);
  wrong.faces.conservativeResize(1, 3);
  const std::string wrongCage = e.dir.file("wrong.obj");
  writeTriangleMesh(wrong, wrongCage);
  const std::string out = e.dir.file("never.nii.gz");
  const auto before = std::distance(fs::directory_iterator(e.dir.path()), {});
  struct Case {
    std::string args, says;
  };
  for (const Case& c :
       {Case{e.warp(wrongCage) + " --mpi --out " + shellQuote(out), "not a pose of"},
        Case{e.warp(e.posed) + " --mpi --out " + shellQuote(out) + " --memory 1K", "budget"},
        Case{e.warp(e.posed) + " --mpi --out " + shellQuote(e.dir.file("never.nrrd")),
             "writes NIfTI"},
        Case{e.warp(e.posed) + " --mpi --out " + shellQuote(out) + " --image " +
                 shellQuote(e.organs) + " --image-out " + shellQuote(e.dir.file("i.nii.gz")),
             "--image is not available"}}) {
    const CommandResult m = runCommand("/usr/bin/mpirun", mpirunArgs(2) + c.args);
    EXPECT_NE(m.exitCode, 0) << c.args;
    EXPECT_EQ(occurrences(m.err, "repose warp:"), 1) << m.err;
    EXPECT_NE(m.err.find(c.says), std::string::npos) << m.err;
    EXPECT_FALSE(fs::exists(out));
    // Nothing new in the folder: no output and no hidden temporary folder.
    EXPECT_EQ(std::distance(fs::directory_iterator(e.dir.path()), {}), before) << c.args;
  }
}
