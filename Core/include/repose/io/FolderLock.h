// One Repose run at a time per output folder: an advisory lock (flock) on a hidden file in the
// folder, so two runs writing the same frames or the same scene cannot interleave their files.
// The kernel releases the lock when the process ends, however it ends (a SIGKILL included), so a
// killed run never blocks the next one.
#pragma once

#include <string>

namespace repose {

class FolderLock {
 public:
  // Takes the lock of `folder` (which must exist) without waiting. Throws repose::Error naming
  // the folder, and the process holding it, when another run (or another FolderLock of this
  // process) holds it.
  explicit FolderLock(const std::string& folder);
  ~FolderLock();  // removes the lock file, then releases the lock
  FolderLock(const FolderLock&) = delete;
  FolderLock& operator=(const FolderLock&) = delete;

  static constexpr const char* kFileName = ".repose.lock";

 private:
  std::string path_;
  int fd_ = -1;
};

}  // namespace repose
