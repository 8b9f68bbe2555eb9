// Python binding of the adaptive raster's pass placement: options as a struct, offsets and cusps as numpy
// arrays, the GIL released (progress takes it back for its call).
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>

#include <algorithm>

#include "tmm/algo/adaptive_raster.hpp"
#include "util/arrays.hpp"
#include "util/progress.hpp"

namespace py = pybind11;

using tmm_bindings::to_array;

void bind_adaptive_raster(py::module_& m) {
  using O = tmm::AdaptiveRasterOptions;
  py::class_<O>(m, "AdaptiveRasterOptions",
      "Options of the adaptive raster: the boundary of the tool centres (model frame, mm), the passes' angle "
      "from +X (rad), the cusp tolerance, the sample step along a pass, the floor, the stock to leave, the slope "
      "limit of the measure (rad) and the step's range (step_min, step_max).")
      .def(py::init<>())
      .def_readwrite("xmin", &O::xmin)
      .def_readwrite("ymin", &O::ymin)
      .def_readwrite("xmax", &O::xmax)
      .def_readwrite("ymax", &O::ymax)
      .def_readwrite("angle", &O::angle)
      .def_readwrite("cusp", &O::cusp)
      .def_readwrite("sample_step", &O::sample_step)
      .def_readwrite("floor_z", &O::floor_z)
      .def_readwrite("stock_to_leave", &O::stock_to_leave)
      .def_readwrite("max_slope", &O::max_slope)
      .def_readwrite("step_min", &O::step_min)
      .def_readwrite("step_max", &O::step_max);

  m.attr("ADAPTIVE_MAX_SECTION_SAMPLES") = tmm::kMaxAdaptiveSectionSamples;

  m.def("adaptive_raster_work",
        [](const tmm::Cutter& cutter, const O& o) {
          const tmm::AdaptiveRasterWork w = tmm::adaptive_raster_work(cutter, o);
          return py::make_tuple(w.cl_points, w.section_samples);
        },
        py::arg("cutter"), py::arg("options"),
        "(CL points at most, section samples per pass) the options ask for; ValueError on bad options or a "
        "section grid above ADAPTIVE_MAX_SECTION_SAMPLES.");

  m.def("adaptive_raster",
        [](const tmm::MeshIndex& index, const tmm::Cutter& tool, const tmm::Cutter& cutter, const O& o,
           int threads, const py::object& progress) {
          tmm::BatchOptions batch;
          batch.threads = threads;
          batch.progress = tmm_bindings::python_progress(progress);
          tmm::AdaptiveRasterResult r;
          {
            py::gil_scoped_release release;
            r = tmm::adaptive_raster(index, tool, cutter, o, batch);
          }
          py::dict info;
          info["limited"] = r.limited;
          info["unreachable"] = r.unreachable;
          info["evaluations"] = r.evaluations;
          info["drops"] = r.drops;
          return py::make_tuple(to_array(r.offsets), to_array(r.cusps), info);
        },
        py::arg("index"), py::arg("tool"), py::arg("cutter"), py::arg("options"), py::kw_only(),
        py::arg("threads") = 0, py::arg("progress") = py::none(),
        "The adaptive raster's pass offsets over `index` (the mesh turned so the passes run along +X): "
        "(offsets (k,), cusps (k - 1,), {limited, unreachable, evaluations, drops}). `tool` is dropped (the "
        "cutter grown by the stock to leave), `cutter`'s profile shapes the cusps. progress(fraction) -> bool; "
        "False cancels (raises Cancelled).");
}
