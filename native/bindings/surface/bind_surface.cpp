// Python binding of Bezier/B-spline faces and multipoint positioning of a toroidal cutter.
#include <pybind11/eigen.h>
#include <pybind11/functional.h>
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include <memory>
#include <sstream>
#include <string>

#include "tmm/surface/bezier.hpp"
#include "tmm/position/multipoint.hpp"
#include "util/progress.hpp"

namespace py = pybind11;
using tmm_bindings::python_progress;

namespace {

using Arr = py::array_t<double, py::array::c_style | py::array::forcecast>;

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

Arr check_points(const Arr& a, py::ssize_t cols, const char* what) {
  if (a.ndim() != 2 || a.shape(1) != cols) {
    std::ostringstream msg;
    msg << what << " must have shape (n, " << cols << ")";
    throw std::invalid_argument(msg.str());
  }
  return a;
}

py::array_t<double> rows3(std::size_t n) { return py::array_t<double>({static_cast<py::ssize_t>(n), py::ssize_t{3}}); }

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
      .def("net", [](const PatchSurface& s, int i, int j) { return net_to_array(s.patch(i, j)); },
           py::arg("i"), py::arg("j"))
      .def("evaluate",
           [](const PatchSurface& s, const Arr& uv_in) {
             const Arr uv = check_points(uv_in, 2, "uv");
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

  m.def("multipoint_reasons", &tmm::multipoint_reason_text, "Text of each multipoint reason code.");

  py::class_<tmm::MultipointPositioner, std::shared_ptr<tmm::MultipointPositioner>>(m, "MultipointPositioner",
      "Multipoint positioning of a toroidal cutter on a PatchSurface (seed 001: VCRF or DRD).")
      .def(py::init([](std::shared_ptr<PatchSurface> surface, double Ro, double Ri, const std::string& shape,
                       const std::string& method, const std::string& rotation, double beta_max, double tol,
                       double sample_spacing, int divisions, int refinements, int drd_divisions,
                       int drd_refinements, int drd_bisections, double extend, const std::string& anchor,
                       int anchor_iterations) {
             tmm::TorusTool tool;
             tool.Ro = Ro;
             tool.Ri = Ri;
             if (shape == "round_insert") tool.shape = tmm::ToolShape::RoundInsert;
             else if (shape == "bull_nose") tool.shape = tmm::ToolShape::BullNose;
             else throw std::invalid_argument("tool shape must be 'round_insert' or 'bull_nose', got '" + shape + "'");
             tmm::MultipointOptions o;
             if (method == "vcrf") o.method = tmm::MultipointMethod::VCRF;
             else if (method == "drd") o.method = tmm::MultipointMethod::DRD;
             else throw std::invalid_argument("method must be 'vcrf' or 'drd', got '" + method + "'");
             if (rotation == "pseudo_insert") o.rotation = tmm::TiltRotation::PseudoInsert;
             else if (rotation == "global_x") o.rotation = tmm::TiltRotation::GlobalX;
             else throw std::invalid_argument("rotation must be 'pseudo_insert' or 'global_x', got '" + rotation + "'");
             if (anchor == "axis") o.anchor = tmm::FootprintAnchor::Axis;
             else if (anchor == "tip") o.anchor = tmm::FootprintAnchor::Tip;
             else throw std::invalid_argument("anchor must be 'axis' or 'tip', got '" + anchor + "'");
             o.extend = extend;
             o.anchor_iterations = anchor_iterations;
             o.beta_max = beta_max;
             o.tol = tol;
             o.sample_spacing = sample_spacing;
             o.divisions = divisions;
             o.refinements = refinements;
             o.drd_divisions = drd_divisions;
             o.drd_refinements = drd_refinements;
             o.drd_bisections = drd_bisections;
             py::gil_scoped_release release;
             return std::make_shared<tmm::MultipointPositioner>(std::move(surface), tool, o);
           }),
           py::arg("surface"), py::arg("Ro"), py::arg("Ri"), py::arg("shape") = "round_insert",
           py::arg("method") = "vcrf", py::arg("rotation") = "pseudo_insert",
           py::arg("beta_max") = 0.7853981633974483, py::arg("tol") = 1e-3, py::arg("sample_spacing") = 0.0,
           py::arg("divisions") = 6, py::arg("refinements") = 1, py::arg("drd_divisions") = 10,
           py::arg("drd_refinements") = 5, py::arg("drd_bisections") = 16, py::arg("extend") = 0.0,
           py::arg("anchor") = "axis", py::arg("anchor_iterations") = 12)
      .def("position_batch",
           [](const tmm::MultipointPositioner& mp, const Arr& xy_in, int threads, const py::object& progress) {
             const Arr xy = check_points(xy_in, 2, "footprint points");
             const std::size_t n = static_cast<std::size_t>(xy.shape(0));
             std::vector<tmm::MultipointResult> res(n);
             tmm::BatchOptions options;
             options.threads = threads;
             options.progress = python_progress(progress);
             {
               py::gil_scoped_release release;
               mp.position_batch(xy.data(), n, res.data(), options);
             }
             py::array_t<int> status(static_cast<py::ssize_t>(n)), reason(static_cast<py::ssize_t>(n)),
                 evals(static_cast<py::ssize_t>(n));
             py::array_t<double> beta(static_cast<py::ssize_t>(n)), drop_z(static_cast<py::ssize_t>(n)),
                 gap_P(static_cast<py::ssize_t>(n)), gap_Q(static_cast<py::ssize_t>(n)),
                 pen(static_cast<py::ssize_t>(n)), seed_angle(static_cast<py::ssize_t>(n)),
                 anchor_error(static_cast<py::ssize_t>(n)), pen_real(static_cast<py::ssize_t>(n));
             py::array_t<int> on_ext(static_cast<py::ssize_t>(n));
             py::array_t<double> tip = rows3(n), axis = rows3(n), centre = rows3(n), P = rows3(n), nP = rows3(n),
                                 Q = rows3(n), nQ = rows3(n), seed_axis = rows3(n);
             py::array_t<double> axis_xy({static_cast<py::ssize_t>(n), py::ssize_t{2}});
             py::array_t<double> uvP({static_cast<py::ssize_t>(n), py::ssize_t{2}}),
                 uvQ({static_cast<py::ssize_t>(n), py::ssize_t{2}});
             auto put3 = [](py::array_t<double>& a, std::size_t i, const Eigen::Vector3d& v) {
               double* d = a.mutable_data();
               for (int c = 0; c < 3; ++c) d[3 * i + static_cast<std::size_t>(c)] = v[c];
             };
             for (std::size_t i = 0; i < n; ++i) {
               const auto& r = res[i];
               status.mutable_data()[i] = static_cast<int>(r.status);
               reason.mutable_data()[i] = static_cast<int>(r.reason);
               evals.mutable_data()[i] = r.evaluations;
               beta.mutable_data()[i] = r.beta;
               drop_z.mutable_data()[i] = r.drop_z;
               gap_P.mutable_data()[i] = r.gap_P;
               gap_Q.mutable_data()[i] = r.gap_Q;
               pen.mutable_data()[i] = r.penetration;
               seed_angle.mutable_data()[i] = r.seed_axis_angle;
               anchor_error.mutable_data()[i] = r.anchor_error;
               pen_real.mutable_data()[i] = r.penetration_real;
               on_ext.mutable_data()[i] = (r.P_extension ? 1 : 0) | (r.Q_extension ? 2 : 0);
               axis_xy.mutable_data()[2 * i] = r.axis_xy.x();
               axis_xy.mutable_data()[2 * i + 1] = r.axis_xy.y();
               put3(tip, i, r.tip);
               put3(axis, i, r.axis);
               put3(centre, i, r.centre);
               put3(P, i, r.P);
               put3(nP, i, r.nP);
               put3(Q, i, r.Q);
               put3(nQ, i, r.nQ);
               put3(seed_axis, i, r.seed_axis);
               uvP.mutable_data()[2 * i] = r.uvP.x();
               uvP.mutable_data()[2 * i + 1] = r.uvP.y();
               uvQ.mutable_data()[2 * i] = r.uvQ.x();
               uvQ.mutable_data()[2 * i + 1] = r.uvQ.y();
             }
             py::dict out;
             out["status"] = status;
             out["reason"] = reason;
             out["evaluations"] = evals;
             out["beta"] = beta;
             out["drop_z"] = drop_z;
             out["gap_P"] = gap_P;
             out["gap_Q"] = gap_Q;
             out["penetration"] = pen;
             out["seed_axis_angle"] = seed_angle;
             out["tip"] = tip;
             out["axis"] = axis;
             out["centre"] = centre;
             out["P"] = P;
             out["nP"] = nP;
             out["Q"] = Q;
             out["nQ"] = nQ;
             out["seed_axis"] = seed_axis;
             out["uvP"] = uvP;
             out["uvQ"] = uvQ;
             out["axis_xy"] = axis_xy;
             out["anchor_error"] = anchor_error;
             out["penetration_real"] = pen_real;
             out["on_extension"] = on_ext;
             return out;
           },
           py::arg("xy"), py::arg("threads") = 0, py::arg("progress") = py::none(),
           "Position the tool at the (n, 2) footprint points; dict of arrays (status 0 two contacts, 1 one "
           "contact, 2 failed; reason codes: multipoint_reasons(); axis_xy: the pre-tilt axis point positioned; "
           "anchor_error: |tip_xy - footprint point| for anchor 'tip'; penetration_real: into the real face; "
           "on_extension: bit 1 P, bit 2 Q on the surface extension). progress(fraction) -> bool; False cancels.")
      .def("tool_distance",
           [](const tmm::MultipointPositioner& mp, const Eigen::Vector3d& tip, const Eigen::Vector3d& axis,
              const Arr& pts_in) {
             const Arr pts = check_points(pts_in, 3, "points");
             const std::size_t n = static_cast<std::size_t>(pts.shape(0));
             py::array_t<double> d(static_cast<py::ssize_t>(n));
             const Eigen::Vector3d a = axis.normalized();
             for (std::size_t i = 0; i < n; ++i) {
               const double* p = pts.data() + 3 * i;
               d.mutable_data()[i] = tmm::tool_distance(mp.tool(), tip, a, Eigen::Vector3d(p[0], p[1], p[2]));
             }
             return d;
           },
           py::arg("tip"), py::arg("axis"), py::arg("points"),
           "Signed distance (n,) of points to the tool solid at (tip, axis): negative inside.")
      .def_property_readonly("sample_count", [](const tmm::MultipointPositioner& mp) { return mp.samples().points().size(); })
      .def_property_readonly("sample_spacing", [](const tmm::MultipointPositioner& mp) { return mp.samples().spacing(); });
}
