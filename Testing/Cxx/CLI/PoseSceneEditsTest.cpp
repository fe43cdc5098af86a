// A scene folder edited by hand (issue 30): scene.json records the size and CRC-32 of the cage
// and transfer mesh it was saved with, so a rig file replaced, edited or removed afterwards is
// never used silently: `repose pose --scene` builds the rig again with a note and saves it over
// the scene, and the scene reader refuses with one line.
#include "CliTestFiles.h"
#include "CommandRunner.h"
#include "TestPaths.h"

#include "repose/pose/SceneFolder.h"
#include "repose/util/Error.h"

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <filesystem>
#include <fstream>
#include <functional>

using namespace repose;
using namespace repose::test;
namespace fs = std::filesystem;

namespace {

std::string readSceneError(const std::string& folder) {
  try {
    readSceneFolder(folder);
  } catch (const Error& e) {
    return e.what();
  }
  return "";
}

}  // namespace

TEST(PoseSceneEdits, AnEditedOrMissingRigFileIsBuiltAgainWithANoteNeverUsed) {
  ScratchDir dir("edits");
  ASSERT_EQ(
      runCommand("repose", "phantom --voxel 8 --out " + shellQuote(dir.path().string())).exitCode,
      0);
  const std::string scene = dir.file("scene");
  const std::string common = "pose --input " + shellQuote(dir.file("G.nii.gz")) + " --parts " +
                             shellQuote(dir.file("S.nii.gz")) + " --pose " +
                             shellQuote(suitePoseFile("elbow90")) + " --scene " +
                             shellQuote(scene) + " --json --out ";
  auto pose = [&](const std::string& out) {
    const CommandResult r = runCommand("repose", common + shellQuote(dir.file(out)));
    EXPECT_EQ(r.exitCode, 0) << r.err;
    return std::make_pair(nlohmann::json::parse(r.out)["scene_reused"].get<bool>(), r.err);
  };
  EXPECT_FALSE(pose("a").first);
  const auto [reused, quiet] = pose("b");
  EXPECT_TRUE(reused);
  EXPECT_EQ(quiet.find("note: the scene's rig"), std::string::npos) << quiet;
  EXPECT_EQ(readSceneError(scene), "");

  // The cage replaced by another (one built with other settings), then the mesh edited in place,
  // then the mesh removed: each is noticed, named, built again and saved, and the next run reuses
  // the rebuilt scene.
  struct Edit {
    std::string file, what;
    std::function<void()> apply;
  };
  const std::vector<Edit> edits{
      {"cage.vtk", "changed since the scene was saved",
       [&] {
         ASSERT_EQ(
             runCommand("repose", "cage --parts " + shellQuote(dir.file("S.nii.gz")) +
                                      " --vertices 120 --out " + shellQuote(scene + "/cage.vtk"))
                 .exitCode,
             0);
       }},
      {"tm.vtu", "changed since the scene was saved",
       [&] { std::ofstream(scene + "/tm.vtu", std::ios::app) << "<!-- edited -->\n"; }},
      {"tm.vtu", "missing", [&] { fs::remove(scene + "/tm.vtu"); }},
  };
  int n = 0;
  for (const Edit& edit : edits) {
    SCOPED_TRACE(edit.file + " " + edit.what);
    edit.apply();
    const std::string read = readSceneError(scene);
    EXPECT_NE(read.find(scene + "/" + edit.file + ": " + edit.what), std::string::npos) << read;
    EXPECT_EQ(read.find('\n'), std::string::npos);
    const std::string out = "edit" + std::to_string(n++);
    const auto [again, note] = pose(out);
    EXPECT_FALSE(again);
    EXPECT_NE(note.find("note: the scene's rig is built again and saved over it: " + scene + "/" +
                        edit.file + ": " + edit.what),
              std::string::npos)
        << note;
    EXPECT_TRUE(pose(out + "next").first);  // the scene saved over is whole again
    EXPECT_EQ(readSceneError(scene), "");
  }
}
