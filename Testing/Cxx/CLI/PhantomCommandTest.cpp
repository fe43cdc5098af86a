// `repose phantom` as a user runs it: a coarse phantom written with a JSON summary, and bad
// options refused with one line on stderr before anything is written.
#include "CommandRunner.h"
#include "TestPaths.h"

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>
#include <unistd.h>

#include <filesystem>

using namespace repose::test;
namespace fs = std::filesystem;

namespace {

std::size_t entries(const ScratchDir& dir) {
  return static_cast<std::size_t>(std::distance(fs::directory_iterator(dir.path()), {}));
}

}  // namespace

TEST(PhantomCommand, WritesThreeFilesAndAJsonSummary) {
  ScratchDir root;
  const std::string out = root.file("phantom");  // created by the command
  const CommandResult r =
      runCommand("repose", "phantom --voxel 6 --out " + shellQuote(out) + " --json");
  ASSERT_EQ(r.exitCode, 0) << r.err;
  const auto j = nlohmann::json::parse(r.out);
  EXPECT_EQ(std::distance(fs::directory_iterator(out), {}), 3);
  for (const char* key : {"organs", "parts", "skeleton"}) {
    const std::string path = j["files"][key];
    EXPECT_TRUE(fs::is_regular_file(path)) << path;
    EXPECT_EQ(fs::path(path).parent_path(), fs::path(out));
  }
  const auto dims = j["dims"].get<std::vector<std::int64_t>>();
  ASSERT_EQ(dims.size(), 3u);
  EXPECT_EQ(j["numVoxels"].get<std::int64_t>(), dims[0] * dims[1] * dims[2]);
  EXPECT_DOUBLE_EQ(j["voxelMm"].get<double>(), 6.0);
  EXPECT_GE(j["organLabels"].size(), 15u);
  EXPECT_EQ(j["partLabels"].size(), 14u);
  EXPECT_EQ(j["partLabels"][0]["name"], "head");
}

TEST(PhantomCommand, HumanSummaryAndPlainNifti) {
  ScratchDir root;
  const CommandResult r =
      runCommand("repose", "phantom --voxel 8 --arms-touching --format nii --prefix kid_ --out " +
                               shellQuote(root.file("")));
  ASSERT_EQ(r.exitCode, 0) << r.err;
  EXPECT_NE(r.out.find("voxels"), std::string::npos) << r.out;  // the size estimate
  EXPECT_TRUE(fs::is_regular_file(root.file("kid_G.nii")));
  EXPECT_TRUE(fs::is_regular_file(root.file("kid_S.nii")));
  EXPECT_TRUE(fs::is_regular_file(root.file("kid_skeleton.json")));
}

TEST(PhantomCommand, BadOptionsFailWithOneLineAndWriteNothing) {
  ScratchDir root;
  const std::string out = root.file("never");
  for (const std::string args : {"--voxel -1", "--voxel 0", "--voxel 0.05", "--voxel abc",
                                 "--format nrrd", "--margin -3", ""}) {
    const std::string outArg = args.empty() ? "" : " --out " + shellQuote(out);
    const CommandResult r = runCommand("repose", "phantom " + args + outArg);
    EXPECT_NE(r.exitCode, 0) << args;
    EXPECT_EQ(lineCount(r.err), 1) << args << ": " << r.err;
    EXPECT_TRUE(r.out.empty()) << args << ": " << r.out;
  }
  EXPECT_EQ(entries(root), 0u);
  // A missing parent folder is named in the message, and nothing is created.
  const CommandResult r =
      runCommand("repose", "phantom --voxel 8 --out " + shellQuote(root.file("no/such/folder")));
  EXPECT_NE(r.exitCode, 0);
  EXPECT_EQ(lineCount(r.err), 1) << r.err;
  EXPECT_NE(r.err.find("no/such"), std::string::npos) << r.err;
  EXPECT_EQ(entries(root), 0u);
}

TEST(PhantomCommand, HelpListsTheOptions) {
  const CommandResult r = runCommand("repose", "phantom --help");
  EXPECT_EQ(r.exitCode, 0);
  for (const char* opt : {"--out", "--voxel", "--arms-touching", "--margin", "--format", "--json"})
    EXPECT_NE(r.out.find(opt), std::string::npos) << opt;
}
