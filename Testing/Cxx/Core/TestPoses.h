// The standard pose suite (bench/poses/) as the Core tests use it: read, and its named joints
// resolved on a phantom's skeleton, as `repose pose` resolves them with the skeleton beside S.
#pragma once

#include "repose/phantom/Phantom.h"
#include "repose/pose/Pose.h"

#include <string>

namespace repose::test {

inline std::string suitePosePath(const std::string& name) {
  return std::string(REPOSE_SOURCE_DIR) + "/bench/poses/" + name + ".pose.json";
}

inline Pose suitePose(const std::string& name, const Phantom& body) {
  Pose pose = readPoseFile(suitePosePath(name));
  resolvePoseJoints(pose, body.skeleton());
  return pose;
}

}  // namespace repose::test
