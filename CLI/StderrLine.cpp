#include "StderrLine.h"

#include <cerrno>
#include <cstdio>
#include <unistd.h>

namespace repose::cli {

void stderrLine(const std::string& line) {
  std::fflush(stderr);  // a progress bar's half-line (TerminalProgress) goes first
  const std::string whole = line + "\n";
  const char* at = whole.data();
  std::size_t left = whole.size();
  while (left > 0) {
    const ssize_t n = ::write(STDERR_FILENO, at, left);
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) return;  // stderr closed: nothing else can be said
    at += n;
    left -= std::size_t(n);
  }
}

}  // namespace repose::cli
