// Progress shown on a terminal: a single self-rewriting line on stderr when stderr is a TTY,
// nothing otherwise (so --json output and logs stay clean).
#pragma once

#include "repose/util/Progress.h"

namespace repose::cli {

// A ProgressFn that draws "stage  [=====>    ]  42%" and ends the line when done.
ProgressFn terminalProgress();

}  // namespace repose::cli
