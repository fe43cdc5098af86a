// Safe output files: everything is written inside a hidden temporary folder beside the target
// (.repose-tmp-HOST-PID-XXXXXX) and moved into place only on commit(), so a failure or a kill
// never leaves a partial file at the target. What a kill leaves in the temporary folder is removed
// by the next output into the same folder (removeStaleTemporaries).
#pragma once

#include <string>
#include <vector>

namespace repose {

class AtomicOutput {
 public:
  // Creates the temporary folder in the target's folder; throws repose::Error naming finalPath
  // when that folder does not exist or cannot be written.
  explicit AtomicOutput(const std::string& finalPath);
  ~AtomicOutput();  // removes the temporary folder and its content unless committed
  AtomicOutput(const AtomicOutput&) = delete;
  AtomicOutput& operator=(const AtomicOutput&) = delete;

  // Where to write: the final file name inside the temporary folder. Companion files
  // (a .nhdr's data file) written beside it are moved too.
  const std::string& tempPath() const { return tempPath_; }
  const std::string& finalPath() const { return finalPath_; }
  // Moves every file of the temporary folder into the target folder (rename, same filesystem).
  // Throws Interrupted instead when the run was interrupted (nothing is moved).
  void commit();

 private:
  friend void commitTogether(const std::vector<AtomicOutput*>& outputs);
  void move();
  std::string finalPath_;
  std::string tempDir_;
  std::string tempPath_;
  bool committed_ = false;
};

// Several outputs of one run (a posed map, its image, its transform) as one unit: an interrupted
// run publishes none of them; otherwise all are moved into place, with no interruption point
// between two of them.
void commitTogether(const std::vector<AtomicOutput*>& outputs);

// Writes `text` to `path` through an AtomicOutput: the whole file or nothing. Throws repose::Error.
void writeTextFileAtomically(const std::string& path, const std::string& text);

// Makes a temporary folder in `folder` named as AtomicOutput names its own
// (.repose-tmp-HOST-PID-XXXXXX), after removing the stale ones there; returns its path. Throws
// repose::Error naming `target` when it cannot be made. For outputs of several files moved in
// by their writer (a posed frame).
std::string makeTemporaryFolder(const std::string& folder, const std::string& target);

// Removes from `folder` the temporary folders of runs that were killed before they could clean
// up: those named for a process of this host that no longer exists. A folder of a live process,
// of another host (a shared file system) or of an older Repose (no process in its name) is left.
// Returns the names removed. AtomicOutput calls it on its target's folder.
std::vector<std::string> removeStaleTemporaries(const std::string& folder);

// Throws repose::Error if output names the same file as input (an input is never overwritten).
void refuseOverwritingInput(const std::string& input, const std::string& output);

}  // namespace repose
