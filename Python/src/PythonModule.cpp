// The `repose._repose` extension: exceptions with the command line's messages, the progress
// bridge, and the submodules' bindings. The Pythonic surface (nibabel helpers, __version__) is in
// Python/repose/__init__.py.
#include "PythonCommon.h"

#include "repose/util/Error.h"

namespace repose::python {

ProgressFn PythonProgress::fn() {
  if (callback_.is_none()) {
    // No callback: still let Ctrl+C stop the work.
    return [this](double, const std::string&) {
      py::gil_scoped_acquire gil;
      if (PyErr_CheckSignals() != 0) {
        error_ = std::make_shared<py::error_already_set>();
        return false;
      }
      return true;
    };
  }
  return [this](double fraction, const std::string& stage) {
    py::gil_scoped_acquire gil;
    if (error_) return false;
    try {
      if (PyErr_CheckSignals() != 0) throw py::error_already_set();
      const py::object go = callback_(fraction, stage);
      return go.is_none() || go.cast<bool>();
    } catch (py::error_already_set& e) {
      error_ = std::make_shared<py::error_already_set>(std::move(e));
      return false;
    }
  };
}

void PythonProgress::rethrow() {
  if (error_) {
    const std::shared_ptr<py::error_already_set> e = std::move(error_);
    throw py::error_already_set(*e);
  }
}

}  // namespace repose::python

PYBIND11_MODULE(_repose, m) {
  namespace py = pybind11;
  using namespace repose::python;
  m.doc() = "Repose: re-pose segmented whole-body volumes with a cage (C++ core bindings).";
  m.attr("__version__") = REPOSE_VERSION;

  // repose::Error -> repose.Error (a RuntimeError: the CLI's one-line message), Cancelled ->
  // repose.Cancelled (a subclass, so `except repose.Error` catches both).
  static py::exception<repose::Error> error(m, "Error", PyExc_RuntimeError);
  static py::exception<repose::Cancelled> cancelled(m, "Cancelled", error.ptr());
  py::register_exception_translator([](std::exception_ptr p) {
    try {
      if (p) std::rethrow_exception(p);
    } catch (const repose::Cancelled& e) {
      cancelled(e.what());
    } catch (const repose::Error& e) {
      error(e.what());
    }
  });
  bindVolumes(m);
  bindRigs(m);
  bindPoses(m);
  bindLive(m);
  bindDosimetry(m);
}
