// Python binding of the z-map stock and the exact 3-axis cutting simulation: numpy in, and the stock's
// heights as a writable numpy view (no copies either way).
#include <pybind11/functional.h>
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>

#include <cstdint>
#include <limits>
#include <sstream>
#include <stdexcept>
#include <vector>

#include "tmm/sim/sweep3.hpp"
#include "tmm/sim/zmap.hpp"
#include "sim/sim_arrays.hpp"
#include "util/progress.hpp"

namespace py = pybind11;
using tmm_bindings::python_progress;

namespace {

using tmm_bindings::check_rows;
using tmm_bindings::kinds_from;
using tmm_bindings::report_dict;
using Tips = tmm_bindings::Rows;

py::dict cut_3axis(tmm::ZMap& stock, const tmm::Cutter& cutter, const Tips& tips, const py::handle& kinds,
                   double collision_tol, int threads, const py::object& progress, const py::object& bodies,
                   double flute_top, double body_tol, double body_step) {
  check_rows(tips, "tips");
  const std::size_t n = static_cast<std::size_t>(tips.shape(0));
  const std::vector<tmm::MoveKind> k = kinds_from(kinds, n > 0 ? n - 1 : 0);
  tmm::Sweep3Options options;
  options.collision_tol = collision_tol;
  tmm::BodyCheck check;
  if (tmm_bindings::body_check_from(bodies, flute_top, body_tol, body_step, check)) options.body_check = &check;
  tmm::BatchOptions batch;
  batch.threads = threads;
  batch.progress = python_progress(progress);
  tmm::SimReport report;
  {
    py::gil_scoped_release release;
    report = tmm::cut_3axis(stock, cutter, tips.data(), k.data(), n, options, batch);
  }
  return report_dict(report, options.body_check != nullptr);
}

}  // namespace

void bind_sim(py::module_& m) {
  py::class_<tmm::ZMap>(m, "ZMap",
      "The stock as a height field: cell (i, j) holds the top's height on the vertical line through its "
      "centre (x0 + (i + 0.5) cell, y0 + (j + 0.5) cell).")
      .def(py::init<double, double, double, std::size_t, std::size_t, double, std::size_t>(), py::arg("x0"),
           py::arg("y0"), py::arg("cell"), py::arg("nx"), py::arg("ny"), py::arg("top"),
           py::arg("max_cells") = tmm::ZMap::kDefaultMaxCells,
           "A grid of nx x ny cells at the height top; refuses (ValueError) more than max_cells cells "
           "before allocating.")
      .def_readonly_static("DEFAULT_MAX_CELLS", &tmm::ZMap::kDefaultMaxCells)
      .def_static("bytes_for",
                  [](std::size_t nx, std::size_t ny) {
                    if (nx != 0 && ny > std::numeric_limits<std::size_t>::max() / sizeof(double) / nx)
                      throw std::invalid_argument("bytes_for: nx * ny cells overflow a byte count");
                    return tmm::ZMap::bytes_for(nx, ny);
                  },
                  py::arg("nx"), py::arg("ny"), "Bytes the heights of an nx x ny grid take.")
      .def_property_readonly("x0", &tmm::ZMap::x0)
      .def_property_readonly("y0", &tmm::ZMap::y0)
      .def_property_readonly("cell", &tmm::ZMap::cell)
      .def_property_readonly("nx", &tmm::ZMap::nx)
      .def_property_readonly("ny", &tmm::ZMap::ny)
      .def_property_readonly(
          "heights",
          [](py::object self) {
            tmm::ZMap& z = self.cast<tmm::ZMap&>();
            const auto nx = static_cast<py::ssize_t>(z.nx()), ny = static_cast<py::ssize_t>(z.ny());
            const auto s = static_cast<py::ssize_t>(sizeof(double));
            // The array's base is the ZMap object: the view keeps it alive.
            return py::array_t<double>({ny, nx}, {nx * s, s}, z.heights().data(), self);
          },
          "Writable (ny, nx) float64 view of the heights (row j is y); keeps the ZMap alive.");

  m.def("cut_3axis", &cut_3axis, py::arg("stock"), py::arg("cutter"), py::arg("tips"), py::arg("kinds"),
        py::arg("collision_tol") = 1e-3, py::arg("threads") = 0, py::arg("progress") = py::none(),
        py::arg("bodies") = py::none(), py::arg("flute_top") = 0.0, py::arg("body_tol") = 1e-3,
        py::arg("body_step") = 0.0,
        "Cuts the tool path into the stock: tips (n, 3) tool tips, kinds (n - 1,) integers (0 cut, 1 rapid, "
        "2 jump) for the moves tips[k] -> tips[k + 1]. Each cell within the tool's radius of a Cut or Rapid "
        "move is lowered to the exact swept envelope. A rapid removing more than collision_tol mm is a "
        "collision. progress(fraction) -> bool; False cancels (raises Cancelled, the stock partly cut). "
        "bodies: None, or (k, 5) rows (z0, z1, r0, r1, clearance) of the tool above the flutes (tip "
        "coordinates): each move's bodies are checked against the stock (poses body_step mm apart, 0: half a "
        "cell; the flutes cut only up to flute_top above the tip); a cell closer than a body's clearance by "
        "more than body_tol is a collision (tmm/sim/body_check.hpp). Returns {'moves_cut', 'cells_lowered', "
        "'collisions': (k, 2) [move index, depth], with bodies 'body_collisions': (m, 6) [move, piece, x, y, z, "
        "depth], the deepest cell per move and piece}.");
}
