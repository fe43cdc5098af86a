#include "NrrdLoad.h"

#include <cerrno>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>

// teem's consistency check as its reader runs it (checkData off: skipData leaves no voxels). It
// is exported by libteem but declared in its private header only.
extern "C" int _nrrdCheck(const Nrrd* nrrd, int checkData, int useBiff);

namespace repose::io {

int loadNrrd(Nrrd* nrrd, const std::string& path, NrrdIoState* nio) {
  // The folder a detached header's data file names are relative to (teem's _nrrdSplitName).
  const std::filesystem::path parent = std::filesystem::path(path).parent_path();
  std::free(nio->path);
  nio->path = strdup(parent.empty() ? "." : parent.c_str());
  std::FILE* file = std::fopen(path.c_str(), "rb");
  if (!file) {
    biffAddf(NRRD, "loadNrrd: fopen(\"%s\",\"rb\") failed: %s", path.c_str(), std::strerror(errno));
    return 1;
  }
  // The magic line, read as teem reads a line (it ends at "\n", "\r" or "\r\n"), into the line
  // buffer teem's format reader starts from; teem grows and frees that buffer itself.
  constexpr unsigned kLine = 64;
  std::free(nio->line);
  nio->line = static_cast<char*>(std::calloc(kLine, 1));
  nio->lineLen = kLine;
  unsigned n = 0;
  for (int c = std::fgetc(file); c != EOF; c = std::fgetc(file)) {
    if (c == '\r') {
      const int next = std::fgetc(file);
      if (next != '\n' && next != EOF) std::ungetc(next, file);
      break;
    }
    if (c == '\n') break;
    if (n + 1 < kLine) nio->line[n++] = char(c);
  }
  nio->format = nrrdFormatNRRD;
  nio->headerStringRead = nullptr;
  bool read = nrrdFormatNRRD->contentStartsLike(nio) && nrrdFormatNRRD->read(file, nrrd, nio) == 0;
  if (read && _nrrdCheck(nrrd, AIR_FALSE, AIR_TRUE) != 0) {
    // A detached data file teem kept open for the caller is not handed over on failure.
    if (nio->keepNrrdDataFileOpen && nio->dataFile && nio->dataFile != file)
      std::fclose(nio->dataFile);
    nio->dataFile = nullptr;
    read = false;
  }
  if (!read) {
    biffAddf(NRRD, "loadNrrd: trouble reading \"%s\"", path.c_str());
    // teem closed a detached data file it opened; the header file (also the data file of an
    // attached header) is ours to close.
    if (nio->dataFile == file) nio->dataFile = nullptr;
    std::fclose(file);
    return 1;
  }
  // As nrrdLoad: an attached header's file stays open when it is the data file to keep.
  if (!(nio->keepNrrdDataFileOpen && nio->dataFile == file)) std::fclose(file);
  return 0;
}

}  // namespace repose::io
