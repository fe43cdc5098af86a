#include "InputChecks.h"
#include "StderrLine.h"

#include <iostream>

namespace repose::cli {

void warnUnnamedLabels(const Volume& volume, const std::string& path, const std::string& command) {
  const std::string line = unnamedLabelsWarning(volume, path);
  if (!line.empty()) stderrLine("repose " + command + ": warning: " + line);
}

void warnUnnamedLabels(const std::vector<int>& values, const std::string& path,
                       const std::string& command) {
  const std::string line = unnamedLabelsWarning(values, path);
  if (!line.empty()) stderrLine("repose " + command + ": warning: " + line);
}

}  // namespace repose::cli
