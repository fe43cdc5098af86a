// `repose pose --mpi` as a user runs it under mpirun (issue 56): the ranks share each frame's
// slabs (ranks 1..N-1 make them, rank 0 writes) and the frame's folder is the one-process frame
// made slab by slab, byte for byte (label maps as NIfTI and seg.nrrd, the image, the transform)
// with the same report, for 1, 2 and 3 ranks. What the command line cannot cause, a failure while
// a slab is made or used, is run on the pipeline itself (ReposeSlabRanksProbe): one message from
// rank 0, the failing rank's exit status, no rank left waiting.
#include "CliTestFiles.h"
#include "CommandRunner.h"
#include "TestPaths.h"

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <filesystem>

using namespace repose;
using namespace repose::test;
namespace fs = std::filesystem;
using nlohmann::json;

namespace {

// A file of a frame's folder as the comparison takes it: a colour table after its first line
// (which names the file it was written as).
std::string frameFile(const fs::path& file) {
  std::string bytes = fileBytes(file.string());
  if (file.extension() == ".ctbl") bytes.erase(0, bytes.find('\n'));
  return bytes;
}

}  // namespace

TEST(PoseMpiCommand, SlabsOverRanksWriteTheOneProcessFrameByteForByte) {
  ASSERT_TRUE(fs::exists("/usr/bin/mpirun")) << "scripts/install-deps.sh installs openmpi-bin";
  if (kAddressSanitizer) GTEST_SKIP() << "mpirun under AddressSanitizer (docs/RELIABILITY.md)";
  ScratchDir dir("pose-mpi");
  ASSERT_EQ(
      runCommand("repose", "phantom --voxel 4 --image --out " + shellQuote(dir.path().string()))
          .exitCode,
      0);
  const std::string job =
      "pose --input " + shellQuote(dir.file("G.nii.gz")) + " --parts " +
      shellQuote(dir.file("S.nii.gz")) + " --image " + shellQuote(dir.file("CT.nii.gz")) +
      " --pose " + shellQuote(suitePoseFile("elbow90")) + " --scene " +
      shellQuote(dir.file("scene")) + " --spacing-mm 3 --output-format both --json";
  // The reference: one process, slab by slab; it builds the rig the ranks then read.
  const CommandResult one =
      runCommand("repose", job + " --out-of-core --out " + shellQuote(dir.file("one")));
  // (At 4 mm the ribs' volume misses its target: exit 4, the frame written all the same.)
  ASSERT_TRUE(one.exitCode == 0 || one.exitCode == 4) << one.err;
  // How the rig came (built there, read from the scene by the ranks) is not the frame's.
  auto frameReport = [](json report) {
    for (const char* key : {"streamed", "scene_reused", "green_coordinates"}) report.erase(key);
    return report.dump();
  };
  const std::string reference = frameReport(json::parse(fileBytes(dir.file("one/report.json"))));
  for (const int ranks : {1, 2, 3}) {
    const std::string out = dir.file("mpi" + std::to_string(ranks));
    const std::string args = job + " --mpi --out " + shellQuote(out);
    // One rank: started without mpirun (MPI's singleton start).
    const CommandResult m = ranks == 1
                                ? runCommand("repose", args)
                                : runCommand("/usr/bin/mpirun", mpirunArgs(ranks, "repose") + args);
    ASSERT_EQ(m.exitCode, one.exitCode) << m.err << m.out;
    json report = json::parse(m.out);  // rank 0's alone on stdout
    EXPECT_EQ(report["streamed"]["ranks"], ranks);
    if (ranks > 1) {
      EXPECT_GE(report["streamed"]["slabs"].get<int>(), 8 * (ranks - 1))
          << "each maker makes several slabs";
    }
    EXPECT_EQ(frameReport(report), reference) << ranks << " ranks";
    int files = 0;
    for (const auto& f : fs::directory_iterator(dir.file("one"))) {
      if (f.path().filename() == "report.json") continue;
      ++files;
      EXPECT_TRUE(frameFile(f.path()) == frameFile(fs::path(out) / f.path().filename()))
          << f.path().filename() << ", " << ranks << " ranks";
    }
    EXPECT_EQ(files, 9) << "G and S as .nii.gz with colour tables and as .seg.nrrd, the image, "
                           "the transform, the scene";
    EXPECT_EQ(std::distance(fs::directory_iterator(out), {}), files + 1);
  }
}

