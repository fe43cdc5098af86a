// `repose mesh` as a user runs it: phantom -> cage -> transfer mesh with its JSON summary, and a
// separation; bad requests fail with one line and write nothing.
#include "CommandRunner.h"
#include "TestPaths.h"

#include "repose/mesh/TransferMesh.h"

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <algorithm>
#include <filesystem>
#include <string>
#include <vector>

using namespace repose;
using namespace repose::test;

TEST(MeshCommand, BuildsEmbedsAndWritesTheTransferMesh) {
  ScratchDir dir;
  const std::string d = shellQuote(dir.path().string());
  ASSERT_EQ(runCommand("repose", "phantom --voxel 4 --arms-touching --out " + d).exitCode, 0);
  const std::string parts = shellQuote(dir.file("S.nii.gz")),
                    cage = shellQuote(dir.file("cage.obj"));
  ASSERT_EQ(runCommand("repose", "cage --parts " + parts + " --out " + cage).exitCode, 0);
  const CommandResult r =
      runCommand("repose", "mesh --parts " + parts + " --cage " + cage + " --out " +
                               shellQuote(dir.file("tm.vtu")) + " --size-mm 30 --json");
  ASSERT_EQ(r.exitCode, 0) << r.err;
  const auto j = nlohmann::json::parse(r.out);
  const TransferMesh tm = readTransferMesh(dir.file("tm.vtu"));
  EXPECT_EQ(j["vertices"].get<long>(), tm.vertices.rows());
  EXPECT_EQ(j["tets"].get<long>(), tm.tets.rows());
  EXPECT_EQ(j["vertices_inside_cage"].get<long>() + j["outliers"].get<long>(), tm.vertices.rows());
  EXPECT_EQ(j["inverted_tets_reoriented"], 0);
  const CommandResult sep = runCommand(
      "repose", "mesh --parts " + parts + " --cage " + cage + " --out " +
                    shellQuote(dir.file("sep.vtu")) +
                    " --size-mm 30 --separate 9:5 --region sphere:-136,9,526,110 --json");
  ASSERT_EQ(sep.exitCode, 0) << sep.err;
  EXPECT_GT(nlohmann::json::parse(sep.out)["separation_vertices_added"].get<int>(), 0);
  // With --slicer-progress the embedding, the longest step, reports its own stage from 0 to 1
  // in order (test_interrupt.py signals on that line).
  const CommandResult progress =
      runCommand("repose", "mesh --parts " + parts + " --cage " + cage + " --out " +
                               shellQuote(dir.file("p.vtu")) + " --size-mm 30 --slicer-progress");
  ASSERT_EQ(progress.exitCode, 0) << progress.err;
  const std::size_t stage = progress.out.find("<filter-comment>Green coordinates</filter-comment>");
  ASSERT_NE(stage, std::string::npos) << progress.out;
  std::vector<double> fractions;
  const std::string open = "<filter-progress>";
  for (std::size_t at = progress.out.find(open, stage); at != std::string::npos;
       at = progress.out.find(open, at + 1))
    fractions.push_back(std::stod(progress.out.substr(at + open.size())));
  ASSERT_GE(fractions.size(), 2u) << progress.out;
  EXPECT_EQ(fractions.front(), 0.0);
  EXPECT_EQ(fractions.back(), 1.0);
  EXPECT_TRUE(std::is_sorted(fractions.begin(), fractions.end())) << progress.out;
  EXPECT_NE(progress.out.find("<filter-end>"), std::string::npos) << progress.out;
  for (const std::string extra : {"--separate 5", "--size-mm -3", ""}) {
    const std::string out = dir.file("bad.vtu");
    const std::string cmd = extra.empty() ? "mesh --parts " + parts + " --out " + shellQuote(out)
                                          : "mesh --parts " + parts + " --cage " + cage +
                                                " --out " + shellQuote(out) + " " + extra;
    const CommandResult bad = runCommand("repose", cmd);
    EXPECT_NE(bad.exitCode, 0) << extra;
    EXPECT_EQ(lineCount(bad.err), 1) << bad.err;
    EXPECT_FALSE(std::filesystem::exists(out));
  }
}

// Under a small --memory, the cage and the mesh are built on a downsampled proxy of S (label mode
// per block): the mesh stays under the budget, the cage needs less than in core (its builder's
// working grids are not yet bounded by the budget), and the mesh remembers the proxy's spacing.
TEST(MeshCommand, ProxyKeepsCageAndMeshUnderTheBudget) {
  ScratchDir dir;
  ASSERT_EQ(
      runCommand("repose", "phantom --voxel 2 --out " + shellQuote(dir.path().string())).exitCode,
      0);
  const std::string parts = shellQuote(dir.file("S.nii.gz")),
                    cage = shellQuote(dir.file("cage.obj"));
  const CommandResult inCore = runCommand(
      "repose", "cage --parts " + parts + " --out " + shellQuote(dir.file("full.obj")) + " --json",
      true);
  ASSERT_EQ(inCore.exitCode, 0) << inCore.err;
  EXPECT_EQ(nlohmann::json::parse(inCore.out)["proxy_factor"], 1);
  // Budgets on top of what the process takes before it reads anything (its libraries: 20 MB
  // plain, ~120 MB under AddressSanitizer): 40 MB more for the cage, 80 MB for the mesh.
  const CommandResult idle = runCommand("repose", "--help", true);
  ASSERT_GT(idle.peakRssKb, 0);
  const long cageBudgetKb = idle.peakRssKb + 40 * 1024, meshBudgetKb = idle.peakRssKb + 80 * 1024;
  const CommandResult c = runCommand("repose",
                                     "cage --parts " + parts + " --out " + cage + " --memory " +
                                         std::to_string(cageBudgetKb) + "K --json",
                                     true);
  ASSERT_EQ(c.exitCode, 0) << c.err;
  EXPECT_GT(nlohmann::json::parse(c.out)["proxy_factor"].get<int>(), 1);
  if (kPeakRssIsMeaningful) {
    EXPECT_LT(c.peakRssKb, inCore.peakRssKb);
  }
  const CommandResult m = runCommand("repose",
                                     "mesh --parts " + parts + " --cage " + cage + " --out " +
                                         shellQuote(dir.file("tm.vtu")) + " --memory " +
                                         std::to_string(meshBudgetKb) + "K --json",
                                     true);
  ASSERT_EQ(m.exitCode, 0) << m.err;
  const int factor = nlohmann::json::parse(m.out)["proxy_factor"].get<int>();
  EXPECT_GT(factor, 1);
  if (kPeakRssIsMeaningful) {
    EXPECT_LT(m.peakRssKb, meshBudgetKb);
  }
  EXPECT_DOUBLE_EQ(readTransferMesh(dir.file("tm.vtu")).sourceSpacingMm, 2.0 * factor);
}
