// Progress reporting and cancellation for long Core work (readers, phantom generation, ...).
// A callback gets a fraction in [0,1] and a short stage name; returning false asks to stop.
#pragma once

#include <functional>
#include <string>

namespace repose {

using ProgressFn = std::function<bool(double fraction, const std::string& stage)>;

// Calls fn if set; throws repose::Cancelled when it returns false or an interrupt was requested
// (util/Interrupt.h), so every progress point is also a stop point.
void reportProgress(const ProgressFn& fn, double fraction, const std::string& stage);

}  // namespace repose
