// See FolderClaim.h.
#include "FolderClaim.h"

#include "repose/io/AtomicOutput.h"
#include "repose/util/Error.h"

#include <filesystem>

namespace fs = std::filesystem;

namespace repose::cli {

FolderClaim::FolderClaim(const std::string& folder) : folder_(folder) {
  std::error_code ec;
  if (!fs::is_directory(fs::absolute(folder).parent_path(), ec))
    throwFileError(folder, "its parent folder does not exist");
  if (!fs::exists(folder, ec)) {
    if (!fs::create_directory(folder, ec) || ec)
      throwFileError(folder, "cannot make the folder: " + ec.message());
    made_ = true;
  }
  try {
    lock_ = std::make_unique<FolderLock>(folder);
  } catch (...) {
    if (made_) fs::remove(folder, ec);
    throw;
  }
  stale_ = removeStaleTemporaries(folder);
}

FolderClaim::~FolderClaim() {
  lock_.reset();  // the lock file goes first, so an empty folder is empty
  std::error_code ec;
  if (made_ && fs::is_empty(folder_, ec)) fs::remove(folder_, ec);
}

bool FolderClaim::holds(const std::string& other) const {
  std::error_code ec;
  return fs::exists(other, ec) && fs::equivalent(folder_, other, ec);
}

}  // namespace repose::cli
