// The child process GDCM reads each DICOM file in first: a reader that hangs is stopped at the
// time limit and its file refused by name; one that crashes is refused by name; the real GDCM
// reader passes a valid series within the default limits and is stopped by a zero limit.
#include "TestPaths.h"
#include "io/DicomSandbox.h"

#include "repose/util/Error.h"

#include <gtest/gtest.h>

#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <chrono>
#include <cstdlib>
#include <filesystem>
#include <fstream>

using namespace repose;
using namespace repose::test;

namespace {

std::vector<std::string> threeFiles() {
  return {"/data/a.dcm", "/data/b.dcm", "/data/c.dcm"};
}

// The message of the Error a probe throws ("" when it throws none).
std::string probeError(const std::vector<std::string>& files, const io::DicomProbeLimits& limits,
                       const std::function<void(const std::string&)>& reader) {
  try {
    io::probeFilesInChild(files, limits, reader);
  } catch (const Error& e) {
    return e.what();
  }
  return "";
}

// No child of this process is left unreaped (killed children are waited for).
bool noChildLeft() {
  return waitpid(-1, nullptr, WNOHANG) < 0 && errno == ECHILD;
}

}  // namespace

TEST(DicomSandbox, AReaderThatNeverReturnsIsStoppedAtTheLimitAndItsFileNamed) {
  const auto start = std::chrono::steady_clock::now();
  const std::string msg = probeError(threeFiles(), {0.3, 1e12}, [](const std::string& f) {
    if (f == "/data/b.dcm")
      for (;;) pause();
  });
  const double seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  EXPECT_EQ(msg.rfind("/data/b.dcm: corrupt DICOM: ", 0), 0u) << msg;
  EXPECT_NE(msg.find("did not finish reading it within 0.3 s"), std::string::npos) << msg;
  EXPECT_EQ(msg.find('\n'), std::string::npos) << msg;
  EXPECT_GE(seconds, 0.3);
  EXPECT_LT(seconds, 5.0);  // the limit, not a hang: generous for a loaded machine
  EXPECT_TRUE(noChildLeft());
}

TEST(DicomSandbox, TheClockRestartsForEachFile) {
  // Three files of 0.2 s each under a 0.5 s limit per file: 0.6 s in all, and no overrun.
  const std::string msg =
      probeError(threeFiles(), {0.5, 1e12}, [](const std::string&) { usleep(200000); });
  EXPECT_EQ(msg, "");
  EXPECT_TRUE(noChildLeft());
}

TEST(DicomSandbox, TheLimitGrowsWithTheFileSize) {
  // 0.1 s a file plus 1 s a megabyte: a reader taking 0.5 s passes on a 1 MB file and overruns
  // on an empty one.
  ScratchDir dir;
  const std::string big = dir.file("big.dcm"), empty = dir.file("empty.dcm");
  std::ofstream(big, std::ios::binary) << std::string(1000000, '\0');
  std::ofstream(empty, std::ios::binary).flush();
  const auto halfSecond = [](const std::string&) { usleep(500000); };
  EXPECT_EQ(probeError({big}, {0.1, 1e6}, halfSecond), "");
  const std::string msg = probeError({empty}, {0.1, 1e6}, halfSecond);
  EXPECT_NE(msg.find("empty.dcm: corrupt DICOM: the DICOM library (GDCM) did not finish reading "
                     "it within 0.1 s"),
            std::string::npos)
      << msg;
  EXPECT_TRUE(noChildLeft());
}

TEST(DicomSandbox, AReaderThatCrashesIsRefusedByName) {
  const std::string msg = probeError(threeFiles(), {}, [](const std::string& f) {
    if (f == "/data/c.dcm") std::abort();
  });
  EXPECT_EQ(msg.rfind("/data/c.dcm: corrupt DICOM: the DICOM library (GDCM) crashed reading it "
                      "(signal 6)",
                      0),
            0u)
      << msg;
  EXPECT_TRUE(noChildLeft());
}

TEST(DicomSandbox, AReaderThatAllocatesPastTheCapIsRefusedByName) {
  // 64 MB plus 64 bytes per byte of the largest file (none here: no such files) allowed; the
  // reader of b.dcm touches 1 GB. The parent's own allocations are not capped.
  const std::string msg = probeError(threeFiles(), {5.0, 10e6, 64e6, 64}, [](const std::string& f) {
    if (f != "/data/b.dcm") return;
    std::vector<char> big(std::size_t(1) << 30, 1);
    if (big[big.size() / 2] != 1) std::abort();
  });
  EXPECT_EQ(msg.rfind("/data/b.dcm: corrupt DICOM: the DICOM library (GDCM) ", 0), 0u) << msg;
  EXPECT_EQ(msg.find('\n'), std::string::npos) << msg;
  // AddressSanitizer's allocator aborts on a failed allocation before operator new can report it.
  EXPECT_NE(
      msg.find(kAddressSanitizer ? "crashed reading it" : "needed more than 64 MB to read it"),
      std::string::npos)
      << msg;
  std::vector<char> parent(std::size_t(256) << 20, 1);  // the cap stayed in the child
  EXPECT_EQ(parent.back(), 1);
  EXPECT_TRUE(noChildLeft());
}

TEST(DicomSandbox, GdcmReadsAValidSeriesWithinTheDefaultLimitsAndIsStoppedByAZeroLimit) {
  std::vector<std::string> files;
  for (const auto& e :
       std::filesystem::directory_iterator(dataPath("totalsegmentator/example_ct_dicom_j2k")))
    files.push_back(e.path().string());
  std::sort(files.begin(), files.end());
  ASSERT_EQ(files.size(), 20u);
  EXPECT_NO_THROW(io::probeDicomFilesInChild(files));
  try {
    io::probeDicomFilesInChild(files, {0.0, 1e12});
    FAIL() << "20 JPEG 2000 slices were decoded in no time";
  } catch (const Error& e) {
    const std::string msg = e.what();
    EXPECT_NE(msg.find("did not finish reading it within 0.0 s"), std::string::npos) << msg;
    EXPECT_EQ(msg.find('\n'), std::string::npos) << msg;
  }
  EXPECT_TRUE(noChildLeft());
}
