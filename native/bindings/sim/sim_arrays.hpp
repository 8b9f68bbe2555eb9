// numpy <-> the simulation's inputs and report, shared by the 3-axis and 5-axis bindings.
#pragma once

#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>

#include <cstdint>
#include <sstream>
#include <stdexcept>
#include <string>
#include <vector>

#include "tmm/sim/sim_report.hpp"

namespace tmm_bindings {

using Rows = pybind11::array_t<double, pybind11::array::c_style | pybind11::array::forcecast>;

// An (n, 3) array of points or directions named `what` in the message.
inline void check_rows(const Rows& a, const char* what) {
  if (a.ndim() != 2 || a.shape(1) != 3) {
    std::ostringstream msg;
    msg << what << " must have shape (n, 3), got ndim " << a.ndim();
    if (a.ndim() == 2) msg << " and " << a.shape(1) << " columns";
    throw std::invalid_argument(msg.str());
  }
}

// An (n - 1,) integer array of move kinds, checked before any narrowing cast (a 256 must not become 0).
inline std::vector<tmm::MoveKind> kinds_from(const pybind11::handle& obj, std::size_t moves) {
  namespace py = pybind11;
  const py::array a = py::array::ensure(obj);
  if (!a) throw py::type_error("kinds must be an (n - 1,) integer array of move kinds");
  const char kind = a.dtype().kind();
  if (kind != 'i' && kind != 'u')
    throw py::type_error("kinds must be an integer array (0 cut, 1 rapid, 2 jump), got dtype " +
                         std::string(py::str(a.dtype())));
  if (a.ndim() != 1 || static_cast<std::size_t>(a.shape(0)) != moves) {
    std::ostringstream msg;
    msg << "kinds must have shape (n - 1,) = (" << moves << ",), one per move, got ";
    if (a.ndim() == 1) msg << "(" << a.shape(0) << ",)";
    else msg << "ndim " << a.ndim();
    throw std::invalid_argument(msg.str());
  }
  std::vector<tmm::MoveKind> out(moves);
  const auto put = [&](auto typed) {
    const auto r = typed.template unchecked<1>();
    for (py::ssize_t k = 0; k < r.shape(0); ++k) {
      const auto v = r(k);
      if (v < 0 || v > 2) {
        std::ostringstream msg;
        msg << "kind of move " << k << " is " << v << ": not a move kind (0 cut, 1 rapid, 2 jump)";
        throw std::invalid_argument(msg.str());
      }
      out[static_cast<std::size_t>(k)] = static_cast<tmm::MoveKind>(v);
    }
  };
  if (kind == 'u') put(py::array_t<std::uint64_t, py::array::forcecast>(a));
  else put(py::array_t<std::int64_t, py::array::forcecast>(a));
  return out;
}

// {"moves_cut", "cells_lowered", "collisions": (k, 2) float64 [move index, depth]}.
inline pybind11::dict report_dict(const tmm::SimReport& report) {
  namespace py = pybind11;
  py::array_t<double> collisions({static_cast<py::ssize_t>(report.collisions.size()), py::ssize_t{2}});
  auto c = collisions.mutable_unchecked<2>();
  for (std::size_t i = 0; i < report.collisions.size(); ++i) {
    c(static_cast<py::ssize_t>(i), 0) = static_cast<double>(report.collisions[i].move);
    c(static_cast<py::ssize_t>(i), 1) = report.collisions[i].depth;
  }
  py::dict out;
  out["moves_cut"] = report.moves_cut;
  out["cells_lowered"] = report.cells_lowered;
  out["collisions"] = collisions;
  return out;
}

}  // namespace tmm_bindings
