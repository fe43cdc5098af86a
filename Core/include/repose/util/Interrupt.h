// A process-wide stop request: the command line's SIGINT/SIGTERM handler sets it, and Core
// honours it at every progress point (reportProgress) and before an output is moved into place
// (AtomicOutput::commit), so an interrupted run unwinds like a cancelled one: no partial output.
#pragma once

namespace repose {

// Async-signal-safe: records the signal number (the first one wins).
void requestInterrupt(int signal) noexcept;
// The signal that asked to stop, or 0.
int interruptSignal() noexcept;
// Throws repose::Cancelled when an interrupt was requested.
void throwIfInterrupted();

}  // namespace repose
