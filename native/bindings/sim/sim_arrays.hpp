// numpy <-> the simulation's inputs and report, shared by the 3-axis and 5-axis bindings.
#pragma once

#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>

#include <cstdint>
#include <sstream>
#include <stdexcept>
#include <string>
#include <vector>

#include "tmm/sim/body_check.hpp"
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

// The body check from Python: bodies None (no check) or a (k, 5) array of (z0, z1, r0, r1, clearance) rows;
// false without a check. The values are checked by the kernel (tmm::validate).
inline bool body_check_from(const pybind11::object& bodies, double flute_top, double tolerance, double step,
                            tmm::BodyCheck& out) {
  namespace py = pybind11;
  if (bodies.is_none()) return false;
  const Rows a = Rows::ensure(bodies);
  if (!a || a.ndim() != 2 || a.shape(1) != 5) {
    std::ostringstream msg;
    msg << "bodies must be None or an (k, 5) array of (z0, z1, r0, r1, clearance) rows";
    if (a) msg << ", got ndim " << a.ndim() << (a.ndim() == 2 ? " and " + std::to_string(a.shape(1)) + " columns" : "");
    throw std::invalid_argument(msg.str());
  }
  const auto r = a.unchecked<2>();
  out.bodies.clear();
  for (py::ssize_t k = 0; k < r.shape(0); ++k) out.bodies.push_back({r(k, 0), r(k, 1), r(k, 2), r(k, 3), r(k, 4)});
  out.flute_top = flute_top;
  out.tolerance = tolerance;
  out.step = step;
  return true;
}

// {"moves_cut", "cells_lowered", "collisions": (k, 2) float64 [move index, depth],
//  and with a body check "body_collisions": (m, 6) float64 [move index, piece, x, y, z, depth]}.
inline pybind11::dict report_dict(const tmm::SimReport& report, bool body_check = false) {
  namespace py = pybind11;
  py::array_t<double> collisions({static_cast<py::ssize_t>(report.collisions.size()), py::ssize_t{2}});
  auto c = collisions.mutable_unchecked<2>();
  for (std::size_t i = 0; i < report.collisions.size(); ++i) {
    c(static_cast<py::ssize_t>(i), 0) = static_cast<double>(report.collisions[i].move);
    c(static_cast<py::ssize_t>(i), 1) = report.collisions[i].depth;
  }
  const auto& bodies = report.body_collisions;
  py::array_t<double> body({static_cast<py::ssize_t>(bodies.size()), py::ssize_t{6}});
  auto b = body.mutable_unchecked<2>();
  for (std::size_t i = 0; i < bodies.size(); ++i) {
    const tmm::BodyCollision& e = bodies[i];
    const double row[6] = {static_cast<double>(e.move), static_cast<double>(e.piece), e.x, e.y, e.z, e.depth};
    for (py::ssize_t col = 0; col < 6; ++col) b(static_cast<py::ssize_t>(i), col) = row[col];
  }
  py::dict out;
  if (body_check) out["body_collisions"] = body;
  out["moves_cut"] = report.moves_cut;
  out["cells_lowered"] = report.cells_lowered;
  out["collisions"] = collisions;
  return out;
}

}  // namespace tmm_bindings
