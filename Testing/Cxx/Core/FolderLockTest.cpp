// One run at a time per output folder (FolderLock), and the temporary folders a killed run
// leaves removed by the next output into the folder (removeStaleTemporaries).
#include "TestPaths.h"
#include "repose/io/AtomicOutput.h"
#include "repose/io/FolderLock.h"
#include "repose/util/Error.h"

#include <gtest/gtest.h>

#include <sys/wait.h>
#include <signal.h>
#include <unistd.h>

#include <algorithm>
#include <filesystem>
#include <fstream>
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
