// Python progress callback -> kernel progress function, shared by every batch binding.
#pragma once

#include <pybind11/pybind11.h>

#include <functional>
#include <memory>

namespace tmm_bindings {

// The kernel calls this from the calling thread with the GIL released (tmm::parallel_chunks' reporter,
// every 20 ms): take it for the call. A return of False (None counts as "go on") cancels; a Python exception
// raised in the callback propagates and cancels. Pending signals are checked at each call, with or without
// a callback, so that Ctrl-C (KeyboardInterrupt) stops a long kernel call within a report or two: Python
// runs its signal handlers only between bytecodes of the main thread, never while the kernel holds it.
// The callback is held by a shared_ptr: the kernel copies the function with the GIL released, and a copy
// must not touch the object's reference count; the last owner (the binding's, after the kernel returns)
// drops it with the GIL.
inline std::function<bool(double)> python_progress(const pybind11::object& callback) {
  namespace py = pybind11;
  std::shared_ptr<py::object> held(new py::object(callback), [](py::object* o) {
    py::gil_scoped_acquire gil;
    delete o;
  });
  return [held](double fraction) {
    py::gil_scoped_acquire gil;
    if (PyErr_CheckSignals() != 0) throw py::error_already_set();
    if (held->is_none()) return true;
    py::object r = (*held)(fraction);
    return r.is_none() || r.cast<bool>();
  };
}

}  // namespace tmm_bindings
