// Python binding of the drop-cutter: spatial index and batch drop, numpy in and out (the cutter itself:
// cutter/bind_cutter.cpp).
#include <pybind11/eigen.h>
#include <pybind11/functional.h>
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>

#include <memory>

#include "tmm/query/drop_cutter.hpp"
#include "tmm/mesh/mesh_index.hpp"
#include "util/arrays.hpp"
#include "util/progress.hpp"

namespace py = pybind11;
using tmm_bindings::python_progress;

namespace {

using XY = py::array_t<double, py::array::c_style | py::array::forcecast>;

py::array_t<double> drop_cutter(const tmm::MeshIndex& index, const tmm::Cutter& cutter,
                                const XY& xy, double floor_z, int threads, const py::object& progress,
                                py::dict* stats_out) {
  tmm_bindings::check_points(xy, 2, "points");
  tmm_bindings::check_range(xy, "points");
  const std::size_t n = static_cast<std::size_t>(xy.shape(0));
  py::array_t<double> z(static_cast<py::ssize_t>(n));
  tmm::BatchOptions options;
  options.threads = threads;
  options.progress = python_progress(progress);
  tmm::DropStats stats;
  {
    py::gil_scoped_release release;
    tmm::drop_batch(index, cutter, xy.data(), n, floor_z, z.mutable_data(), options, &stats);
  }
  if (stats_out) (*stats_out)["triangles_tested"] = stats.triangles_tested;
  return z;
}

}  // namespace

void bind_drop(py::module_& m) {
  py::register_exception<tmm::Cancelled>(m, "Cancelled");

  py::class_<tmm::MeshIndex, std::shared_ptr<tmm::MeshIndex>>(m, "MeshIndex",
      "Spatial index (XY bounding volume hierarchy with heights) over a triangle mesh for drop-cutter.")
      .def(py::init([](const Eigen::Ref<const tmm::Vertices>& V, const py::object& F, int threads,
                       const py::object& progress) {
             const tmm::Triangles T = tmm_bindings::triangles_from(F);
             const auto report = python_progress(progress);
             py::gil_scoped_release release;
             return std::make_shared<tmm::MeshIndex>(V, T, threads, report);
           }),
           py::arg("vertices"), py::arg("triangles"), py::kw_only(), py::arg("threads") = 0,
           py::arg("progress") = py::none(),
           "threads: build threads (0: all cores; small meshes build on one). progress(fraction) -> bool, "
           "called now and then; False cancels (raises Cancelled).")
      .def_property_readonly("build_threads", &tmm::MeshIndex::build_threads)
      .def_property_readonly("triangle_count", &tmm::MeshIndex::triangle_count)
      .def_property_readonly("node_count", [](const tmm::MeshIndex& i) { return i.nodes().size(); })
      .def_property_readonly("memory_bytes", &tmm::MeshIndex::memory_bytes)
      .def_property_readonly("zmin", &tmm::MeshIndex::zmin)
      .def_property_readonly("zmax", &tmm::MeshIndex::zmax);

  m.def("drop_cutter",
        [](const tmm::MeshIndex& index, const tmm::Cutter& cutter, const XY& xy, double floor_z, int threads,
           const py::object& progress) {
          return drop_cutter(index, cutter, xy, floor_z, threads, progress, nullptr);
        },
        py::arg("index"), py::arg("cutter"), py::arg("xy"), py::arg("floor_z"), py::arg("threads") = 0,
        py::arg("progress") = py::none(),
        "Tip heights (n,) of the cutter dropped along -Z at the (n, 2) points, never below floor_z. "
        "progress(fraction) -> bool; False cancels (raises Cancelled).");

  m.def("drop_cutter_stats",
        [](const tmm::MeshIndex& index, const tmm::Cutter& cutter, const XY& xy, double floor_z, int threads) {
          py::dict stats;
          py::array_t<double> z = drop_cutter(index, cutter, xy, floor_z, threads, py::none(), &stats);
          return py::make_tuple(z, stats);
        },
        py::arg("index"), py::arg("cutter"), py::arg("xy"), py::arg("floor_z"), py::arg("threads") = 0,
        "drop_cutter that also returns counters (triangles tested).");

  m.def("drop_on_triangle",
        [](const tmm::Cutter& cutter, double x, double y, const Eigen::Matrix3d& corners) {
          tmm::require_in_range(x, "x");
          tmm::require_in_range(y, "y");
          tmm::Vertices V = corners;
          tmm::require_rows_in_range(V.data(), 3, 3, "corners");
          tmm::Triangles F(1, 3);
          F << 0, 1, 2;
          const tmm::MeshIndex index(V, F);
          return tmm::drop_on_triangle(cutter, x, y, index.triangles()[0]);
        },
        py::arg("cutter"), py::arg("x"), py::arg("y"), py::arg("corners"),
        "Exact contact height of the cutter with one triangle (rows: corners), -inf if none.");
}
