// Shared by the binding's translation units: how a Python progress callback becomes a Core
// ProgressFn (called with the GIL taken; returning False or raising stops the work, which Core
// turns into repose::Cancelled), and how long calls give the GIL back.
#pragma once

#include <pybind11/pybind11.h>

#include "repose/util/Progress.h"

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

void bindVolumes(py::module_& m);
void bindPoses(py::module_& m);
void bindRigs(py::module_& m);
void bindDosimetry(py::module_& m);

}  // namespace repose::python
