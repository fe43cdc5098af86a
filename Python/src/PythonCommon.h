// Shared by the binding's translation units: how a Python progress callback becomes a Core
// ProgressFn (called with the GIL taken; returning False or raising stops the work, which Core
// turns into repose::Cancelled), and how long calls give the GIL back.
#pragma once

#include <pybind11/pybind11.h>

#include "repose/util/Error.h"
#include "repose/util/Progress.h"
#include "repose/volume/Volume.h"

#include <memory>

namespace repose::python {

namespace py = pybind11;

// The callback is `progress(fraction: float, stage: str) -> bool | None`; None counts as "go on".
// A Python exception raised in it (KeyboardInterrupt included) stops the work and is raised again
// from the call, so Ctrl+C in a script cancels cleanly. Pending signals are checked on each call.
class PythonProgress {
 public:
  explicit PythonProgress(py::object callback) : callback_(std::move(callback)) {}
  ProgressFn fn();
  // After the call: raises the exception the callback raised, if any.
  void rethrow();

 private:
  py::object callback_;
  std::shared_ptr<py::error_already_set> error_;
};

// Runs `work` with the GIL released and the callback bridged; a cancellation raised by the
// callback (or Ctrl+C) comes back as that Python exception, else as repose.Cancelled.
template <class F>
auto withProgress(const py::object& progress, F&& work) {
  PythonProgress p(progress);
  try {
    py::gil_scoped_release release;
    return work(p.fn());
  } catch (const Cancelled&) {
    p.rethrow();
    throw;
  }
}

// The Volume a rig's or session's `organs` argument holds, its type checked with a message that
// names the argument (pybind's cast error would not say which argument it was).
const Volume& organsVolume(const py::object& organs);

void bindVolumes(py::module_& m);
void bindPoses(py::module_& m);
void bindRigs(py::module_& m);
void bindLive(py::module_& m);
void bindDosimetry(py::module_& m);

}  // namespace repose::python
