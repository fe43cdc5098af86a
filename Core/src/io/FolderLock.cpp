// The folder's lock file, taken with flock; see FolderLock.h.
#include "repose/io/FolderLock.h"

#include "repose/util/Error.h"

#include <fcntl.h>
#include <sys/file.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <filesystem>
#include <string>

namespace fs = std::filesystem;

namespace repose {

FolderLock::FolderLock(const std::string& folder) {
  std::error_code ec;
  if (!fs::is_directory(folder, ec))
    throwFileError(folder,
                   fs::exists(folder, ec) ? "not a folder" : "output folder does not exist");
  path_ = (fs::path(folder) / kFileName).string();
  // The holder removes the file before it lets go, so a lock taken on a file that is no longer
  // the one at the path (removed, perhaps made again, in between) is no lock: try again.
  for (int attempt = 0; attempt < 100; ++attempt) {
    const int fd = ::open(path_.c_str(), O_RDWR | O_CREAT | O_CLOEXEC, 0644);
    if (fd < 0)
      throwFileError(folder, std::string("cannot create its lock file: ") + std::strerror(errno));
    if (::flock(fd, LOCK_EX | LOCK_NB) != 0) {
      const int error = errno;
      char text[32] = {0};
      const ssize_t n = ::pread(fd, text, sizeof text - 1, 0);
      ::close(fd);
      if (error != EWOULDBLOCK)
        throwFileError(folder, std::string("cannot lock it: ") + std::strerror(error));
      std::string holder = n > 0 ? std::string(text, std::size_t(n)) : std::string();
      while (!holder.empty() && (holder.back() == '\n' || holder.back() == ' ')) holder.pop_back();
      throwFileError(folder, "another Repose run" +
                                 (holder.empty() ? std::string() : " (process " + holder + ")") +
                                 " is writing here; wait for it to end or choose another folder");
    }
    struct stat held {
    }, now{};
    if (::fstat(fd, &held) == 0 && ::stat(path_.c_str(), &now) == 0 && held.st_dev == now.st_dev &&
        held.st_ino == now.st_ino) {
      const std::string pid = std::to_string(::getpid()) + "\n";
      if (::ftruncate(fd, 0) != 0 || ::pwrite(fd, pid.data(), pid.size(), 0) < 0) {
        // The pid is only for the message another run shows; the lock holds without it.
      }
      fd_ = fd;
      return;
    }
    ::close(fd);
  }
  throwFileError(folder, "cannot lock it: its lock file keeps being replaced");
}

FolderLock::~FolderLock() {
  if (fd_ < 0) return;
  ::unlink(path_.c_str());
  ::close(fd_);
}

}  // namespace repose
