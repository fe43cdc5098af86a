#include "TerminalProgress.h"

#include <unistd.h>

#include <cstdio>
#include <memory>

namespace repose::cli {

ProgressFn terminalProgress() {
  if (!isatty(STDERR_FILENO)) return {};
  struct State {
    int lastPercent = -1;
    std::string lastStage;
  };
  auto state = std::make_shared<State>();
  return [state](double fraction, const std::string& stage) {
    const int percent = static_cast<int>(fraction * 100.0 + 0.5);
    if (percent == state->lastPercent && stage == state->lastStage) return true;
    state->lastPercent = percent;
    state->lastStage = stage;
    const int width = 30, filled = percent * width / 100;
    std::string bar(filled, '=');
    bar.resize(width, ' ');
    std::fprintf(stderr, "\r%-24.24s [%s] %3d%%", stage.c_str(), bar.c_str(), percent);
    if (percent >= 100) std::fputc('\n', stderr);
    std::fflush(stderr);
    return true;
  };
}

}  // namespace repose::cli
