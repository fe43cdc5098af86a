// All-or-nothing commits of several files (AtomicOutput.h, CommitJournal.h).
#include "CommitJournal.h"

#include "repose/io/AtomicOutput.h"
#include "repose/util/Error.h"

#include <nlohmann/json.hpp>

#include <fcntl.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <fstream>
#include <set>
#include <string>
#include <vector>

namespace fs = std::filesystem;

namespace repose {

namespace detail {
void (*commitStepHook)(std::size_t step) = nullptr;
void (*commitSyncHook)(const std::string& path) = nullptr;
}  // namespace detail

// Makes what `path` (a file, or a folder's entries) holds reach the disk, so a power cut or a
// crash of the machine cannot undo it: a rename alone survives a kill of the process, but the
// file system may write the new name before the file's data, and a cut between the two leaves an
// empty or partial file under the published name. A folder whose file system cannot sync folders
// (EINVAL: some network and FUSE file systems) is left as it is; any other failure means the
// data may not be on the disk, and throws repose::Error naming `target`.
void syncToDisk(const std::string& path, bool folder, const std::string& target) {
  if (detail::commitSyncHook) detail::commitSyncHook(path);
  const int fd = ::open(path.c_str(), folder ? O_RDONLY | O_DIRECTORY : O_RDONLY);
  if (fd < 0)
    throwFileError(target, "cannot write to the disk: " + std::string(std::strerror(errno)));
  const int rc = ::fsync(fd);
  const int error = errno;
  ::close(fd);
  if (rc != 0 && !(folder && (error == EINVAL || error == ENOTSUP)))
    throwFileError(target, "cannot write to the disk: " + std::string(std::strerror(error)));
}

namespace {

const char* const kJournal = ".repose-commit";        // in the first folder: the decision
const char* const kMember = ".repose-commit-member";  // in the others: the first folder's path

void hook(std::size_t step) {
  if (detail::commitStepHook) detail::commitStepHook(step);
}

fs::path folderOf(const fs::path& file) {
  const fs::path parent = file.parent_path();
  return parent.empty() ? fs::path(".") : parent;
}

// Written whole or not at all (a rename within the folder), so a kill never leaves half a
// journal that would read as a decision; on the disk before it is renamed into place, and its
// name on the disk before the first step.
void writeWhole(const fs::path& path, const std::string& text, const std::string& target) {
  const fs::path part = path.string() + ".part";
  {
    std::ofstream f(part, std::ios::binary);
    f << text;
    if (!f.flush()) throwFileError(target, "cannot write in the output folder");
  }
  syncToDisk(part.string(), false, target);
  std::error_code ec;
  fs::rename(part, path, ec);
  if (ec) throwFileError(target, "cannot write in the output folder: " + ec.message());
  syncToDisk(folderOf(path).string(), true, target);
}

// Before a commit publishes them: every file it moves, on the disk.
void syncSources(const std::vector<CommitStep>& steps) {
  std::error_code ec;
  for (const CommitStep& s : steps)
    if (!s.from.empty() && fs::is_regular_file(s.from, ec)) syncToDisk(s.from, false, s.to);
}

// After: the folders the commit changed, so the new names (and removals) are on the disk too.
void syncTargets(const std::vector<CommitStep>& steps) {
  std::set<fs::path> folders;
  for (const CommitStep& s : steps) folders.insert(folderOf(s.to));
  for (const fs::path& f : folders) syncToDisk(f.string(), true, (f / "").string());
}

// A step done again after a kill is harmless: a file already moved is no longer in its
// temporary folder, and a removed file is gone.
std::size_t apply(const CommitStep& step, std::error_code& ec) {
  if (step.from.empty()) {
    fs::remove(step.to, ec);
    return 0;
  }
  if (!fs::exists(step.from, ec)) return 0;
  fs::rename(step.from, step.to, ec);
  return ec ? 0 : 1;
}

struct Journal {
  std::vector<std::string> folders;
  std::vector<CommitStep> steps;
};

std::optional<Journal> readJournal(const fs::path& folder) {
  std::ifstream in(folder / kJournal, std::ios::binary);
  if (!in) return std::nullopt;
  try {
    const nlohmann::json j = nlohmann::json::parse(in);
    Journal journal;
    journal.folders = j.at("folders").get<std::vector<std::string>>();
    for (const auto& s : j.at("steps"))
      journal.steps.push_back({s.at("from").get<std::string>(), s.at("to").get<std::string>()});
    return journal;
  } catch (const nlohmann::json::exception&) {
    return std::nullopt;  // not ours, or damaged otherwise than by a kill: not a decision
  }
}

}  // namespace

void commitFiles(const std::vector<std::string>& folders, const std::vector<CommitStep>& steps,
                 const std::string& target) {
  std::error_code ec;
  syncSources(steps);
  // One rename alone is atomic already.
  if (steps.size() == 1) {
    apply(steps[0], ec);
    if (ec) throwFileError(steps[0].to, "cannot move the output into place: " + ec.message());
    syncTargets(steps);
    return;
  }
  if (folders.empty()) throw Error("commitFiles: no temporary folder");
  // Absolute paths: the run that finishes a killed commit may work in another folder.
  const auto absolute = [](const std::string& p) {
    return p.empty() ? p : fs::absolute(p).lexically_normal().string();
  };
  for (std::size_t k = 1; k < folders.size(); ++k)
    writeWhole(fs::path(folders[k]) / kMember, absolute(folders[0]), target);
  nlohmann::json j;
  j["folders"] = nlohmann::json::array();
  for (const std::string& f : folders) j["folders"].push_back(absolute(f));
  j["steps"] = nlohmann::json::array();
  for (const CommitStep& s : steps)
    j["steps"].push_back({{"from", absolute(s.from)}, {"to", absolute(s.to)}});
  const fs::path journal = fs::path(folders[0]) / kJournal;
  writeWhole(journal, j.dump(), target);
  hook(0);
  for (std::size_t i = 0; i < steps.size(); ++i) {
    apply(steps[i], ec);
    if (ec) {
      // Not a kill: this run reports it, and its temporary folders go with it.
      fs::remove(journal, ec);
      throwFileError(steps[i].to, "cannot move the output into place: " + ec.message());
    }
    hook(i + 1);
  }
  // The moves on the disk before the journal goes: a machine that stops between the two
  // finishes the commit again on the next output into the folder, which is harmless.
  syncTargets(steps);
  // Done: the journal goes first, so what is left of the folders is plain leftovers.
  fs::remove(journal, ec);
}

namespace io {

std::optional<std::size_t> recoverKilledCommit(const fs::path& folder) {
  fs::path first = folder;
  std::error_code ec;
  if (!fs::exists(folder / kJournal, ec)) {
    std::ifstream member(folder / kMember, std::ios::binary);
    if (!member) return std::nullopt;
    std::string path((std::istreambuf_iterator<char>(member)), {});
    first = path;
  }
  const std::optional<Journal> journal = readJournal(first);
  if (!journal) return std::nullopt;
  std::size_t moved = 0;
  for (const CommitStep& step : journal->steps) {
    moved += apply(step, ec);
    if (ec) return moved;  // left as it is, for a later run to finish (the same files, once)
  }
  try {
    syncTargets(journal->steps);
  } catch (const Error&) {
    return moved;  // the journal stays, for a later run to finish the commit again
  }
  fs::remove(first / kJournal, ec);
  for (const std::string& f : journal->folders) fs::remove_all(f, ec);
  fs::remove_all(folder, ec);
  return moved;
}

}  // namespace io
}  // namespace repose
