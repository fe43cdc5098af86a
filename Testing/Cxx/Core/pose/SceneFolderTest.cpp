// Scene folders as the readers meet them from outside: whatever scene.json holds, reading it
// either succeeds or throws repose::Error with one line naming the file (never another exception).
#include "TestPaths.h"
#include "TestVolumes.h"

#include "repose/pose/SceneFolder.h"
#include "repose/util/Error.h"

#include <gtest/gtest.h>

#include <fstream>

using namespace repose;
using namespace repose::test;

// Regression (Testing/Fuzz/FuzzScene): members of the wrong JSON type reached json::value(),
// which throws nlohmann's type_error, not repose::Error.
TEST(SceneFolder, MalformedScenesGiveOneLineErrors) {
  ScratchDir dir;
  const std::string cases[] = {
      R"({"format": 3})",
      R"({"format": "repose-scene", "nodes": [1, "x", null]})",
      R"({"format": "repose-scene", "nodes": {"a": {"class": 7}}})",
      R"({"format": "repose-scene", "nodes": [{"class": "vtkMRMLReposeSegmentationNode",
          "LabelMapFileName": ["G.nii.gz"]}]})",
      R"([1, 2, 3])",
      "{\"format\": \"repose-scene\", \"built_for\": \"\xff\xfe\"}",
  };
  for (const std::string& text : cases) {
    std::ofstream(dir.file("scene.json"), std::ios::binary | std::ios::trunc) << text;
    try {
      readSceneFolder(dir.path().string());
      ADD_FAILURE() << "read: " << text;
    } catch (const Error& e) {
      const std::string msg = e.what();
      EXPECT_NE(msg.find(dir.path().string()), std::string::npos) << msg;
      EXPECT_EQ(msg.find('\n'), std::string::npos) << msg;
    } catch (const std::exception& e) {
      ADD_FAILURE() << "not a repose::Error (" << e.what() << ") for: " << text;
    }
    EXPECT_FALSE(readSceneRig(dir.path().string(), R"({"cage_vertices": 300})").has_value());
  }
}