TEST(PoseMpiCommand, WhatARankRefusesIsSaidOnceAndLeavesNothing) {
  ASSERT_TRUE(fs::exists("/usr/bin/mpirun")) << "scripts/install-deps.sh installs openmpi-bin";
  if (kAddressSanitizer) GTEST_SKIP() << "mpirun under AddressSanitizer (docs/RELIABILITY.md)";
  ScratchDir dir("pose-mpi-refused");
  ASSERT_EQ(
      runCommand("repose", "phantom --voxel 8 --out " + shellQuote(dir.path().string())).exitCode,
      0);
  const std::string job = "pose --input " + shellQuote(dir.file("G.nii.gz")) + " --parts " +
                          shellQuote(dir.file("S.nii.gz")) + " --pose " +
                          shellQuote(suitePoseFile("elbow90")) + " --mpi --out " +
                          shellQuote(dir.file("never"));
  struct Case {
    std::string args, says;
    int exit;
  };
  for (const Case& c :
       {Case{job, "--mpi needs --scene", 2},
        Case{job + " --scene " + shellQuote(dir.file("scene")) + " --posed-labels " +
                 shellQuote(dir.file("one.nii.gz")),
             "--mpi writes the frames into --out only", 2},
        Case{job + " --scene " + shellQuote(dir.file("scene")) + " --memory 1K", "budget", 1}}) {
    const CommandResult m = runCommand("/usr/bin/mpirun", mpirunArgs(2, "repose") + c.args);
    EXPECT_EQ(m.exitCode, c.exit) << c.args << "\n" << m.err;
    EXPECT_EQ(occurrences(m.err, "repose pose:"), 1) << m.err;
    EXPECT_NE(m.err.find(c.says), std::string::npos) << m.err;
    EXPECT_FALSE(fs::exists(dir.file("never")));
  }
}

TEST(PoseMpiCommand, TheSlabPipelineDeliversEverySlabInOrderAndAgreesOnAFailure) {
  ASSERT_TRUE(fs::exists("/usr/bin/mpirun")) << "scripts/install-deps.sh installs openmpi-bin";
  if (kAddressSanitizer) GTEST_SKIP() << "mpirun under AddressSanitizer (docs/RELIABILITY.md)";
  for (const int ranks : {1, 2, 3, 4}) {
    const CommandResult ok =
        runCommand("/usr/bin/mpirun", mpirunArgs(ranks, "ReposeSlabRanksProbe") + "ok");
    ASSERT_EQ(ok.exitCode, 0) << ok.err;
    EXPECT_NE(ok.out.find("used 28 slabs over " + std::to_string(ranks)), std::string::npos)
        << ok.out;
  }
  struct Case {
    std::string args, says;
    int exit;
  };
  // Slab 9 of 23 is made by rank 2 of 3 (ranks 1 and 2 make slabs in turn); slab 0 by rank 1.
  for (const Case& c : {Case{"make-fails 9", "probe: error: rank 2: slab 9 cannot be made", 1},
                        Case{"make-fails 0", "probe: error: rank 1: slab 0 cannot be made", 1},
                        Case{"use-fails 4", "probe: error: slab 4 cannot be used", 1},
                        Case{"use-fails 22", "probe: error: slab 22 cannot be used", 1},
                        Case{"make-cancels 3", "probe: cancelled", 130}}) {
    const CommandResult m =
        runCommand("/usr/bin/mpirun", mpirunArgs(3, "ReposeSlabRanksProbe") + c.args);
    EXPECT_EQ(m.exitCode, c.exit) << c.args << "\n" << m.err;
    EXPECT_EQ(occurrences(m.err, "probe:"), 1) << m.err;
    EXPECT_NE(m.err.find(c.says), std::string::npos) << c.args << "\n" << m.err;
  }
}
