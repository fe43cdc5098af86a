// What the CLI tests share: the standard pose suite's pose files, JSON outputs, a phantom
// with its cage and transfer mesh made by the commands, and the MPI tests' mpirun arguments.
#pragma once

#include "CommandRunner.h"

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <fstream>
#include <iterator>
#include <string>

namespace repose::test {

// bench/poses/<name>.pose.json in the source tree.
// How often `what` occurs in `text` (a message said once, not once per MPI rank).
inline int occurrences(const std::string& text, const std::string& what) {
  int n = 0;
  for (auto at = text.find(what); at != std::string::npos; at = text.find(what, at + 1)) ++n;
  return n;
}

// mpirun's arguments that start `program` (of the build's bin folder) on `ranks` ranks.
inline std::string mpirunArgs(int ranks, const std::string& program = "repose") {
  return "-np " + std::to_string(ranks) + " --oversubscribe --allow-run-as-root " +
         shellQuote(binPath(program)) + " ";
}

inline std::string suitePoseFile(const std::string& name) {
  return std::string(REPOSE_SOURCE_DIR) + "/bench/poses/" + name + ".pose.json";
}

inline nlohmann::json readJsonFile(const std::string& path) {
  std::ifstream f(path);
  return nlohmann::json::parse(f);
}

// `repose phantom`, `cage` and `mesh` into `dir`: G.nii.gz, S.nii.gz, skeleton.json, then
// `cage` and `mesh` (paths) from S with the default settings.
// A file's bytes ("" when it cannot be read).
inline std::string fileBytes(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  return std::string(std::istreambuf_iterator<char>(in), {});
}

inline void makePhantomRig(const std::string& dir, double voxelMm, const std::string& cage,
                           const std::string& mesh) {
  const std::string parts = dir + "/S.nii.gz";
  EXPECT_EQ(runCommand("repose",
                       "phantom --voxel " + std::to_string(voxelMm) + " --out " + shellQuote(dir))
                .exitCode,
            0);
  EXPECT_EQ(runCommand("repose", "cage --parts " + shellQuote(parts) + " --out " + shellQuote(cage))
                .exitCode,
            0);
  EXPECT_EQ(runCommand("repose", "mesh --parts " + shellQuote(parts) + " --cage " +
                                     shellQuote(cage) + " --out " + shellQuote(mesh))
                .exitCode,
            0);
}

}  // namespace repose::test
