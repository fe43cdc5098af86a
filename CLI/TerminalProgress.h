// Progress shown on a terminal: a single self-rewriting line on stderr when stderr is a TTY,
// nothing otherwise (so --json output and logs stay clean). Run as a 3D Slicer CLI module, the
// same progress goes to stdout as the lines Slicer's progress bar reads instead.
#pragma once

#include "repose/util/Progress.h"

#include <string>

namespace repose::cli {

// A ProgressFn that draws "stage  [=====>    ]  42%" and ends the line when done; in Slicer
// mode, "<filter-comment>stage</filter-comment>" when the stage changes and
// "<filter-progress>0.42</filter-progress>", each flushed.
ProgressFn terminalProgress();

// Slicer mode from now on (vtkSlicerCLIModuleLogic.cxx parses stdout; the format is that of
// Slicer's itkPluginFilterWatcher.h): prints <filter-start> with the filter's name.
void startSlicerProgress(const std::string& filterName, const std::string& comment);
// Prints <filter-end> (Slicer mode only).
void endSlicerProgress(const std::string& filterName);

}  // namespace repose::cli
