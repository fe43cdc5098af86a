// A folder a command writes into, held for the whole run: made if missing, locked so that a
// second run into it refuses at once (repose::FolderLock), cleared of the temporary folders of
// killed runs, and removed again at the end if this run made it and left it empty (a refused or
// failed run leaves no folder behind).
#pragma once

#include "repose/io/FolderLock.h"

#include <memory>
#include <string>
#include <vector>

namespace repose::cli {

class FolderClaim {
 public:
  // Throws repose::Error naming the folder: its parent is missing, or another run holds it.
  explicit FolderClaim(const std::string& folder);
  ~FolderClaim();
  FolderClaim(const FolderClaim&) = delete;
  FolderClaim& operator=(const FolderClaim&) = delete;

  // Whether `other` is this folder (then it needs no claim of its own: a second lock of the same
  // folder would refuse this very run).
  bool holds(const std::string& other) const;
  // The temporary folders of killed runs removed from it (names).
  const std::vector<std::string>& staleRemoved() const { return stale_; }

 private:
  std::string folder_;
  bool made_ = false;
  std::unique_ptr<FolderLock> lock_;
  std::vector<std::string> stale_;
};

}  // namespace repose::cli
