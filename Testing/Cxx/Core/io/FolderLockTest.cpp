// One run at a time per output folder (FolderLock), and the temporary folders a killed run
// leaves removed by the next output into the folder (removeStaleTemporaries).
#include "TestPaths.h"
#include "repose/io/AtomicOutput.h"
#include "repose/io/FolderLock.h"
#include "repose/pose/PoseFrame.h"
#include "repose/util/Error.h"

#include <gtest/gtest.h>

#include <sys/wait.h>
#include <signal.h>
#include <unistd.h>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <set>
#include <string>

using namespace repose;
using namespace repose::test;
namespace fs = std::filesystem;

namespace {

std::string hostName() {  // as AtomicOutput spells it in its folders' names
  char name[256] = {0};
  ::gethostname(name, sizeof name - 1);
  std::string host(name);
  std::replace(host.begin(), host.end(), '-', '_');
  std::replace(host.begin(), host.end(), '/', '_');
  return host;
}

// A process id that no process has now: a child that has exited and been reaped.
pid_t deadProcess() {
  const pid_t child = ::fork();
  if (child == 0) ::_exit(0);
  ::waitpid(child, nullptr, 0);
  return child;
}

std::string errorOf(const std::string& folder) {
  try {
    FolderLock again(folder);
  } catch (const Error& e) {
    return e.what();
  }
  return "";
}

}  // namespace

TEST(FolderLock, ASecondLockRefusesNamingTheHolderAndTheFolderIsFreeAfterwards) {
  ScratchDir dir;
  const std::string folder = dir.file("out");
  fs::create_directory(folder);
  {
    FolderLock held(folder);
    EXPECT_TRUE(fs::exists(fs::path(folder) / FolderLock::kFileName));
    const std::string error = errorOf(folder);
    EXPECT_EQ(error.rfind(folder + ": another Repose run (process " + std::to_string(::getpid()) +
                              ") is writing here",
                          0),
              0u)
        << error;
  }
  EXPECT_FALSE(fs::exists(fs::path(folder) / FolderLock::kFileName));  // nothing left behind
  EXPECT_EQ(errorOf(folder), "");
  EXPECT_NE(errorOf(dir.file("missing")).find("output folder does not exist"), std::string::npos);
  std::ofstream(dir.file("a file")) << "x";
  EXPECT_EQ(errorOf(dir.file("a file")), dir.file("a file") + ": not a folder");
}

// Another process holds the lock, then is killed: the kernel lets go, and the lock file it left
// does not block the next run.
TEST(FolderLock, AKilledHolderBlocksNothing) {
  ScratchDir dir;
  const std::string folder = dir.file("out");
  fs::create_directory(folder);
  int ready[2];
  ASSERT_EQ(::pipe(ready), 0);
  const pid_t child = ::fork();
  if (child == 0) {
    FolderLock held(folder);
    const char c = 1;
    if (::write(ready[1], &c, 1) != 1) ::_exit(1);
    ::pause();
    ::_exit(0);
  }
  char c = 0;
  ASSERT_EQ(::read(ready[0], &c, 1), 1);
  EXPECT_NE(errorOf(folder).find("(process " + std::to_string(child) + ")"), std::string::npos);
  ::kill(child, SIGKILL);
  ::waitpid(child, nullptr, 0);
  ::close(ready[0]), ::close(ready[1]);
  EXPECT_TRUE(fs::exists(fs::path(folder) / FolderLock::kFileName));  // SIGKILL: no clean-up ran
  EXPECT_EQ(errorOf(folder), "");
}

TEST(AtomicOutput, RemovesTheTemporariesOfDeadProcessesOfThisHostOnly) {
  ScratchDir dir;
  const fs::path folder = dir.file("out");
  fs::create_directory(folder);
  const std::string host = hostName();
  const pid_t dead = deadProcess();
  auto make = [&](const std::string& name) {
    fs::create_directory(folder / name);
    std::ofstream(folder / name / "posed_G.nii.gz") << "part of a file";
    return name;
  };
  const std::string stale = make(".repose-tmp-" + host + "-" + std::to_string(dead) + "-a1B2c3");
  const std::string live =
      make(".repose-tmp-" + host + "-" + std::to_string(::getppid()) + "-a1B2c3");
  const std::string foreign = make(".repose-tmp-otherhost-" + std::to_string(dead) + "-a1B2c3");
  const std::string older = make(".repose-tmp-a1B2c3");  // an older Repose's: no process
  const std::string notOurs = make("repose-tmp-" + host + "-" + std::to_string(dead) + "-a1B2c3");
  // The next output into the folder removes the stale one and writes as usual.
  writeTextFileAtomically((folder / "report.json").string(), "{}\n");
  std::vector<std::string> left;
  for (const auto& e : fs::directory_iterator(folder)) left.push_back(e.path().filename());
  std::sort(left.begin(), left.end());
  std::vector<std::string> expected{live, foreign, older, notOurs, "report.json"};
  std::sort(expected.begin(), expected.end());
  EXPECT_EQ(left, expected);
  // Called directly it finds nothing more to remove, and names what it removes.
  EXPECT_TRUE(removeStaleTemporaries(folder.string()).empty());
  const std::string again =
      make(".repose-tmp-" + host + "-" + std::to_string(deadProcess()) + "-zzzzzz");
  EXPECT_EQ(removeStaleTemporaries(folder.string()), std::vector<std::string>{again});
}

