// Python binding of the 5-axis cutting simulation (tmm/sim/sweep5.hpp) on the bound ZMap stock.
#include <pybind11/functional.h>
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>

#include <cmath>
#include <cstdint>
#include <sstream>
#include <stdexcept>
#include <string>
#include <vector>

#include "tmm/sim/sweep5.hpp"
#include "sim/sim_arrays.hpp"
#include "util/arrays.hpp"
#include "util/progress.hpp"

namespace py = pybind11;
using tmm_bindings::python_progress;

namespace {

using tmm_bindings::check_rows;
using tmm_bindings::kinds_from;
using tmm_bindings::report_dict;
using tmm_bindings::Rows;

tmm::TorusTool tool_from(double Ro, double Ri, const std::string& shape) {
  tmm::TorusTool t;
  t.Ro = Ro;
  t.Ri = Ri;
  if (shape == "round_insert") t.shape = tmm::ToolShape::RoundInsert;
  else if (shape == "bull_nose") t.shape = tmm::ToolShape::BullNose;
  else throw std::invalid_argument("tool_shape must be 'round_insert' or 'bull_nose', got '" + shape + "'");
  t.validate_solid();
  return t;
}

py::dict cut_5axis(tmm::ZMap& stock, double Ro, double Ri, const std::string& shape, const Rows& tips,
                   const Rows& axes, const py::handle& kinds, double max_step, double collision_tol, int threads,
                   const py::object& progress, const py::object& bodies, double body_tol) {
  const tmm::TorusTool tool = tool_from(Ro, Ri, shape);
  check_rows(tips, "tips");
  check_rows(axes, "axes");
  const std::size_t n = static_cast<std::size_t>(tips.shape(0));
  if (static_cast<std::size_t>(axes.shape(0)) != n) {
    std::ostringstream msg;
    msg << "axes must have as many rows as tips (" << n << "), got " << axes.shape(0);
    throw std::invalid_argument(msg.str());
  }
  const std::vector<tmm::MoveKind> k = kinds_from(kinds, n > 0 ? n - 1 : 0);
  tmm::Sweep5Options options;
  options.max_step = max_step;
  options.collision_tol = collision_tol;
  tmm::BodyCheck check;
  if (tmm_bindings::body_check_from(bodies, 0.0, body_tol, 0.0, check)) options.body_check = &check;
  tmm::BatchOptions batch;
  batch.threads = threads;
  batch.progress = python_progress(progress);
  tmm::SimReport report;
  tmm::Sweep5Stats stats;
  {
    py::gil_scoped_release release;
    report = tmm::cut_5axis(stock, tool, tips.data(), axes.data(), k.data(), n, options, batch, &stats);
  }
  py::dict out = report_dict(report, options.body_check != nullptr);
  out["instances"] = stats.instances;
  out["cells_tested"] = stats.cells_tested;
  out["exact_solves"] = stats.exact_solves;
  out["fallback_solves"] = stats.fallback_solves;
  out["lowerings"] = stats.lowerings;
  return out;
}

Eigen::Vector3d vec3(const Rows& a, const char* what) {
  if (a.size() != 3) throw std::invalid_argument(std::string(what) + " must have 3 components");
  const double* d = a.data();
  return {d[0], d[1], d[2]};
}

}  // namespace

void bind_sim5(py::module_& m) {
  m.def("cut_5axis", &cut_5axis, py::arg("stock"), py::arg("tool_Ro"), py::arg("tool_Ri"), py::arg("tool_shape"),
        py::arg("tips"), py::arg("axes"), py::arg("kinds"), py::arg("max_step") = 0.05,
        py::arg("collision_tol") = 1e-3, py::arg("threads") = 0, py::arg("progress") = py::none(),
        py::arg("bodies") = py::none(), py::arg("body_tol") = 1e-3,
        "Cuts a 5-axis tool path into the ZMap stock with the toroidal tool (Ro, Ri, 'round_insert' | "
        "'bull_nose'): tips, axes (n, 3) (axes tip -> spindle, normalised, a_z > 0), kinds (n - 1,) integers "
        "(0 cut, 1 rapid, 2 jump) for the moves k -> k + 1. Tip linear, axis by slerp, sub-stepped so that no "
        "torus point moves more than max_step between instances; each cell is lowered to the tool's lowest "
        "point on its vertical line. A rapid removing more than collision_tol mm is a collision. "
        "progress(fraction) -> bool; False cancels (raises Cancelled, the stock partly cut). Returns "
        "{'moves_cut', 'cells_lowered', 'collisions': (k, 2) [move index, depth], 'instances', "
        "'cells_tested', 'exact_solves', 'fallback_solves'; with bodies 'body_collisions': (m, 6) [move, piece, x, y, z, depth]}. "
        "bodies: None, or (k, 5) rows (z0, z1, r0, r1, clearance) of the tool above the flutes, checked at each "
        "instance against the stock before it is stamped (enclosing frusta, tmm/sim/body_check.hpp).");
  m.def("lowest_on_vertical",
        [](double Ro, double Ri, const std::string& shape, const Rows& tip, const Rows& axis, double x, double y) {
          const tmm::TorusTool tool = tool_from(Ro, Ri, shape);
          tmm_bindings::check_range(tip, "tip");
          tmm::require_in_range(x, "x");
          tmm::require_in_range(y, "y");
          Eigen::Vector3d a = vec3(axis, "axis");
          const double len = a.norm();
          if (!(len > 0.0 && std::isfinite(len))) throw std::invalid_argument("axis must be a finite nonzero vector");
          a /= len;
          if (!(a.z() > 1e-6)) throw std::invalid_argument("axis must point upwards (a_z > 0)");
          return tmm::lowest_on_vertical(tool, vec3(tip, "tip"), a, x, y);
        },
        py::arg("tool_Ro"), py::arg("tool_Ri"), py::arg("tool_shape"), py::arg("tip"), py::arg("axis"),
        py::arg("x"), py::arg("y"),
        "Lowest z of the tool solid at (tip, axis) on the vertical line through (x, y); inf if it misses.");
}
