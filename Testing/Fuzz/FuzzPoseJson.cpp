// Pose files (.pose.json): parsing, validation, and writing back what was accepted.
#include "FuzzFiles.h"
#include "repose/pose/Pose.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace repose;
  const std::string text(reinterpret_cast<const char*>(data), size);
  try {
    const Pose pose = parsePose(text, "fuzz.pose.json");
    // What was accepted must serialize and read back.
    (void)parsePose(poseToJson(pose), "fuzz.pose.json (written back)");
  } catch (const Error&) {
  }
  return 0;
}
