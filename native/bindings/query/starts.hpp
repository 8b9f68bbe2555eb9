// The start points and tool axes of the drops along a direction (bind_direction.cpp, bind_drop_assembly.cpp):
// shapes checked with a message naming them.
#pragma once

#include <pybind11/numpy.h>

#include <cmath>
#include <cstddef>
#include <sstream>
#include <stdexcept>

namespace tmm_bindings {

// starts (n, 3); axes (3,) or (n, 3); max_travel not NaN. Returns whether there is an axis per start.
template <class A>
bool check_starts_and_axes(const A& starts, const A& axes, double max_travel) {
  if (starts.ndim() != 2 || starts.shape(1) != 3) {
    std::ostringstream msg;
    msg << "start points must have shape (n, 3), got ndim " << starts.ndim();
    if (starts.ndim() == 2) msg << " and " << starts.shape(1) << " columns";
    throw std::invalid_argument(msg.str());
  }
  const bool per_point = axes.ndim() == 2;
  if (per_point ? (axes.shape(0) != starts.shape(0) || axes.shape(1) != 3) : axes.size() != 3)
    throw std::invalid_argument("axes must have shape (3,) or (n, 3) like the start points");
  if (std::isnan(max_travel)) throw std::invalid_argument("max_travel must not be NaN");
  return per_point;
}

}  // namespace tmm_bindings
