// Python progress callback -> kernel progress function, shared by every batch binding.
#pragma once

#include <pybind11/pybind11.h>

#include <functional>

namespace tmm_bindings {

// The kernel calls this from a worker with the GIL released: take it for the call. A return of False
// (None counts as "go on") cancels; a Python exception raised in the callback propagates and cancels.
inline std::function<bool(double)> python_progress(const pybind11::object& callback) {
  if (callback.is_none()) return {};
  return [callback](double fraction) {
    pybind11::gil_scoped_acquire gil;
    pybind11::object r = callback(fraction);
    return r.is_none() || r.cast<bool>();
  };
}

}  // namespace tmm_bindings
