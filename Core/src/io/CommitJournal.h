// The journal that makes a commit of several files all-or-nothing under SIGKILL (see commitFiles
// in repose/io/AtomicOutput.h). The first temporary folder of a commit holds the journal: its
// steps and every temporary folder taking part. Written atomically before the first step, it is
// the commit's decision: a run killed before it leaves the old files, one killed after it is
// finished by the next output into the folder (recoverKilledCommit). The other temporary folders
// name the first in a member file, so whichever folder is found first decides the same way.
#pragma once

#include <cstddef>
#include <filesystem>
#include <optional>

namespace repose::io {

// For a stale temporary folder of a killed run: when it belongs to a commit whose journal was
// written, finishes that commit (the steps not yet done, each done once) and removes every
// temporary folder of it; returns the number of files it moved into place. Nothing (and nothing
// done) when the folder holds no decided commit: the caller removes it as a plain leftover.
std::optional<std::size_t> recoverKilledCommit(const std::filesystem::path& temporaryFolder);

}  // namespace repose::io
