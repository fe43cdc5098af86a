// Temporary folder beside the target, renamed into place on commit; see AtomicOutput.h.
#include "repose/io/AtomicOutput.h"

#include "CommitJournal.h"

#include <fstream>

#include "repose/util/Error.h"
#include "repose/util/Interrupt.h"

#include <signal.h>
#include <unistd.h>

#include <cerrno>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <vector>

namespace fs = std::filesystem;

namespace repose {

namespace {

const std::string kTempPrefix = ".repose-tmp-";

std::string hostName() {
  char name[256] = {0};
  if (::gethostname(name, sizeof name - 1) != 0) return "host";
  std::string host(name);
  for (char& c : host)  // the name is parsed back from the right, at '-'
    if (c == '/' || c == '-') c = '_';
  return host.empty() ? "host" : host;
}

}  // namespace

std::string makeTemporaryFolder(const std::string& folder, const std::string& target) {
  removeStaleTemporaries(folder);
  const std::string pattern =
      (fs::path(folder) / (kTempPrefix + hostName() + "-" + std::to_string(::getpid()) + "-XXXXXX"))
          .string();
  std::vector<char> buf(pattern.begin(), pattern.end());
  buf.push_back('\0');
  if (!::mkdtemp(buf.data()))
    throwFileError(target,
                   std::string("cannot write in the output folder: ") + std::strerror(errno));
  return buf.data();
}

std::vector<std::string> removeStaleTemporaries(const std::string& folder) {
  std::vector<std::string> removed;
  std::error_code ec;
  const std::string host = hostName();
  for (fs::directory_iterator it(folder, ec), end; !ec && it != end; it.increment(ec)) {
    const std::string name = it->path().filename().string();
    if (name.rfind(kTempPrefix, 0) != 0 || !it->is_directory(ec)) continue;
    // kTempPrefix + HOST + "-" + PID + "-" + six characters of mkdtemp.
    const std::size_t last = name.rfind('-');
    const std::size_t before =
        last == std::string::npos || last == 0 ? std::string::npos : name.rfind('-', last - 1);
    if (before == std::string::npos || before < kTempPrefix.size()) continue;
    if (name.compare(kTempPrefix.size(), before - kTempPrefix.size(), host) != 0) continue;
    const std::string digits = name.substr(before + 1, last - before - 1);
    if (digits.empty() || digits.size() > 9 ||
        digits.find_first_not_of("0123456789") != std::string::npos)
      continue;
    const pid_t pid = static_cast<pid_t>(std::stol(digits));
    if (pid <= 0 || pid == ::getpid() || ::kill(pid, 0) == 0 || errno != ESRCH) continue;
    if (const auto moved = io::recoverKilledCommit(it->path())) {
      removed.push_back(name + " (its " + std::to_string(*moved) + " files moved into place)");
      continue;
    }
    std::error_code removeError;
    fs::remove_all(it->path(), removeError);
    if (!removeError) removed.push_back(name);
  }
  return removed;
}

AtomicOutput::AtomicOutput(const std::string& finalPath) : finalPath_(finalPath) {
  const fs::path target(finalPath);
  if (target.filename().empty()) throwFileError(finalPath, "output path names no file");
  fs::path folder = target.parent_path();
  if (folder.empty()) folder = ".";
  std::error_code ec;
  if (!fs::is_directory(folder, ec)) throwFileError(finalPath, "output folder does not exist");
  if (fs::is_directory(target, ec)) throwFileError(finalPath, "output path is a folder");
  tempDir_ = makeTemporaryFolder(folder.string(), finalPath);
  tempPath_ = (fs::path(tempDir_) / target.filename()).string();
}

AtomicOutput::~AtomicOutput() {
  std::error_code ec;
  if (!tempDir_.empty()) fs::remove_all(tempDir_, ec);
}

void AtomicOutput::commit() {
  if (committed_) return;
  // An interrupted run never publishes: the destructor removes what was written.
  throwIfInterrupted();
  move();
}

void commitTogether(const std::vector<AtomicOutput*>& outputs) {
  throwIfInterrupted();
  std::vector<std::string> folders;
  std::vector<CommitStep> steps;
  std::string target;  // named by an error writing the journal: the first output's
  for (AtomicOutput* o : outputs)
    if (o && !o->committed_) {
      if (target.empty()) target = o->finalPath_;
      folders.push_back(o->tempDir_);
      const std::vector<CommitStep> own = o->steps();
      steps.insert(steps.end(), own.begin(), own.end());
    }
  if (steps.empty()) return;
  commitFiles(folders, steps, target);
  for (AtomicOutput* o : outputs)
    if (o) o->committed_ = true;
}

std::vector<CommitStep> AtomicOutput::steps() const {
  const fs::path folder = fs::path(finalPath_).parent_path().empty()
                              ? fs::path(".")
                              : fs::path(finalPath_).parent_path();
  std::error_code ec;
  // The main file goes last, so a reader that sees it also sees its companions.
  std::vector<fs::path> files;
  for (const auto& entry : fs::directory_iterator(tempDir_, ec))
    if (entry.path() != fs::path(tempPath_)) files.push_back(entry.path());
  if (fs::exists(tempPath_, ec)) files.push_back(tempPath_);
  if (files.empty()) throwFileError(finalPath_, "nothing was written");
  std::vector<CommitStep> steps;
  for (const fs::path& f : files) steps.push_back({f.string(), (folder / f.filename()).string()});
  return steps;
}

void AtomicOutput::move() {
  commitFiles({tempDir_}, steps(), finalPath_);
  committed_ = true;
}

void writeTextFileAtomically(const std::string& path, const std::string& text) {
  AtomicOutput out(path);
  {
    std::ofstream f(out.tempPath(), std::ios::binary);
    f << text;
    if (!f.flush()) throwFileError(path, "cannot write");
  }
  out.commit();
}

void refuseOverwritingInput(const std::string& input, const std::string& output) {
  std::error_code ec;
  if (fs::exists(output, ec) && fs::equivalent(input, output, ec))
    throwFileError(output, "output would overwrite the input file");
}

}  // namespace repose
