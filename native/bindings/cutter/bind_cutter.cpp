// Python binding of the cutter of revolution: its kinds, its constructors and its profile h(rho). Bound before
// the queries that take a cutter, so their signatures name the Python class.
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>

#include <stdexcept>

#include "tmm/cutter/cutter.hpp"

namespace py = pybind11;

void bind_cutter(py::module_& m) {
  py::enum_<tmm::CutterKind>(m, "CutterKind")
      .value("Flat", tmm::CutterKind::Flat)
      .value("Ball", tmm::CutterKind::Ball)
      .value("Bull", tmm::CutterKind::Bull)
      .value("General", tmm::CutterKind::General);

  py::class_<tmm::Cutter>(m, "Cutter",
      "Convex cutter of revolution: the generalized APT cutter of seed 000 (ball, flat, bull-nose, cone, taper).")
      .def(py::init<double, double>(), py::arg("radius"), py::arg("corner_radius"),
           "Ball (corner radius = radius), flat (0) or bull-nose.")
      .def_static("apt", &tmm::Cutter::apt, py::arg("radius"), py::arg("corner_radius"),
                  py::arg("cutting_length"), py::arg("beta1"), py::arg("beta2"),
                  "Generalized APT cutter: radius R at the cutting-edge height L_C, corner radius r, bottom angle "
                  "beta1 from the horizontal and taper angle beta2 from the axis (radians).")
      .def_property_readonly("radius", &tmm::Cutter::radius)
      .def_property_readonly("corner_radius", &tmm::Cutter::corner_radius)
      .def_property_readonly("cutting_length", &tmm::Cutter::cutting_length)
      .def_property_readonly("max_radius", &tmm::Cutter::max_radius)
      .def_property_readonly("kind", &tmm::Cutter::kind)
      .def("height",
           [](const tmm::Cutter& c, const py::array_t<double, py::array::c_style | py::array::forcecast>& rho) {
             py::array_t<double> out(rho.request().shape);
             const double* in = rho.data();
             double* o = out.mutable_data();
             for (py::ssize_t i = 0; i < rho.size(); ++i) {
               if (!(in[i] >= 0.0 && in[i] <= c.max_radius()))
                 throw std::invalid_argument("rho outside 0..max_radius");
               o[i] = c.height(in[i]);
             }
             return out;
           },
           py::arg("rho"), "Height h(rho) of the cutting surface above the tip.");
}
