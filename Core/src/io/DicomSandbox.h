// GDCM, as Debian builds it, keeps its assert()s: a corrupt file can abort the whole process
// inside the library (found by Testing/Fuzz/FuzzDicom, in its parser and its scanner), which no
// exception handler can catch and which would take the user's session with it. So every file of
// a series is first read by GDCM in a child process, exactly as the real read will (parse, pixel
// decoding); when the child dies, the file it was reading is refused with a one-line error.
#pragma once

#include <string>
#include <vector>

namespace repose::io {

// Throws repose::Error naming the file on which GDCM crashed in the child. Parse errors are not
// reported here (the real read reports them); if no child can be started the check is skipped.
void probeDicomFilesInChild(const std::vector<std::string>& files);

}  // namespace repose::io
