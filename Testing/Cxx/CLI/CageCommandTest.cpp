// `repose cage` as a user runs it: a phantom's cage with its JSON report, a separation, and
// failures that print one line and write nothing.
#include "CommandRunner.h"
#include "TestPaths.h"

#include "repose/io/MeshIO.h"

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <filesystem>
#include <fstream>

using namespace repose;
using namespace repose::test;

namespace {

// A 4 mm phantom (fast) in a scratch folder.
std::string makePhantom(const ScratchDir& dir, bool armsTouching) {
  const CommandResult r =
      runCommand("repose", "phantom --voxel 4 --out " + shellQuote(dir.path().string()) +
                               (armsTouching ? " --arms-touching" : ""));
  EXPECT_EQ(r.exitCode, 0) << r.err;
  return dir.file("S.nii.gz");
}

}  // namespace

TEST(CageCommand, BuildsAValidCageAroundThePhantom) {
  ScratchDir dir;
  const std::string parts = makePhantom(dir, false);
  const CommandResult r =
      runCommand("repose", "cage --parts " + shellQuote(parts) + " --out " +
                               shellQuote(dir.file("cage.obj")) + " --vertices 300 --json");
  ASSERT_EQ(r.exitCode, 0) << r.err;
  const auto j = nlohmann::json::parse(r.out);
  EXPECT_NEAR(j["vertices"].get<int>(), 300, 30);
  EXPECT_GE(j["enclosed_fraction"].get<double>(), 0.95);
  for (const char* check : {"closed", "manifold", "outward", "self_intersection_free"})
    EXPECT_TRUE(j["checks"][check]) << check;
  const TriangleMesh cage = readTriangleMesh(dir.file("cage.obj"));
  EXPECT_EQ(cage.vertices.rows(), j["vertices"].get<int>());
}

TEST(CageCommand, SameInputGivesTheSameCageFile) {
  // Batch scripts rebuild cages: two runs must agree byte for byte.
  ScratchDir dir;
  const std::string parts = makePhantom(dir, false);
  for (const char* name : {"a.obj", "b.obj"})
    ASSERT_EQ(runCommand("repose", "cage --parts " + shellQuote(parts) + " --out " +
                                       shellQuote(dir.file(name)))
                  .exitCode,
              0);
  std::ifstream a(dir.file("a.obj")), b(dir.file("b.obj"));
  const std::string textA((std::istreambuf_iterator<char>(a)), {}),
      textB((std::istreambuf_iterator<char>(b)), {});
  EXPECT_FALSE(textA.empty());
  EXPECT_EQ(textA, textB);
}

TEST(CageCommand, SeparatesAndRefusesBadRequests) {
  ScratchDir dir;
  const std::string parts = makePhantom(dir, true);
  const std::string out = dir.file("sep.vtk");
  const CommandResult ok =
      runCommand("repose", "cage --parts " + shellQuote(parts) + " --out " + shellQuote(out) +
                               " --separate 5:9 --region sphere:-136,9,526,110 --json");
  ASSERT_EQ(ok.exitCode, 0) << ok.err;
  EXPECT_TRUE(std::filesystem::exists(out));
  const std::string bad[] = {
      "--separate 5:99 --region sphere:-136,9,526,110",             // label not present
      "--separate 5:9 --region box:9000,9000,9000,9100,9100,9100",  // region selects nothing
      "--separate 5:9",                                             // region missing
      "--vertices 10",                                              // out of range
  };
  for (const std::string& extra : bad) {
    const std::string target = dir.file("bad.obj");
    const CommandResult r = runCommand("repose", "cage --parts " + shellQuote(parts) + " --out " +
                                                     shellQuote(target) + " " + extra);
    EXPECT_NE(r.exitCode, 0) << extra;
    EXPECT_EQ(lineCount(r.err), 1) << extra << ": " << r.err;
    EXPECT_FALSE(std::filesystem::exists(target)) << extra;
  }
}
