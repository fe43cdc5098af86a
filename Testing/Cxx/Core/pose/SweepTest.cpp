// Posture sweeps' shared parts in Core (pose/Sweep.h) on their own: the subject and pose lists
// (relative paths, comments, one line per refusal naming the list and the line), where each job
// writes, when a job's outputs are complete, the scene folder of a rig, the records' JSON and the
// summary files. The whole command, ranks and resume: Testing/Cxx/CLI/SweepCommandTest.cpp.
#include "TestPaths.h"

#include "repose/pose/PoseFrame.h"
#include "repose/pose/Sweep.h"
#include "repose/util/Error.h"

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <filesystem>
#include <fstream>
#include <functional>

using namespace repose;
namespace fs = std::filesystem;

namespace {

void write(const fs::path& path, const std::string& text) {
  fs::create_directories(path.parent_path());
  std::ofstream(path) << text;
}

// What a list read refuses with: its one line.
std::string refusal(const std::function<void()>& read) {
  try {
    read();
  } catch (const Error& e) {
    return e.what();
  }
  return "";
}

}  // namespace

TEST(Sweep, ListsReadRelativePathsSkipCommentsAndNameTheLineTheyRefuse) {
  test::ScratchDir dir("lists");
  const fs::path root = dir.path();
  write(root / "bodies/af/G.nii.gz", "g"), write(root / "bodies/af/S.nii.gz", "s");
  write(root / "bodies/am/G.nrrd", "g"), write(root / "bodies/am/S.nii.gz", "s");
  write(root / "poses/elbow90.pose.json", "{}"), write(root / "poses/walk.json", "{}");
  write(root / "subjects.txt", "# adults\n\nbodies/af\n  bodies/am  \n");
  const std::vector<SweepSubject> subjects = readSweepSubjects((root / "subjects.txt").string());
  ASSERT_EQ(subjects.size(), 2u);
  EXPECT_EQ(subjects[0].name, "af");
  EXPECT_EQ(subjects[0].organs, (root / "bodies/af/G.nii.gz").string());
  EXPECT_EQ(subjects[0].parts, (root / "bodies/af/S.nii.gz").string());
  EXPECT_EQ(subjects[1].organs, (root / "bodies/am/G.nrrd").string());
  write(root / "poses.txt", "poses/elbow90.pose.json\n" + (root / "poses/walk.json").string());
  const std::vector<SweepPose> poses = readSweepPoses((root / "poses.txt").string());
  ASSERT_EQ(poses.size(), 2u);
  EXPECT_EQ(poses[0].name, "elbow90");
  EXPECT_EQ(poses[1].name, "walk");

  // Refusals: the list, the line and the problem.
  const std::string list = (root / "bad.txt").string();
  write(list, "bodies/af\n\nbodies/none\n");
  EXPECT_EQ(refusal([&] { readSweepSubjects(list); }).rfind(list + ":3: ", 0), 0u);
  write(root / "other/af/G.nii.gz", "g"), write(root / "other/af/S.nii.gz", "s");
  write(list, "bodies/af\nother/af\n");
  EXPECT_NE(refusal([&] { readSweepSubjects(list); }).find(":2: a second entry named \"af\""),
            std::string::npos);
  write(root / "bodies/nos/G.nii.gz", "g");
  write(list, "bodies/nos\n");
  EXPECT_NE(refusal([&] { readSweepSubjects(list); }).find("has no S.nii.gz"), std::string::npos);
  write(list, "# nothing\n");
  EXPECT_NE(refusal([&] { readSweepPoses(list); }).find("lists nothing"), std::string::npos);
  write(list, "poses/elbow90.pose.json\nposes/missing.pose.json\n");
  EXPECT_EQ(refusal([&] { readSweepPoses(list); }).rfind(list + ":2: ", 0), 0u);
}

TEST(Sweep, JobFoldersScenesCompletenessAndTheSummary) {
  test::ScratchDir dir("jobs");
  const std::string out = dir.file("out");
  const SweepSubject af{"af", "/data/af", "/data/af/G.nii.gz", "/data/af/S.nii.gz"};
  const SweepPose walk{"walk", "/poses/walk.pose.json"};
  EXPECT_EQ(sweepJobFolder(out, af, walk, "step1", true), out + "/af/walk");
  EXPECT_EQ(sweepJobFolder(out, af, walk, "step1", false), out + "/af/walk/step1");
  // One folder per rig key, the same for the same key.
  const std::string a = sweepSceneFolder(out, af, "key A"), b = sweepSceneFolder(out, af, "key B");
  EXPECT_NE(a, b);
  EXPECT_EQ(a, sweepSceneFolder(out, af, "key A"));
  EXPECT_EQ(fs::path(a).parent_path().string(), out + "/af/scenes");
  EXPECT_EQ(fs::path(a).filename().string().size(), 16u);

  // Complete: a report naming this G and its label-map files, every output there and not empty.
  const fs::path job = sweepJobFolder(out, af, walk, "", true);
  EXPECT_FALSE(sweepJobComplete(job.string(), af.organs, LabelMapFiles::Nifti));
  nlohmann::json report = {{"input", af.organs}, {"outputs", nlohmann::json::object()}};
  std::vector<std::string> files = labelMapFileNames(LabelMapFiles::Nifti);
  report["outputs"]["label_maps"] = files;
  for (const std::string& f : files) write(job / f, "data");
  write(job / "report.json", report.dump());
  EXPECT_TRUE(sweepJobComplete(job.string(), af.organs, LabelMapFiles::Nifti));
  EXPECT_FALSE(sweepJobComplete(job.string(), "/data/other/G.nii.gz", LabelMapFiles::Nifti));
  EXPECT_FALSE(sweepJobComplete(job.string(), af.organs, LabelMapFiles::DicomSeg));
  write(job / files.front(), "");  // an empty output: done again
  EXPECT_FALSE(sweepJobComplete(job.string(), af.organs, LabelMapFiles::Nifti));

  // Records through JSON, with and without their figures; the summary's three files.
  SweepRecord done;
  done.job = 1, done.subject = "af", done.pose = "walk", done.frame = "step1";
  done.status = "done", done.folder = "af/walk/step1", done.rank = 1, done.seconds = 12.5;
  done.bodyVolumeChangePercent = -0.25, done.worstLabelChangePercent = 0.75;
  done.bonesMinDice = 0.97, done.targetsMet = true;
  SweepRecord failed;
  failed.job = 0, failed.subject = "af", failed.pose = "sit", failed.status = "failed";
  failed.error = "sit.pose.json: groups[0]: no such part", failed.folder = "af/sit";
  for (const SweepRecord& r : {done, failed})
    EXPECT_EQ(sweepRecordToJson(sweepRecordFromJson(sweepRecordToJson(r))), sweepRecordToJson(r));
  EXPECT_FALSE(sweepRecordFromJson(sweepRecordToJson(failed)).bonesMinDice.has_value());
  SweepSummary totals;
  totals.ranks = 2, totals.seconds = 30, totals.mpi = true;
  const nlohmann::json summary =
      nlohmann::json::parse(writeSweepSummary(out, {done, failed}, totals));
  for (const char* f : {"sweep.json", "sweep.csv", "sweep.svg"})
    EXPECT_GT(fs::file_size(fs::path(out) / f), 0u) << f;
  std::ifstream csv(fs::path(out) / "sweep.csv");
  int rows = 0;
  for (std::string line; std::getline(csv, line);) rows += !line.empty();
  EXPECT_EQ(rows, 3);  // a header and one row per job
  EXPECT_EQ(nlohmann::json::parse(std::ifstream(fs::path(out) / "sweep.json")), summary);
}
