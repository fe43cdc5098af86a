// Files the CLI tests share: the standard pose suite's pose files and JSON outputs.
#pragma once

#include <nlohmann/json.hpp>

#include <fstream>
#include <string>

namespace repose::test {

// bench/poses/<name>.pose.json in the source tree.
inline std::string suitePoseFile(const std::string& name) {
  return std::string(REPOSE_SOURCE_DIR) + "/bench/poses/" + name + ".pose.json";
}

inline nlohmann::json readJsonFile(const std::string& path) {
  std::ifstream f(path);
  return nlohmann::json::parse(f);
}

}  // namespace repose::test
