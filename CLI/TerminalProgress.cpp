#include "TerminalProgress.h"

#include <unistd.h>

#include <cstdio>
#include <memory>

namespace repose::cli {
namespace {

bool slicerMode = false;

ProgressFn slicerProgress() {
  struct State {
    int lastPermille = -1;
    std::string lastStage;
  };
  auto state = std::make_shared<State>();
  return [state](double fraction, const std::string& stage) {
    const int permille = static_cast<int>(fraction * 1000.0 + 0.5);
    if (permille == state->lastPermille && stage == state->lastStage) return true;
    if (stage != state->lastStage)
      std::printf("<filter-comment>%s</filter-comment>\n", stage.c_str());
    state->lastPermille = permille;
    state->lastStage = stage;
    std::printf("<filter-progress>%.3f</filter-progress>\n", permille / 1000.0);
    std::fflush(stdout);
    return true;
  };
}

}  // namespace

ProgressFn terminalProgress() {
  if (slicerMode) return slicerProgress();
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

void startSlicerProgress(const std::string& filterName, const std::string& comment) {
  slicerMode = true;
  std::printf(
      "<filter-start>\n<filter-name>%s</filter-name>\n<filter-comment>%s</filter-comment>\n"
      "</filter-start>\n",
      filterName.c_str(), comment.c_str());
  std::fflush(stdout);
}

void endSlicerProgress(const std::string& filterName) {
  if (!slicerMode) return;
  std::printf("<filter-end>\n<filter-name>%s</filter-name>\n</filter-end>\n", filterName.c_str());
  std::fflush(stdout);
}

}  // namespace repose::cli
