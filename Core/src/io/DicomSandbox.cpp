#include "DicomSandbox.h"

#include "repose/util/Error.h"

#include <gdcmImageReader.h>
#include <gdcmScanner.h>

#include <fcntl.h>
#include <poll.h>
#include <signal.h>
#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <chrono>
#include <climits>
#include <cstdint>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <limits>
#include <new>

namespace repose::io {

namespace {

using Clock = std::chrono::steady_clock;

// The child: announce each file on the pipe, then read it. The announcement is what lets the
// parent name the file a crash or an overrun happened on, and restart the clock for the next one.
[[noreturn]] void childReads(const std::vector<std::string>& files,
                             const std::function<void(const std::string&)>& readInChild, int out) {
  for (std::uint32_t i = 0; i < files.size(); ++i) {
    if (write(out, &i, sizeof i) != sizeof i) _exit(0);  // parent gone: nothing to report to
    readInChild(files[i]);
  }
  _exit(0);  // no atexit handlers, no flushing of the parent's buffers
}

// GDCM reading a file the ways readDicomSeries will: the scanner's tags, then the pixel data.
void gdcmReads(const std::string& file) {
  gdcm::Scanner scanner;
  scanner.AddTag(gdcm::Tag(0x0020, 0x000E));
  scanner.AddTag(gdcm::Tag(0x0020, 0x0032));
  scanner.Scan({file});
  gdcm::ImageReader reader;
  reader.SetFileName(file.c_str());
  if (!reader.Read()) return;
  const gdcm::Image& image = reader.GetImage();
  std::vector<char> buffer(image.GetBufferLength());
  image.GetBuffer(buffer.data());
}

double secondsAllowed(const std::string& file, const DicomProbeLimits& limits) {
  std::error_code ec;
  const auto size = std::filesystem::file_size(file, ec);
  return limits.secondsPerFile + (ec ? 0.0 : double(size) / limits.bytesPerSecond);
}

// The exit code of a child whose allocation failed under its memory cap.
constexpr int kOutOfMemoryExit = 86;

// Caps what the child can allocate from now on: RLIMIT_DATA counts the heap and private
// mappings, so the cap is what the process already has mapped (VmData: under AddressSanitizer
// that includes terabytes of reserved shadow) plus the allowance. An allocation past it fails;
// operator new then ends the child with kOutOfMemoryExit (under the sanitizers the allocator
// aborts instead: the file is refused either way).
void capChildMemory(double allowanceBytes) {
  std::ifstream status("/proc/self/status");
  std::string key;
  unsigned long long kib = 0;
  while (status >> key) {
    if (key == "VmData:" && status >> kib) break;
    status.ignore(std::numeric_limits<std::streamsize>::max(), '\n');
  }
  if (kib == 0) return;  // no /proc: no cap, the time limit still holds
  const auto limit = rlim_t(double(kib) * 1024.0 + std::max(allowanceBytes, 0.0));
  const rlimit r{limit, limit};
  if (setrlimit(RLIMIT_DATA, &r) != 0) return;
  std::set_new_handler([] { _exit(kOutOfMemoryExit); });
}

double memoryAllowed(const std::vector<std::string>& files, const DicomProbeLimits& limits) {
  std::uintmax_t largest = 0;
  for (const std::string& f : files) {
    std::error_code ec;
    const auto size = std::filesystem::file_size(f, ec);
    if (!ec) largest = std::max(largest, size);
  }
  return limits.memoryBytes + limits.memoryPerFileByte * double(largest);
}

std::string megabytes(double bytes) {
  return std::to_string(static_cast<long long>(bytes / 1e6 + 0.5)) + " MB";
}

Clock::time_point deadlineAfter(double seconds) {
  return Clock::now() + std::chrono::duration_cast<Clock::duration>(
                            std::chrono::duration<double>(std::max(seconds, 0.0)));
}

}  // namespace

void probeFilesInChild(const std::vector<std::string>& files, const DicomProbeLimits& limits,
                       const std::function<void(const std::string&)>& readInChild) {
  if (files.empty()) return;
  const double memory = memoryAllowed(files, limits);
  int fds[2];
  if (pipe(fds) != 0) return;
  const pid_t pid = fork();
  if (pid < 0) {
    close(fds[0]);
    close(fds[1]);
    return;
  }
  if (pid == 0) {
    close(fds[0]);
    // GDCM's assertion text would be a second line under the parent's one-line error.
    const int null = open("/dev/null", O_WRONLY);
    if (null >= 0) dup2(null, STDERR_FILENO);
    capChildMemory(memory);
    childReads(files, readInChild, fds[1]);
  }
  close(fds[1]);

  // Follow the announcements until the child closes the pipe (it exited or died) or overruns the
  // time allowed for the file it announced last; the clock restarts at each announcement.
  std::uint32_t current = 0;
  double allowed = secondsAllowed(files[0], limits);
  Clock::time_point deadline = deadlineAfter(allowed);
  bool overran = false;
  for (;;) {
    const auto left = deadline - Clock::now();
    if (left <= Clock::duration::zero()) {
      overran = true;
      break;
    }
    const auto ms = std::chrono::ceil<std::chrono::milliseconds>(left).count();
    pollfd p{fds[0], POLLIN, 0};
    const int ready = poll(&p, 1, int(std::min<long long>(ms, INT_MAX)));
    if (ready < 0 && errno == EINTR) continue;
    if (ready < 0) break;  // cannot watch the clock: wait for the child as before
    if (ready == 0) continue;
    std::uint32_t index = 0;
    const ssize_t got = read(fds[0], &index, sizeof index);
    if (got < 0 && errno == EINTR) continue;
    if (got != sizeof index || index >= files.size()) break;  // end of file: the child is done
    current = index;
    allowed = secondsAllowed(files[index], limits);
    deadline = deadlineAfter(allowed);
  }
  if (overran) kill(pid, SIGKILL);
  close(fds[0]);
  int status = 0;
  while (waitpid(pid, &status, 0) < 0 && errno == EINTR) {
  }
  const std::string& file = files[current];
  if (overran) {
    char seconds[32];
    std::snprintf(seconds, sizeof seconds, "%.1f", allowed);
    throwFileError(file, std::string("corrupt DICOM: the DICOM library (GDCM) did not finish "
                                     "reading it within ") +
                             seconds + " s, the time allowed for a file of its size");
  }
  if (WIFEXITED(status) && WEXITSTATUS(status) == 0) return;
  if (WIFEXITED(status) && WEXITSTATUS(status) == kOutOfMemoryExit)
    throwFileError(file, "corrupt DICOM: the DICOM library (GDCM) needed more than " +
                             megabytes(memory) +
                             " to read it, the memory allowed for a series "
                             "whose largest file has its size");
  throwFileError(
      file,
      "corrupt DICOM: the DICOM library (GDCM) " +
          (WIFSIGNALED(status)
               ? "crashed reading it (signal " + std::to_string(WTERMSIG(status)) + ")"
               : "failed hard reading it (exit " + std::to_string(WEXITSTATUS(status)) + ")"));
}

void probeDicomFilesInChild(const std::vector<std::string>& files, const DicomProbeLimits& limits) {
  probeFilesInChild(files, limits, gdcmReads);
}

}  // namespace repose::io