// The temporary folder of a run in progress is named for this host and this process.
TEST(AtomicOutput, NamesItsTemporaryFolderForTheHostAndTheProcess) {
  ScratchDir dir;
  AtomicOutput out(dir.file("x.nii.gz"));
  const std::string name = fs::path(out.tempPath()).parent_path().filename();
  EXPECT_EQ(name.rfind(".repose-tmp-" + hostName() + "-" + std::to_string(::getpid()) + "-", 0), 0u)
      << name;
}

namespace {

// In a child process: three outputs of one run committed together over an earlier run's files,
// the child killed (SIGKILL, no handler) right after commit step `killAfter` (0: the journal
// written; 1-3: that many files moved), or before the commit begins with killAfter < 0. With
// `relative`, the child works in the folder and names its outputs relative to it, as a command
// run there does; the run that finishes the commit works elsewhere.
void killedCommit(const fs::path& folder, int killAfter, bool relative) {
  const pid_t child = ::fork();
  if (child == 0) {
    static int at;
    at = killAfter;
    detail::commitStepHook = [](std::size_t step) {
      if (int(step) == at) ::kill(::getpid(), SIGKILL);
    };
    fs::path in = folder;
    if (relative && ::chdir(folder.c_str()) == 0) in = "";
    AtomicOutput a((in / "posed_G.nii.gz").string()), b((in / "posed_S.nii.gz").string()),
        c((in / "report.json").string());
    for (AtomicOutput* o : {&a, &b, &c}) std::ofstream(o->tempPath()) << "new";
    if (killAfter < 0) ::kill(::getpid(), SIGKILL);
    commitTogether({&a, &b, &c});
    ::_exit(3);  // not reached: killed at its step
  }
  int status = 0;
  ::waitpid(child, &status, 0);
  ASSERT_TRUE(WIFSIGNALED(status) && WTERMSIG(status) == SIGKILL) << killAfter;
}

std::string contentOf(const fs::path& file) {
  std::ifstream in(file);
  return std::string((std::istreambuf_iterator<char>(in)), {});
}

}  // namespace

// SIGKILL in the middle of publishing a run's outputs: the folder may show a mix for as long as
// no Repose run comes (the renames are microseconds apart), and the next output into the folder
// finishes the killed commit from its journal before anything else, so the outputs are all the
// killed run's; killed before its journal, they are all the earlier run's.
TEST(AtomicOutput, AKillDuringTheFinalRenamesIsFinishedByTheNextRunNeverLeftMixed) {
  const std::vector<std::string> names{"posed_G.nii.gz", "posed_S.nii.gz", "report.json"};
  for (const auto& [killAfter, relative] : std::vector<std::pair<int, bool>>{
           {-1, false}, {0, false}, {1, false}, {2, false}, {1, true}}) {
    ScratchDir dir;
    const fs::path folder = dir.file("out");
    fs::create_directory(folder);
    for (const std::string& n : names) std::ofstream(folder / n) << "old";
    killedCommit(folder, killAfter, relative);
    std::size_t moved = 0;
    for (const std::string& n : names) moved += contentOf(folder / n) == "new";
    EXPECT_EQ(moved, std::size_t(std::max(killAfter, 0))) << killAfter;
    // The next run into the folder (here a small text file of its own).
    const std::vector<std::string> removed = removeStaleTemporaries(folder.string());
    const std::string expectedAll = killAfter < 0 ? "old" : "new";
    for (const std::string& n : names) EXPECT_EQ(contentOf(folder / n), expectedAll) << killAfter;
    // Reported: the folders of the run's three outputs, the commit named once it was decided.
    ASSERT_FALSE(removed.empty()) << killAfter;
    const std::string note =
        "(its " + std::to_string(3 - std::max(killAfter, 0)) + " files moved into place)";
    const bool finished = std::any_of(removed.begin(), removed.end(), [&](const std::string& r) {
      return r.find(note) != std::string::npos;
    });
    EXPECT_EQ(finished, killAfter >= 0) << killAfter;
    std::vector<std::string> left;
    for (const auto& e : fs::directory_iterator(folder)) left.push_back(e.path().filename());
    std::sort(left.begin(), left.end());
    EXPECT_EQ(left, (std::vector<std::string>{"posed_G.nii.gz", "posed_S.nii.gz", "report.json"}))
        << killAfter;
  }
}

