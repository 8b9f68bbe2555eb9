// The one Python module over the kernel. Each part of the kernel binds itself in its own file.
#include <pybind11/pybind11.h>

namespace py = pybind11;

void bind_mesh(py::module_& m);   // mesh/bind_mesh.cpp: STL reading, indexed mesh, vertex normals
void bind_cutter(py::module_& m);  // cutter/bind_cutter.cpp: the cutter of revolution and its profile
void bind_drop(py::module_& m);   // query/bind_drop.cpp: spatial index, batch drop-cutter
void bind_direction(py::module_& m);  // query/bind_direction.cpp: drop along any direction, any axis
void bind_drop_assembly(py::module_& m);  // query/bind_drop_assembly.cpp: drop of cutter + shank + holder
void bind_surface(py::module_& m);    // surface/bind_surface.cpp: Bezier/B-spline faces
void bind_multipoint(py::module_& m);  // position/bind_multipoint.cpp: multipoint positioning of a torus
void bind_waterline(py::module_& m);  // query/bind_waterline.cpp: exact waterline loops
void bind_sim(py::module_& m);    // sim/bind_sim.cpp: the z-map stock and 3-axis cutting simulation
void bind_sim5(py::module_& m);   // sim/bind_sim5.cpp: 5-axis cutting simulation (moving tool axis)
void bind_adaptive_raster(py::module_& m);  // algo/bind_adaptive_raster.cpp: adaptive raster pass placement
void bind_arrival_field(py::module_& m);  // algo/bind_arrival_field.cpp: the 3D offset's arrival-time field
void bind_lean_profile(py::module_& m);  // algo/bind_lean_profile.cpp: lean passes, the kernel fit

PYBIND11_MODULE(_native, m) {
  m.doc() = "TMM geometry kernel (C++17, Eigen)";
  bind_mesh(m);
  bind_cutter(m);
  bind_drop(m);
  bind_direction(m);
  bind_drop_assembly(m);
  bind_waterline(m);
  bind_surface(m);
  bind_multipoint(m);
  bind_sim(m);
  bind_sim5(m);
  bind_adaptive_raster(m);
  bind_arrival_field(m);
  bind_lean_profile(m);
}
