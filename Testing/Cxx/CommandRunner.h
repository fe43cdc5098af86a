// Runs a built executable as a user would (through the shell) and captures its exit code,
// standard output and standard error, for CLI tests.
#pragma once

#include "TestPaths.h"

#include <sys/wait.h>

#include <cstdio>
#include <fstream>
#include <sstream>
#include <string>

namespace repose::test {

// A peak resident set means nothing under AddressSanitizer (its shadow memory and a 256 MB
// quarantine of freed blocks come on top of what the command needs): memory budgets are checked
// in the plain build; the sanitized build (make test-asan) checks everything else in those tests.
inline constexpr bool kPeakRssIsMeaningful = !kAddressSanitizer;

struct CommandResult {
  int exitCode = -1;
  std::string out, err;
  long peakRssKb = -1;  // with measureMemory
};

inline std::string shellQuote(const std::string& s) {
  std::string q = "'";
  for (char c : s) q += c == '\'' ? std::string("'\\''") : std::string(1, c);
  return q + "'";
}

// `exe`: a program of the build's bin folder, or an absolute path (a system program). `args` is
// appended verbatim (quote paths with shellQuote). With measureMemory the command runs under
// /usr/bin/time and peakRssKb receives its peak resident set.
inline CommandResult runCommand(const std::string& exe, const std::string& args,
                                bool measureMemory = false) {
  ScratchDir io("run");  // its own folder: the calling test's ScratchDir must survive
  const std::string outFile = io.file("stdout"), errFile = io.file("stderr"),
                    rssFile = io.file("rss");
  const std::string prefix =
      measureMemory ? "/usr/bin/time -f %M -o " + shellQuote(rssFile) + " " : std::string();
  const std::string program = exe.rfind('/', 0) == 0 ? exe : binPath(exe);
  const std::string cmd = prefix + shellQuote(program) + " " + args + " >" + shellQuote(outFile) +
                          " 2>" + shellQuote(errFile) + " </dev/null";
  const int status = std::system(cmd.c_str());
  CommandResult r;
  r.exitCode = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  auto slurp = [](const std::string& p) {
    std::ifstream in(p);
    std::stringstream s;
    s << in.rdbuf();
    return s.str();
  };
  r.out = slurp(outFile);
  r.err = slurp(errFile);
  if (measureMemory) {
    std::string rss = slurp(rssFile);
    const std::size_t at = rss.find_last_of("0123456789");  // the last line holds the figure
    const std::size_t from = rss.find_last_not_of("0123456789", at);
    r.peakRssKb = at == std::string::npos ? -1 : std::stol(rss.substr(from + 1, at - from));
  }
  return r;
}

inline int lineCount(const std::string& s) {
  int n = 0;
  for (char c : s) n += c == '\n';
  return n + (!s.empty() && s.back() != '\n');
}

}  // namespace repose::test
