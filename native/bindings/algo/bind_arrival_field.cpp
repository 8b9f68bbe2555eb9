// Python binding of the 3D offset's arrival-time field: numpy arrays in and out, the GIL released.
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include <algorithm>
#include <cstdint>
#include <stdexcept>
#include <vector>

#include "tmm/algo/arrival_field.hpp"
#include "util/arrays.hpp"
#include "util/progress.hpp"

namespace py = pybind11;

namespace {

using Doubles = py::array_t<double, py::array::c_style | py::array::forcecast>;

tmm::ArrivalGrid grid_of(const Doubles& z, double cell) {
  if (z.ndim() != 2) throw std::invalid_argument("arrival field: z must be a 2-d array (ny, nx)");
  tmm::ArrivalGrid g;
  g.ny = static_cast<int>(z.shape(0));
  g.nx = static_cast<int>(z.shape(1));
  g.cell = cell;
  return g;
}

std::vector<double> values(const Doubles& a) { return std::vector<double>(a.data(), a.data() + a.size()); }

tmm::StepRuleTable rule_of(const Doubles& steps, double dslope, double radius, double probe, double min_step) {
  tmm::StepRuleTable r;
  r.steps = values(steps);
  r.dslope = dslope;
  r.radius = radius;
  r.probe = probe;
  r.min_step = min_step;
  return r;
}

}  // namespace

void bind_arrival_field(py::module_& m) {
  m.def("arrival_field",
        [](const Doubles& z, double cell, const py::array_t<std::uint8_t, py::array::c_style | py::array::forcecast>& active,
           const Doubles& start, const Doubles& steps, double dslope, double radius, double probe, double min_step,
           const py::object& progress) {
          const tmm::ArrivalGrid g = grid_of(z, cell);
          if (active.size() != z.size() || start.size() != z.size())
            throw std::invalid_argument("arrival field: active and start must have z's shape");
          const std::vector<double> zv = values(z), sv = values(start);
          const std::vector<std::uint8_t> av(active.data(), active.data() + active.size());
          const tmm::StepRuleTable r = rule_of(steps, dslope, radius, probe, min_step);
          tmm::BatchOptions batch;
          batch.progress = tmm_bindings::python_progress(progress);
          std::vector<double> T;
          {
            py::gil_scoped_release release;
            T = tmm::arrival_field(g, zv, av, sv, r, batch);
          }
          py::array_t<double> out({static_cast<py::ssize_t>(g.ny), static_cast<py::ssize_t>(g.nx)});
          std::copy(T.begin(), T.end(), out.mutable_data());
          return out;
        },
        py::arg("z"), py::arg("cell"), py::arg("active"), py::arg("start"), py::arg("steps"), py::arg("dslope"),
        py::arg("radius"), py::arg("probe"), py::arg("min_step"), py::kw_only(), py::arg("progress") = py::none(),
        "Fast marching of the 3D offset's passes: T (ny, nx) in steps from the start band (start: finite T there, "
        "NaN elsewhere), over the nodes where active is nonzero (+inf elsewhere), the speed the cusp rule's step "
        "steps[k] at slope k * dslope (rad) across the front, divided by sqrt(1 + radius k) where the CL section "
        "bends up, at least min_step; z the CL heights, node (i, j) at (i cell, j cell). ValueError on bad input. "
        "progress(fraction) -> bool; False cancels (raises Cancelled).");
  m.def("arrival_steps",
        [](const Doubles& z, double cell, const Doubles& xy, const Doubles& dirs, const Doubles& steps, double dslope,
           double radius, double probe, double min_step) {
          const tmm::ArrivalGrid g = grid_of(z, cell);
          if (xy.ndim() != 2 || xy.shape(1) != 2 || dirs.ndim() != 2 || dirs.shape(1) != 2 ||
              dirs.shape(0) != xy.shape(0))
            throw std::invalid_argument("arrival steps: xy and dirs must be (n, 2) arrays of the same n");
          tmm_bindings::check_range(xy, "xy");
          tmm_bindings::check_range(dirs, "dirs");
          const std::vector<double> zv = values(z);
          const tmm::StepRuleTable r = rule_of(steps, dslope, radius, probe, min_step);
          tmm::check_arrival_inputs(g, zv, r);
          py::array_t<double> out(xy.shape(0));
          const double* p = xy.data();
          const double* u = dirs.data();
          double* o = out.mutable_data();
          for (py::ssize_t k = 0; k < xy.shape(0); ++k)
            o[k] = tmm::arrival_step(g, zv, r, p[2 * k], p[2 * k + 1], u[2 * k], u[2 * k + 1]);
          return out;
        },
        py::arg("z"), py::arg("cell"), py::arg("xy"), py::arg("dirs"), py::arg("steps"), py::arg("dslope"),
        py::arg("radius"), py::arg("probe"), py::arg("min_step"),
        "The step arrival_field uses at points xy (n, 2; mm from node 0) for fronts moving along dirs (n, 2).");
}
