// Safe output files: everything is written inside a hidden temporary folder beside the target
// (.repose-tmp-HOST-PID-XXXXXX) and moved into place only on commit(), so a failure or a kill
// never leaves a partial file at the target. What a kill leaves in the temporary folder is removed
// by the next output into the same folder (removeStaleTemporaries).
#pragma once

#include <cstddef>
#include <string>
#include <vector>

namespace repose {

// One step of a commit: the file `from` (in a temporary folder) renamed to `to`, or with `from`
// empty, the file `to` removed (an output of an earlier run that this one does not write).
struct CommitStep {
  std::string from, to;
};

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
  std::vector<CommitStep> steps() const;  // what move() does: companions first, main file last
  void move();
  std::string finalPath_;
  std::string tempDir_;
  std::string tempPath_;
  bool committed_ = false;
};

// Several outputs of one run (a posed map, its image, its transform) as one unit: an interrupted
// run publishes none of them; otherwise all are moved into place, with no interruption point
// between two of them, and even a SIGKILL between two of them leaves no mix (commitFiles).
void commitTogether(const std::vector<AtomicOutput*>& outputs);

// Applies `steps` in order as one unit that even SIGKILL cannot leave half done. A journal of
// the steps is written into the first of `temporaryFolders` before the first step: a run killed
// before it leaves every target as it was; one killed after it is finished by the next output
// into the folder (removeStaleTemporaries). The caller removes its temporary folders afterwards.
// A step that fails (not a kill) throws repose::Error naming its file, `target` for the journal.
// Durable as well: the moved files and the journal reach the disk (fsync) before the first step,
// and the changed folders after the last, so a power cut cannot leave an empty or partial file
// under a published name either.
void commitFiles(const std::vector<std::string>& temporaryFolders,
                 const std::vector<CommitStep>& steps, const std::string& target);
// Makes what `path` holds reach the disk (fsync): a file's data, or with `folder` a folder's
// entries (names made, renamed or removed). Throws repose::Error naming `target` when it cannot,
// except for a folder on a file system that cannot sync folders (EINVAL, ENOTSUP).
void syncToDisk(const std::string& path, bool folder, const std::string& target);

namespace detail {
// For tests only: called after the journal is written (0) and after each step (1, 2, ...), e.g.
// to kill the process there.
extern void (*commitStepHook)(std::size_t step);
// For tests only: called with each file or folder syncToDisk makes reach the disk, before it.
extern void (*commitSyncHook)(const std::string& path);
}  // namespace detail

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
// A run killed in the middle of a commit (commitFiles) has its commit finished first: the files
// it had decided to publish are moved into place. Returns the names removed, each followed by
// " (its N files moved into place)" when a commit was finished. AtomicOutput calls it on its
// target's folder.
std::vector<std::string> removeStaleTemporaries(const std::string& folder);

// Throws repose::Error if output names the same file as input (an input is never overwritten).
void refuseOverwritingInput(const std::string& input, const std::string& output);

}  // namespace repose
