#include "DicomSandbox.h"

#include "repose/util/Error.h"

#include <gdcmImageReader.h>
#include <gdcmScanner.h>

#include <fcntl.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cerrno>
#include <cstdint>
#include <vector>

namespace repose::io {

namespace {

// The child: announce each file on the pipe, then read it the ways readDicomSeries will.
[[noreturn]] void childReads(const std::vector<std::string>& files, int out) {
  for (std::uint32_t i = 0; i < files.size(); ++i) {
    if (write(out, &i, sizeof i) != sizeof i) _exit(0);  // parent gone: nothing to report to
    gdcm::Scanner scanner;
    scanner.AddTag(gdcm::Tag(0x0020, 0x000E));
    scanner.AddTag(gdcm::Tag(0x0020, 0x0032));
    scanner.Scan({files[i]});
    gdcm::ImageReader reader;
    reader.SetFileName(files[i].c_str());
    if (!reader.Read()) continue;
    const gdcm::Image& image = reader.GetImage();
    std::vector<char> buffer(image.GetBufferLength());
    image.GetBuffer(buffer.data());
  }
  _exit(0);  // no atexit handlers, no flushing of the parent's buffers
}

}  // namespace

void probeDicomFilesInChild(const std::vector<std::string>& files) {
  if (files.empty()) return;
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
    childReads(files, fds[1]);
  }
  close(fds[1]);
  std::uint32_t index = 0, last = 0;
  bool any = false;
  ssize_t got;
  while ((got = read(fds[0], &index, sizeof index)) == sizeof index || (got < 0 && errno == EINTR))
    if (got == sizeof index) last = index, any = true;
  close(fds[0]);
  int status = 0;
  while (waitpid(pid, &status, 0) < 0 && errno == EINTR) {
  }
  if (WIFEXITED(status) && WEXITSTATUS(status) == 0) return;
  const std::string& file = any && last < files.size() ? files[last] : files.front();
  throwFileError(
      file,
      "corrupt DICOM: the DICOM library (GDCM) " +
          (WIFSIGNALED(status)
               ? "crashed reading it (signal " + std::to_string(WTERMSIG(status)) + ")"
               : "failed hard reading it (exit " + std::to_string(WEXITSTATUS(status)) + ")"));
}

}  // namespace repose::io
