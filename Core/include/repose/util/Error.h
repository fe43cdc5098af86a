// repose::Error: the one exception type Core throws for bad input or failed work.
// Its message is a single line that names the file (when there is one) and the problem.
#pragma once

#include <stdexcept>
#include <string>

namespace repose {

class Error : public std::runtime_error {
 public:
  explicit Error(const std::string& message) : std::runtime_error(message) {}
};

// "path: problem", the shape every file-related error takes.
[[noreturn]] void throwFileError(const std::string& path, const std::string& problem);

// Thrown when a ProgressFn asks to stop; callers treat it as a clean cancellation.
class Cancelled : public Error {
 public:
  Cancelled() : Error("cancelled") {}
};

}  // namespace repose
