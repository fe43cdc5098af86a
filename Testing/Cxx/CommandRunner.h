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

struct CommandResult {
  int exitCode = -1;
  std::string out, err;
};

inline std::string shellQuote(const std::string& s) {
  std::string q = "'";
  for (char c : s) q += c == '\'' ? std::string("'\\''") : std::string(1, c);
  return q + "'";
}

// `args` is appended verbatim (quote paths with shellQuote).
inline CommandResult runCommand(const std::string& exe, const std::string& args) {
  ScratchDir io("run");  // its own folder: the calling test's ScratchDir must survive
  const std::string outFile = io.file("stdout"), errFile = io.file("stderr");
  const std::string cmd = shellQuote(binPath(exe)) + " " + args + " >" + shellQuote(outFile) +
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
  return r;
}

inline int lineCount(const std::string& s) {
  int n = 0;
  for (char c : s) n += c == '\n';
  return n + (!s.empty() && s.back() != '\n');
}

}  // namespace repose::test
