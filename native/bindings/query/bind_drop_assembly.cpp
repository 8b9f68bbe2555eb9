// Python binding of the tool assembly's drop (cutter + shank/neck + holder, each with a clearance): numpy in
// and out, GIL released, progress and cancel as drop_cutter (bind_drop.cpp).
#include <pybind11/functional.h>
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>

#include <cmath>
#include <limits>
#include <sstream>
#include <utility>
#include <vector>

#include "tmm/query/drop_assembly.hpp"
#include "tmm/query/drop_assembly_direction.hpp"
#include "util/arrays.hpp"
#include "util/progress.hpp"
#include "starts.hpp"

namespace py = pybind11;

namespace {

using Array = py::array_t<double, py::array::c_style | py::array::forcecast>;

// (k, 5) rows (z0, z1, r0, r1, clearance); an empty array of any shape is no bodies. The kernel checks the
// values (ToolAssembly).
std::vector<tmm::ToolBody> bodies_from(const Array& a) {
  if (a.size() == 0) return {};
  if (a.ndim() != 2 || a.shape(1) != 5) {
    std::ostringstream msg;
    msg << "bodies must have shape (k, 5): rows (z0, z1, r0, r1, clearance), got ndim " << a.ndim();
    if (a.ndim() == 2) msg << " and " << a.shape(1) << " columns";
    throw std::invalid_argument(msg.str());
  }
  std::vector<tmm::ToolBody> bodies(static_cast<std::size_t>(a.shape(0)));
  const double* v = a.data();
  for (auto& b : bodies) {
    b = {v[0], v[1], v[2], v[3], v[4]};
    v += 5;
  }
  return bodies;
}

py::tuple drop_assembly(const tmm::MeshIndex& index, const tmm::Cutter& cutter, const Array& bodies,
                        const Array& xy, double floor_z, double cutter_clearance, int threads,
                        const py::object& progress) {
  const tmm::ToolAssembly tool(cutter, bodies_from(bodies), cutter_clearance);
  tmm_bindings::check_points(xy, 2, "points");
  tmm_bindings::check_range(xy, "points");
  const std::size_t n = static_cast<std::size_t>(xy.shape(0));
  py::array_t<double> z(static_cast<py::ssize_t>(n));
  py::array_t<int32_t> set_by(static_cast<py::ssize_t>(n));
  tmm::BatchOptions options;
  options.threads = threads;
  options.progress = tmm_bindings::python_progress(progress);
  {
    py::gil_scoped_release release;
    tmm::drop_assembly_batch(index, tool, xy.data(), n, floor_z, z.mutable_data(), set_by.mutable_data(), options);
  }
  return py::make_tuple(std::move(z), std::move(set_by));
}

py::tuple drop_assembly_along(const tmm::DirectionalIndex& index, const tmm::Cutter& cutter, const Array& bodies,
                              const Array& starts, const Array& axes, double max_travel, double cutter_clearance,
                              int threads, const py::object& progress) {
  const tmm::ToolAssembly tool(cutter, bodies_from(bodies), cutter_clearance);
  const bool per_point = tmm_bindings::check_starts_and_axes(starts, axes, max_travel);
  const std::size_t n = static_cast<std::size_t>(starts.shape(0));
  py::array_t<double> travel(static_cast<py::ssize_t>(n));
  py::array_t<int32_t> set_by(static_cast<py::ssize_t>(n));
  tmm::BatchOptions options;
  options.threads = threads;
  options.progress = tmm_bindings::python_progress(progress);
  {
    py::gil_scoped_release release;
    tmm::drop_assembly_along_batch(index, tool, starts.data(), axes.data(), per_point, n, max_travel,
                                   travel.mutable_data(), set_by.mutable_data(), options);
  }
  return py::make_tuple(std::move(travel), std::move(set_by));
}

}  // namespace

void bind_drop_assembly(py::module_& m) {
  m.def("drop_assembly", &drop_assembly, py::arg("index"), py::arg("cutter"), py::arg("bodies"), py::arg("xy"),
        py::arg("floor_z"), py::arg("cutter_clearance") = 0.0, py::arg("threads") = 0,
        py::arg("progress") = py::none(),
        "Drop of the whole tool assembly along -Z at the (n, 2) points: the lowest tip heights, never below "
        "floor_z, at which no piece comes closer to the mesh than its clearance. bodies: (k, 5) float rows "
        "(z0, z1, r0, r1, clearance), frustums coaxial with the tool in tip coordinates (radius r0 at z0 above "
        "the tip, r1 at z1), sorted from the tip up with z ranges not overlapping (one may start where the last "
        "ends); an empty array for none. cutter_clearance: the cutter's own (a positive one needs a "
        "flat-bottomed cutter). Returns (z, set_by): z (n,) float64 tip heights (floor_z where nothing is under "
        "the tool, as drop_cutter), set_by (n,) int32: -1 the cutter, i body i, -2 nothing above floor_z. With "
        "no bodies and no clearance z equals drop_cutter's exactly. Bad bodies raise ValueError naming the "
        "body. progress(fraction) -> bool; False cancels (raises Cancelled).");
  m.def("drop_assembly_along", &drop_assembly_along, py::arg("index"), py::arg("cutter"), py::arg("bodies"),
        py::arg("starts"), py::arg("axes"), py::arg("max_travel") = std::numeric_limits<double>::infinity(),
        py::arg("cutter_clearance") = 0.0, py::arg("threads") = 0, py::arg("progress") = py::none(),
        "Drop of the whole tool assembly along the DirectionalIndex's direction: from each (n, 3) start the tool "
        "(tip at start + t * direction, t from -inf) travels until a piece first comes as close to the mesh as "
        "its clearance. axes: the tool axis, (3,) or (n, 3) unit vectors. bodies and cutter_clearance as "
        "drop_assembly; along a tilted axis an endless cutter is cut where the first body starts and nothing "
        "above the last body is modelled. Returns (travel, set_by): travel (n,) float64 (max_travel where "
        "nothing is touched before it), set_by (n,) int32: -1 the cutter, i body i, -2 nothing. With the axis "
        "opposite to the direction: drop_assembly in the rotated frame (travel = start height - tip height). "
        "progress(fraction) -> bool; False cancels (raises Cancelled).");
}
