// What every fuzz target shares: a private folder for the files a reader opens (readers take
// paths, as the command line and the GUI call them), and the one rule of the harness: a reader
// may reject its input only by throwing repose::Error. Anything else (another exception, a
// crash, a sanitizer report, a hang, an allocation past libFuzzer's limit) is a finding.
#pragma once

#include "repose/io/VolumeIO.h"
#include "repose/util/Error.h"

#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <string>
#include <unistd.h>

namespace repose::fuzz {

// Volumes are read as the command line reads them, under a memory budget (--memory, never unset
// there): a header claiming 300 GB is then refused from the header. Without one a reader is told
// to allocate what the file claims, which teem does (a FuzzSegNrrd campaign finding). 1 GB stays
// under libFuzzer's 2 GB malloc limit.
inline ReadOptions readOptions() {
  ReadOptions options;
  options.memoryLimitBytes = 1e9;
  return options;
}

// A folder of this process (removed at exit), made once.
inline const std::filesystem::path& workFolder() {
  static const std::filesystem::path folder = [] {
    std::string pattern = (std::filesystem::temp_directory_path() / "repose-fuzz-XXXXXX").string();
    if (!mkdtemp(pattern.data())) std::abort();
    std::atexit([] { std::filesystem::remove_all(workFolder()); });
    return std::filesystem::path(pattern);
  }();
  return folder;
}

// Writes the input to `name` inside the work folder; returns its path.
inline std::string writeInput(const std::string& name, const std::uint8_t* data, std::size_t size) {
  const std::filesystem::path path = workFolder() / name;
  std::filesystem::create_directories(path.parent_path());
  std::ofstream out(path, std::ios::binary | std::ios::trunc);
  out.write(reinterpret_cast<const char*>(data), static_cast<std::streamsize>(size));
  if (!out) std::abort();  // the harness itself failed, not the reader
  return path.string();
}

// gzip-compressed inputs keep a .gz name, so the reader takes its decompressing path.
inline bool isGzip(const std::uint8_t* data, std::size_t size) {
  return size >= 2 && data[0] == 0x1f && data[1] == 0x8b;
}

}  // namespace repose::fuzz
