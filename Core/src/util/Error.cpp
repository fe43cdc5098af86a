// One-line file errors: "path: problem".
#include "repose/util/Error.h"
#include "repose/util/Interrupt.h"
#include "repose/util/Progress.h"

namespace repose {

void throwFileError(const std::string& path, const std::string& problem) {
  std::string line = path + ": " + problem;
  for (char& c : line)
    if (c == '\n' || c == '\r') c = ' ';
  throw Error(line);
}

void reportProgress(const ProgressFn& fn, double fraction, const std::string& stage) {
  throwIfInterrupted();
  if (fn && !fn(fraction, stage)) throw Cancelled();
}

}  // namespace repose
