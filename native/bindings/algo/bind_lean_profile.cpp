// Python binding of the lean passes' kernel fit (algo/lean_profile.hpp): runs as flat numpy arrays in, the
// vertices as numpy arrays out, the GIL released (progress takes it back for its call).
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>

#include <algorithm>
#include <cstdint>
#include <limits>
#include <stdexcept>
#include <vector>

#include "tmm/algo/lean_profile.hpp"
#include "util/arrays.hpp"
#include "util/progress.hpp"

namespace py = pybind11;

namespace {

template <class T>
using Arr = py::array_t<T, py::array::c_style | py::array::forcecast>;

template <class T>
std::vector<T> to_vector(const Arr<T>& a, const char* name, py::ssize_t width = 0) {
  if (width ? (a.ndim() != 2 || a.shape(1) != width) : a.ndim() != 1)
    throw std::invalid_argument(std::string(name) + (width ? " must have shape (n, 2)" : " must be 1-d"));
  return std::vector<T>(a.data(), a.data() + a.size());
}

using tmm_bindings::to_array;

}  // namespace

void bind_lean_profile(py::module_& m) {
  m.attr("LEAN_FIXED") = tmm::kLeanFixed;
  m.attr("LEAN_KEEP") = tmm::kLeanKeep;
  m.def("lean_profiles",
        [](const tmm::MeshIndex& index, const tmm::Cutter& tool, const Arr<double>& origin, const Arr<double>& dir,
           const Arr<std::int64_t>& offsets, const Arr<double>& s, const Arr<double>& z,
           const Arr<std::uint8_t>& flags, double tol, double max_step, double min_step, double drop_floor,
           double z_shift, double clamp_floor, double air_below, bool lower_bound, const py::object& arcs,
           double arc_min_radius, double arc_max_radius, double arc_max_slope, int threads,
           const py::object& progress) {
          tmm::LeanRuns runs;
          runs.origin = to_vector(origin, "origin", 2);
          runs.dir = to_vector(dir, "dir", 2);
          for (std::int64_t o : to_vector(offsets, "offsets")) {
            if (o < 0) throw std::invalid_argument("offsets must not be negative");
            runs.offsets.push_back(static_cast<std::size_t>(o));
          }
          runs.s = to_vector(s, "s");
          runs.z = to_vector(z, "z");
          runs.flags = to_vector(flags, "flags");
          if (!arcs.is_none()) runs.arcs = to_vector(arcs.cast<Arr<std::uint8_t>>(), "arcs");
          tmm::LeanOptions o;
          o.tol = tol;
          o.max_step = max_step;
          o.min_step = min_step;
          o.lower_bound = lower_bound;
          o.arc_min_radius = arc_min_radius;
          o.arc_max_radius = arc_max_radius;
          o.arc_max_slope = arc_max_slope;
          o.drop = {drop_floor, z_shift, clamp_floor, air_below};
          tmm::BatchOptions batch;
          batch.threads = threads;
          batch.progress = tmm_bindings::python_progress(progress);
          tmm::LeanResult r;
          {
            py::gil_scoped_release release;
            r = tmm::lean_profiles(index, tool, runs, o, batch);
          }
          std::vector<std::int64_t> off(r.offsets.begin(), r.offsets.end());
          py::dict info;
          info["drops"] = r.drops;
          info["breakpoints"] = r.breakpoints;
          info["refits"] = r.refits;
          info["kept_dense"] = r.kept_dense;
          info["lower_bound"] = r.lower_bound;
          info["arcs"] = r.arcs;
          if (!runs.arcs.empty()) {
            info["arc_s"] = to_array(r.arc_s);
            info["arc_z"] = to_array(r.arc_z);
          }
          return py::make_tuple(to_array(off), to_array(r.s), to_array(r.z), info);
        },
        py::arg("index"), py::arg("tool"), py::arg("origin"), py::arg("dir"), py::arg("offsets"), py::arg("s"),
        py::arg("z"), py::arg("flags"), py::kw_only(), py::arg("tol"), py::arg("max_step") = 0.05,
        py::arg("min_step") = 0.002, py::arg("drop_floor") = -1e6, py::arg("z_shift") = 0.0,
        py::arg("clamp_floor") = -std::numeric_limits<double>::infinity(),
        py::arg("air_below") = -std::numeric_limits<double>::infinity(), py::arg("lower_bound") = false,
        py::arg("arcs") = py::none(), py::arg("arc_min_radius") = 0.5, py::arg("arc_max_radius") = 1000.0,
        py::arg("arc_max_slope") = 1.0, py::arg("threads") = 0, py::arg("progress") = py::none(),
        "Lean vertices of straight runs (run k: samples offsets[k]..offsets[k+1]-1 at origin[k] + s * dir[k], "
        "exact heights z, flags LEAN_FIXED / LEAN_KEEP): the fewest lines within +-tol of the exact CL path "
        "(drop of `tool` at drop_floor, + z_shift, at least clamp_floor; air at or below air_below). Returns "
        "(offsets, s, z, {drops, breakpoints, refits, kept_dense, lower_bound, arcs}); with `arcs` (a flag per run: "
        "moves merged into arcs in its vertical plane where they hold the band) also info arc_s, arc_z: per vertex "
        "the centre (s, z) of the arc ending there, NaN for a line. ValueError on bad input; "
        "progress(fraction) -> bool, False cancels (raises Cancelled).");
}
