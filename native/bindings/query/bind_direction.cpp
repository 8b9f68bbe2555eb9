// Python binding of the drop along any direction with any cutter axis: numpy in and out, GIL released,
// progress and cancel as drop_cutter (bind_drop.cpp).
#include <pybind11/eigen.h>
#include <pybind11/functional.h>
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>

#include <limits>
#include <memory>
#include <sstream>

#include "tmm/query/drop_direction.hpp"
#include "util/arrays.hpp"
#include "util/progress.hpp"
#include "starts.hpp"

namespace py = pybind11;
using tmm_bindings::python_progress;

namespace {

using Array = py::array_t<double, py::array::c_style | py::array::forcecast>;

Eigen::Vector3d vec3(const Array& a, const char* what) {
  if (a.size() != 3) {
    std::ostringstream msg;
    msg << what << " must have 3 components, got " << a.size();
    throw std::invalid_argument(msg.str());
  }
  return Eigen::Vector3d(a.data()[0], a.data()[1], a.data()[2]);
}

py::array_t<double> drop_along(const tmm::DirectionalIndex& index, const tmm::Cutter& cutter, const Array& starts,
                               const Array& axes, double max_travel, int threads, const py::object& progress,
                               py::dict* stats_out) {
  const bool per_point = tmm_bindings::check_starts_and_axes(starts, axes, max_travel);
  const std::size_t n = static_cast<std::size_t>(starts.shape(0));
  py::array_t<double> travel(static_cast<py::ssize_t>(n));
  tmm::BatchOptions options;
  options.threads = threads;
  options.progress = python_progress(progress);
  tmm::DropStats stats;
  {
    py::gil_scoped_release release;
    tmm::drop_along_batch(index, cutter, starts.data(), axes.data(), per_point, n, max_travel,
                          travel.mutable_data(), options, &stats);
  }
  if (stats_out) (*stats_out)["triangles_tested"] = stats.triangles_tested;
  return travel;
}

}  // namespace

void bind_direction(py::module_& m) {
  py::class_<tmm::DirectionalIndex, std::shared_ptr<tmm::DirectionalIndex>>(m, "DirectionalIndex",
      "A mesh indexed for drops along one unit direction V (the mesh rotated so that V = -Z', XY' hierarchy).")
      .def(py::init([](const Eigen::Ref<const tmm::Vertices>& V, const py::object& F, const Array& direction,
                       int threads) {
             const Eigen::Vector3d d = vec3(direction, "direction");
             const tmm::Triangles T = tmm_bindings::triangles_from(F);
             py::gil_scoped_release release;
             return std::make_shared<tmm::DirectionalIndex>(V, T, d, threads);
           }),
           py::arg("vertices"), py::arg("triangles"), py::arg("direction"), py::kw_only(), py::arg("threads") = 0)
      .def_property_readonly("direction", [](const tmm::DirectionalIndex& i) { return Eigen::Vector3d(i.direction()); })
      .def_property_readonly("rotation", [](const tmm::DirectionalIndex& i) { return Eigen::Matrix3d(i.rotation()); })
      .def_property_readonly("triangle_count", [](const tmm::DirectionalIndex& i) { return i.index().triangle_count(); });

  m.def("drop_along",
        [](const tmm::DirectionalIndex& index, const tmm::Cutter& cutter, const Array& starts, const Array& axes,
           double max_travel, int threads, const py::object& progress) {
          return drop_along(index, cutter, starts, axes, max_travel, threads, progress, nullptr);
        },
        py::arg("index"), py::arg("cutter"), py::arg("starts"), py::arg("axes"),
        py::arg("max_travel") = std::numeric_limits<double>::infinity(), py::arg("threads") = 0,
        py::arg("progress") = py::none(),
        "Travel (n,) along the index's direction V of the first contact of the cutter (tip at start + t V, axis "
        "`axes`: (3,) for all points or (n, 3)), capped at max_travel (inf: no contact). Only the cutting part "
        "(up to the cutting length) is checked, not the shank. progress(fraction) -> bool; False cancels "
        "(raises Cancelled).");

  m.def("drop_along_stats",
        [](const tmm::DirectionalIndex& index, const tmm::Cutter& cutter, const Array& starts, const Array& axes,
           double max_travel, int threads) {
          py::dict stats;
          py::array_t<double> t = drop_along(index, cutter, starts, axes, max_travel, threads, py::none(), &stats);
          return py::make_tuple(t, stats);
        },
        py::arg("index"), py::arg("cutter"), py::arg("starts"), py::arg("axes"),
        py::arg("max_travel") = std::numeric_limits<double>::infinity(), py::arg("threads") = 0,
        "drop_along that also returns counters (triangles tested).");

  m.def("drop_along_triangle",
        [](const tmm::Cutter& cutter, const Array& start, const Array& axis, const Array& direction,
           const Eigen::Matrix3d& corners) {
          tmm_bindings::check_range(start, "start");
          tmm_bindings::check_range(axis, "axis");
          tmm_bindings::check_range(direction, "direction");
          const tmm::Vertices rows = corners;
          tmm::require_rows_in_range(rows.data(), 3, 3, "corners");
          return tmm::drop_along(cutter, vec3(start, "start"), vec3(axis, "axis"), vec3(direction, "direction"),
                                 corners.row(0).transpose(), corners.row(1).transpose(), corners.row(2).transpose());
        },
        py::arg("cutter"), py::arg("start"), py::arg("axis"), py::arg("direction"), py::arg("corners"),
        "First-contact travel of the cutter against one triangle (rows: corners), inf if none.");
}
