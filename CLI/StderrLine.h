// One line on stderr, written by one write(2). std::cerr is unbuffered, so `cerr << a << b`
// issues a write per piece; under mpirun every rank's stderr is forwarded through one pipe and
// another process's message can land between the pieces ("repose " ... "pose: error: ...").
// A line written at once arrives whole, so scripts (and the tests) can find "repose <command>:".
#pragma once

#include <string>

namespace repose::cli {

// Writes `line` and a newline to stderr in one call; retries what a signal interrupts.
void stderrLine(const std::string& line);

}  // namespace repose::cli
