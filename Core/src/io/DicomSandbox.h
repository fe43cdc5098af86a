// GDCM, as Debian builds it, keeps its assert()s: a corrupt file can abort the whole process
// inside the library (found by Testing/Fuzz/FuzzDicom, in its parser and its scanner), which no
// exception handler can catch and which would take the user's session with it. Some corrupt files
// instead keep GDCM busy for many seconds (a 16.8 KB file took 8 s: a libFuzzer time-out). So
// every file of a series is first read by GDCM in a child process, exactly as the real read will
// (parse, pixel decoding), under a time limit per file; when the child dies or overruns, the file
// it was reading is refused with a one-line error.
#pragma once

#include <functional>
#include <string>
#include <vector>

namespace repose::io {

// How long the child may spend on one file, and how much memory it may take: each a fixed
// allowance plus one for the file's size (the largest file's, for memory). The defaults are far
// above what GDCM needs for a valid file (JPEG 2000 CT slices decode at about 3 MB of file a
// second here, with both cores busy; decoded pixels are rarely 10 times the file), and for the
// small inputs of the fuzz targets the time is below libFuzzer's 10 s time-out. A corrupt 4.7 KB
// file made GDCM allocate and zero-fill 1.3 GB.
struct DicomProbeLimits {
  double secondsPerFile = 5.0;
  double bytesPerSecond = 1e6;
  double memoryBytes = 512e6;
  double memoryPerFileByte = 64;
};

// Throws repose::Error naming the file on which GDCM crashed in the child, did not finish within
// the time limit, or needed more memory than allowed. Parse errors are not reported here (the real
// read reports them); if no child can be started the check is skipped.
void probeDicomFilesInChild(const std::vector<std::string>& files,
                            const DicomProbeLimits& limits = {});

// The same, with what the child does to each file given (tests: a reader that never returns or
// that crashes). `readInChild` runs only in the child.
void probeFilesInChild(const std::vector<std::string>& files, const DicomProbeLimits& limits,
                       const std::function<void(const std::string&)>& readInChild);

}  // namespace repose::io