// A power cut is not a kill: the file system may put a renamed name on the disk before the file's
// data. So every file a commit publishes reaches the disk before the commit's first rename, the
// journal before it is relied on, and the output folder after the last rename; and the journal
// is still there when the folder is synced (a cut before that finishes the commit again). One
// output alone (a single rename) is synced the same way.
TEST(AtomicOutput, ACommitPutsItsFilesOnTheDiskBeforeItPublishesThemAndItsFolderAfter) {
  ScratchDir dir;
  const fs::path folder = fs::canonical(dir.path());
  static std::vector<std::string> events;
  events.clear();
  detail::commitSyncHook = [](const std::string& path) {
    std::error_code ec;
    const bool journal = fs::exists(fs::path(path) / ".repose-commit", ec) ||
                         fs::path(path).filename() == ".repose-commit.part";
    events.push_back("sync " + fs::path(path).filename().string() + (journal ? " +journal" : ""));
  };
  detail::commitStepHook = [](std::size_t step) {
    events.push_back("step " + std::to_string(step));
  };
  {
    AtomicOutput a((folder / "posed_G.nii.gz").string()), b((folder / "report.json").string());
    std::ofstream(a.tempPath()) << "labels";
    std::ofstream(b.tempPath()) << "{}";
    commitTogether({&a, &b});
  }
  detail::commitStepHook = nullptr;
  const std::string top = folder.filename().string();
  auto at = [&](const std::string& e) {
    return std::find(events.begin(), events.end(), e) - events.begin();
  };
  const auto n = std::ptrdiff_t(events.size());
  ASSERT_LT(at("sync posed_G.nii.gz"), n);
  ASSERT_LT(at("sync report.json"), n);
  ASSERT_LT(at("sync .repose-commit.part +journal"), n);
  ASSERT_LT(at("step 0"), n);
  ASSERT_LT(at("step 2"), n);
  EXPECT_LT(at("sync posed_G.nii.gz"), at("step 0"));
  EXPECT_LT(at("sync report.json"), at("step 0"));
  EXPECT_LT(at("sync .repose-commit.part +journal"), at("step 0"));
  // The journal's folder (a temporary one) synced after the journal's rename, before step 0.
  const auto tempSynced = std::find_if(events.begin(), events.end(),
                                       [](const std::string& e) {
                                         return e.rfind("sync .repose-tmp-", 0) == 0 &&
                                                e.find("+journal") != std::string::npos;
                                       }) -
                          events.begin();
  EXPECT_LT(tempSynced, at("step 0"));
  // The output folder after the last rename, while the journal still decides.
  ASSERT_LT(at("sync " + top), n);
  EXPECT_LT(at("step 2"), at("sync " + top));
  EXPECT_EQ(contentOf(folder / "posed_G.nii.gz"), "labels");
  // One output alone: its file before the rename, its folder after.
  events.clear();
  {
    AtomicOutput one((folder / "alone.txt").string());
    std::ofstream(one.tempPath()) << "x";
    one.commit();
    EXPECT_TRUE(fs::exists(folder / "alone.txt"));
  }
  detail::commitSyncHook = nullptr;
  EXPECT_EQ(events, (std::vector<std::string>{"sync alone.txt", "sync " + top}));
}

// A posed frame written into a new folder is renamed into place as a whole folder, not through a
// commit: its files reach the disk before the folder appears under its name, and the folder's
// parent after; into an existing folder it is a commit (above).
TEST(AtomicOutput, ANewFrameFolderIsOnTheDiskBeforeItAppears) {
  ScratchDir dir;
  const fs::path folder = fs::canonical(dir.path());
  PosedFrame frame;
  frame.name = "rest";
  frame.grid.dims = {3, 2, 2};
  frame.organs = Volume(frame.grid, ScalarType::UInt8);
  frame.organs.setLabelMap(true);
  frame.parts = Volume(frame.grid, ScalarType::UInt8);
  frame.parts.setLabelMap(true);
  frame.field.assign(3 * 12, 0.0f);
  frame.reportJson = "{}";
  static std::vector<std::string> synced;
  synced.clear();
  static fs::path frameFolder;
  frameFolder = folder / "frame";
  detail::commitSyncHook = [](const std::string& path) {
    // Where it is when synced: in the hidden folder (a file) or the frame folder's parent.
    synced.push_back(fs::path(path).filename().string() +
                     (fs::exists(frameFolder) ? " (frame in place)" : ""));
  };
  writePosedFrame(frame, frameFolder.string());
  detail::commitSyncHook = nullptr;
  std::vector<std::string> files;
  for (const auto& e : fs::directory_iterator(frameFolder)) files.push_back(e.path().filename());
  std::sort(files.begin(), files.end());
  ASSERT_FALSE(files.empty());
  ASSERT_GE(synced.size(), files.size() + 2);
  // Every file of the frame (each writer syncs its own file too), and the hidden folder they are
  // in, before the frame is in place; then the folder holding the frame, once, after.
  std::set<std::string> before(synced.begin(), synced.end() - 1);
  std::set<std::string> expected(files.begin(), files.end());
  ASSERT_EQ(synced[synced.size() - 2].rfind(".repose-tmp-", 0), 0u) << synced[synced.size() - 2];
  expected.insert(synced[synced.size() - 2]);
  EXPECT_EQ(before, expected);
  EXPECT_EQ(synced.back(), folder.filename().string() + " (frame in place)");
  EXPECT_EQ(
      std::count_if(synced.begin(), synced.end(),
                    [](const std::string& s) { return s.find("in place") != std::string::npos; }),
      1);
}
