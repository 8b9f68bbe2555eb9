// Python binding of Bezier/B-spline faces.
#include <pybind11/eigen.h>
#include <pybind11/functional.h>
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include <memory>
#include <sstream>
#include <string>

#include "tmm/surface/bezier.hpp"
#include "util/arrays.hpp"

namespace py = pybind11;

namespace {

using tmm_bindings::Arr;
using tmm_bindings::check_points;
using tmm_bindings::rows3;

tmm::BezierPatch patch_from_array(const Arr& net) {
  if (net.ndim() != 3 || net.shape(2) != 3 || net.shape(0) < 1 || net.shape(1) < 1) {
    std::ostringstream msg;
    msg << "Bezier control net must have shape (p+1, q+1, 3), got ndim " << net.ndim();
    throw std::invalid_argument(msg.str());
  }
  const int p = static_cast<int>(net.shape(0)) - 1, q = static_cast<int>(net.shape(1)) - 1;
  std::vector<Eigen::Vector3d> poles(static_cast<std::size_t>((p + 1) * (q + 1)));
  const double* d = net.data();
  for (std::size_t k = 0; k < poles.size(); ++k) poles[k] = Eigen::Vector3d(d[3 * k], d[3 * k + 1], d[3 * k + 2]);
  return tmm::BezierPatch(p, q, std::move(poles));
}

py::array_t<double> net_to_array(const tmm::BezierPatch& b) {
  py::array_t<double> out({b.degree_u() + 1, b.degree_v() + 1, 3});
  double* d = out.mutable_data();
  for (std::size_t k = 0; k < b.poles().size(); ++k)
    for (int c = 0; c < 3; ++c) d[3 * k + static_cast<std::size_t>(c)] = b.poles()[k][c];
  return out;
}

}  // namespace

void bind_surface(py::module_& m) {
  using tmm::PatchSurface;

  py::class_<PatchSurface, std::shared_ptr<PatchSurface>>(m, "PatchSurface",
      "A face made of nu x nv Bezier patches (any degree) over breakpoints in u and v; exact evaluation.")
      .def(py::init([](const std::vector<Arr>& nets, int nu, int nv, std::vector<double> bu, std::vector<double> bv) {
             std::vector<tmm::BezierPatch> patches;
             patches.reserve(nets.size());
             for (const auto& n : nets) patches.push_back(patch_from_array(n));
             return std::make_shared<PatchSurface>(std::move(patches), nu, nv, std::move(bu), std::move(bv));
           }),
           py::arg("nets"), py::arg("nu"), py::arg("nv"), py::arg("breaks_u"), py::arg("breaks_v"),
           "nets: nu*nv control nets (p+1, q+1, 3), row-major over (i in u, j in v).")
      .def_static("from_net", [](const Arr& net) { return std::make_shared<PatchSurface>(patch_from_array(net)); },
                  py::arg("net"), "One Bezier patch over [0, 1]^2.")
      .def_property_readonly("nu", &PatchSurface::nu)
      .def_property_readonly("nv", &PatchSurface::nv)
      .def_property_readonly("domain", [](const PatchSurface& s) {
        return py::make_tuple(s.umin(), s.umax(), s.vmin(), s.vmax());
      })
      .def_property_readonly("bounds", [](const PatchSurface& s) {
        const auto& b = s.bounds();
        return py::make_tuple(py::make_tuple(b.lo.x(), b.lo.y(), b.lo.z()), py::make_tuple(b.hi.x(), b.hi.y(), b.hi.z()));
      })
      .def("net",
           [](const PatchSurface& s, int i, int j) {
             if (i < 0 || i >= s.nu() || j < 0 || j >= s.nv()) {
               std::ostringstream msg;
               msg << "patch (" << i << ", " << j << ") outside 0.." << s.nu() - 1 << " x 0.." << s.nv() - 1;
               throw py::index_error(msg.str());
             }
             return net_to_array(s.patch(i, j));
           },
           py::arg("i"), py::arg("j"))
      .def("evaluate",
           [](const PatchSurface& s, const Arr& uv_in) {
             const Arr uv = check_points(uv_in, 2, "uv");
             tmm_bindings::check_range(uv, "uv");
             const std::size_t n = static_cast<std::size_t>(uv.shape(0));
             py::array_t<double> out[6] = {rows3(n), rows3(n), rows3(n), rows3(n), rows3(n), rows3(n)};
             double* d[6];
             for (int k = 0; k < 6; ++k) d[k] = out[k].mutable_data();
             const double* p = uv.data();
             {
               py::gil_scoped_release release;
               for (std::size_t i = 0; i < n; ++i) {
                 const tmm::SurfacePoint sp = s.eval(p[2 * i], p[2 * i + 1], 2);
                 const Eigen::Vector3d* v[6] = {&sp.S, &sp.Su, &sp.Sv, &sp.Suu, &sp.Suv, &sp.Svv};
                 for (int k = 0; k < 6; ++k)
                   for (int c = 0; c < 3; ++c) d[k][3 * i + static_cast<std::size_t>(c)] = (*v[k])[c];
               }
             }
             py::dict r;
             const char* names[6] = {"S", "Su", "Sv", "Suu", "Suv", "Svv"};
             for (int k = 0; k < 6; ++k) r[names[k]] = out[k];
             return r;
           },
           py::arg("uv"), "S and its first and second derivatives at (n, 2) global parameters: dict of (n, 3).")
      .def("ray_hit",
           [](const PatchSurface& s, const Eigen::Vector3d& o, const Eigen::Vector3d& d) -> py::object {
             tmm::require_rows_in_range(o.data(), 1, 3, "origin");
             tmm::require_rows_in_range(d.data(), 1, 3, "direction");
             const auto hit = s.ray_hit(o, d);
             if (!hit) return py::none();
             return py::make_tuple(hit->s, hit->uv.x(), hit->uv.y());
           },
           py::arg("origin"), py::arg("direction"),
           "First hit (s, u, v) of origin + s*direction (s >= 0), or None.");

  m.def("bezier_subpatch",
        [](const Arr& net, double u0, double u1, double v0, double v1) {
          return net_to_array(patch_from_array(net).sub(u0, u1, v0, v1));
        },
        py::arg("net"), py::arg("u0"), py::arg("u1"), py::arg("v0"), py::arg("v1"),
        "Control net of the piece [u0, u1] x [v0, v1] of a Bezier patch (de Casteljau).");
}
