// Python binding of the exact waterline: options as a struct, loops as numpy arrays, the GIL released.
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include <vector>

#include "tmm/query/waterline.hpp"
#include "util/progress.hpp"

namespace py = pybind11;

namespace {

// One level's loops as a list of (xy (n, 2) float64, contact (n,) bool) tuples.
py::list loops_to_python(const std::vector<tmm::WaterlineLoop>& loops) {
  py::list out;
  for (const tmm::WaterlineLoop& loop : loops) {
    const auto n = static_cast<py::ssize_t>(loop.size());
    py::array_t<double> xy({n, py::ssize_t{2}});
    std::copy(loop.xy.begin(), loop.xy.end(), xy.mutable_data());
    py::array_t<bool> contact(n);
    bool* c = contact.mutable_data();
    for (py::ssize_t i = 0; i < n; ++i) c[i] = loop.contact[static_cast<std::size_t>(i)] != 0;
    out.append(py::make_tuple(xy, contact));
  }
  return out;
}

}  // namespace

void bind_waterline(py::module_& m) {
  py::class_<tmm::WaterlineOptions>(m, "WaterlineOptions",
      "Options of the exact waterline: bounds of the tip (mm), grid sample step, chord tolerance, the bracket of "
      "each exact crossing, the shortest chord split, the split depth and the adaptive grid's finest cell (min_step; 0: a uniform grid).")
      .def(py::init<>())
      .def_readwrite("xmin", &tmm::WaterlineOptions::xmin)
      .def_readwrite("ymin", &tmm::WaterlineOptions::ymin)
      .def_readwrite("xmax", &tmm::WaterlineOptions::xmax)
      .def_readwrite("ymax", &tmm::WaterlineOptions::ymax)
      .def_readwrite("sample_step", &tmm::WaterlineOptions::sample_step)
      .def_readwrite("chord_tol", &tmm::WaterlineOptions::chord_tol)
      .def_readwrite("bracket", &tmm::WaterlineOptions::bracket)
      .def_readwrite("min_segment", &tmm::WaterlineOptions::min_segment)
      .def_readwrite("max_depth", &tmm::WaterlineOptions::max_depth)
      .def_readwrite("min_step", &tmm::WaterlineOptions::min_step);

  m.attr("WATERLINE_MAX_GRID_NODES") = tmm::kMaxWaterlineGridNodes;

  m.def("waterline_grid_size",
        [](const tmm::WaterlineOptions& o) {
          std::size_t nx = 0, ny = 0;
          tmm::waterline_grid_size(o, nx, ny);
          return py::make_tuple(nx, ny);
        },
        py::arg("options"), "(nx, ny): the drop grid's nodes along X and Y (bounds included, padding excluded).");

  m.def("waterline",
        [](const tmm::MeshIndex& index, const tmm::Cutter& cutter, const std::vector<double>& zs,
           const tmm::WaterlineOptions& options, int threads, const py::object& progress) {
          tmm::BatchOptions batch;
          batch.threads = threads;
          batch.progress = tmm_bindings::python_progress(progress);
          tmm::WaterlineStats stats;
          std::vector<std::vector<tmm::WaterlineLoop>> levels;
          {
            py::gil_scoped_release release;
            levels = tmm::waterline(index, cutter, zs, options, batch, &stats);
          }
          py::list out;
          for (const auto& level : levels) out.append(loops_to_python(level));
          py::dict info;
          info["grid_nodes"] = stats.grid_nodes;
          info["drops"] = stats.drops;
          info["refined_cells"] = stats.refined_cells;
          return py::make_tuple(out, info);
        },
        py::arg("index"), py::arg("cutter"), py::arg("zs"), py::arg("options"), py::kw_only(),
        py::arg("threads") = 0, py::arg("progress") = py::none(),
        "Waterline loops of the tip at each height of zs: ([[(xy (n, 2), contact (n,) bool), ...] per level], "
        "stats). Blocked material on the left of each loop (islands counter-clockwise). progress(fraction) -> "
        "bool; False cancels (raises Cancelled).");
}
