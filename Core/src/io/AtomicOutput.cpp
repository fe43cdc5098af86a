// Temporary folder beside the target, renamed into place on commit; see AtomicOutput.h.
#include "repose/io/AtomicOutput.h"

#include <fstream>

#include "repose/util/Error.h"
#include "repose/util/Interrupt.h"

#include <unistd.h>

#include <cerrno>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <vector>

namespace fs = std::filesystem;

namespace repose {

AtomicOutput::AtomicOutput(const std::string& finalPath) : finalPath_(finalPath) {
  const fs::path target(finalPath);
  if (target.filename().empty()) throwFileError(finalPath, "output path names no file");
  fs::path folder = target.parent_path();
  if (folder.empty()) folder = ".";
  std::error_code ec;
  if (!fs::is_directory(folder, ec)) throwFileError(finalPath, "output folder does not exist");
  if (fs::is_directory(target, ec)) throwFileError(finalPath, "output path is a folder");
  std::string pattern = (folder / ".repose-tmp-XXXXXX").string();
  std::vector<char> buf(pattern.begin(), pattern.end());
  buf.push_back('\0');
  if (!::mkdtemp(buf.data()))
    throwFileError(finalPath,
                   std::string("cannot write in the output folder: ") + std::strerror(errno));
  tempDir_ = buf.data();
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
  for (AtomicOutput* o : outputs)
    if (o && !o->committed_) o->move();
}

void AtomicOutput::move() {
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
  for (const fs::path& f : files) {
    fs::rename(f, folder / f.filename(), ec);
    if (ec) throwFileError(finalPath_, "cannot move the output into place: " + ec.message());
  }
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
