// Python binding of STL reading and the indexed mesh (tmm/stl_io.hpp, tmm/mesh.hpp).
#include "tmm/mesh/mesh.hpp"
#include "tmm/mesh/stl_io.hpp"

#include <pybind11/eigen.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl/filesystem.h>

#include "util/arrays.hpp"
#include "util/progress.hpp"

#include <cstddef>
#include <filesystem>
#include <string>

namespace py = pybind11;
using tmm_bindings::python_progress;
using tmm_bindings::triangles_from;

namespace {

// Every mesh phase takes seconds on a mesh of millions of triangles: each reports and can be cancelled.
constexpr const char* kProgressDoc =
    "\nprogress(fraction) -> bool, called now and then (every 20 ms, 1.0 at the end); False cancels (raises "
    "Cancelled).";

std::string with_progress(const char* doc) { return std::string(doc) + kProgressDoc; }

}  // namespace

void bind_mesh(py::module_& m) {
  // A broken or unreadable STL is bad input: a ValueError subclass carrying the kernel's message.
  py::register_local_exception<tmm::StlError>(m, "StlError", PyExc_ValueError);

  m.def(
      "read_stl",
      [](const std::filesystem::path& path, const py::object& progress) {
        const auto report = python_progress(progress);
        py::gil_scoped_release release;
        return tmm::read_stl(path.string(), report);
      },
      py::arg("path"), py::arg("progress") = py::none(),
      with_progress(
          "Triangles of an ASCII or binary STL file (detected by content) as an (m, 9) float64 array of corners\n"
          "x1 y1 z1 x2 y2 z2 x3 y3 z3. Facet normals are not returned. Raises StlError (a ValueError) naming the\n"
          "file and the line or triangle for a missing, empty, truncated, garbled or non-finite file.")
          .c_str());

  m.def(
      "weld",
      [](const tmm::SoupRef& corners, double tol, const py::object& progress) {
        const auto report = python_progress(progress);
        tmm::Mesh mesh;
        std::size_t removed = 0;
        {
          py::gil_scoped_release release;
          mesh = tmm::weld(corners, tol, &removed, report);
        }
        return py::make_tuple(std::move(mesh.V), std::move(mesh.F), removed);
      },
      py::arg("corners"), py::arg("tol"), py::arg("progress") = py::none(),
      with_progress(
          "Weld an (m, 9) float64 triangle soup into shared vertices within distance `tol`.\n"
          "Returns (V (n, 3) float64, F (k, 3) int32, removed_degenerate: int): triangles that became degenerate\n"
          "(repeated vertex or zero area) are dropped and counted. ValueError for a non-finite coordinate, a bad\n"
          "tolerance or when no non-degenerate triangle remains.")
          .c_str());

  m.def(
      "face_normals",
      [](const tmm::VerticesRef& V, const py::object& F, const py::object& progress) {
        const tmm::Triangles T = triangles_from(F);
        const auto report = python_progress(progress);
        py::gil_scoped_release release;
        return tmm::face_normals(V, T, report);
      },
      py::arg("V"), py::arg("F"), py::arg("progress") = py::none(),
      with_progress("Unit normal (m, 3) of each triangle from its winding; (0, 0, 0) for a zero-area triangle.")
          .c_str());

  m.def(
      "vertex_normals",
      [](const tmm::VerticesRef& V, const py::object& F, const std::string& weighting, const py::object& progress) {
        const tmm::NormalWeighting w = tmm::parse_weighting(weighting);
        const tmm::Triangles T = triangles_from(F);
        const auto report = python_progress(progress);
        py::gil_scoped_release release;
        return tmm::vertex_normals(V, T, w, report);
      },
      py::arg("V"), py::arg("F"), py::arg("weighting") = "angle", py::arg("progress") = py::none(),
      with_progress(
          "Unit normal (n, 3) of each vertex: weighting 'angle' (MWA), 'area' (MWAAT) or 'meyer' (mean-curvature\n"
          "normal direction, angle weighting where it is undefined), seed 000 section 3.2. (0, 0, 0) for a vertex\n"
          "used by no triangle of non-zero area.")
          .c_str());

  m.def(
      "triangle_adjacency",
      [](const py::object& F, const py::object& progress) {
        const tmm::Triangles T = triangles_from(F);
        const auto report = python_progress(progress);
        py::gil_scoped_release release;
        return tmm::triangle_adjacency(T, report);
      },
      py::arg("F"), py::arg("progress") = py::none(),
      with_progress(
          "(m, 3) int32: for triangle t and edge i = (F[t, i], F[t, (i + 1) % 3]) the other triangle sharing the\n"
          "edge, or -1 for a boundary or non-manifold edge (shared by more than two triangles).")
          .c_str());
}
