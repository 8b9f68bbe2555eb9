// Python binding of multipoint positioning (tmm/position/multipoint.hpp): the options as one class, the
// positioner built from a surface and the options.
#include <pybind11/eigen.h>
#include <pybind11/functional.h>
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include <memory>
#include <sstream>
#include <string>
#include <utility>
#include <vector>

#include "tmm/position/multipoint.hpp"
#include "util/arrays.hpp"
#include "util/progress.hpp"

namespace py = pybind11;
using tmm_bindings::Arr;
using tmm_bindings::check_points;
using tmm_bindings::python_progress;
using tmm_bindings::rows3;

namespace {

// The tool and the kernel's options, as Python sees them (one object, enums as names).
struct Options {
  tmm::TorusTool tool;
  tmm::MultipointOptions kernel;
};

template <class E>
using Names = std::vector<std::pair<std::string, E>>;

const Names<tmm::ToolShape> kShapes = {{"round_insert", tmm::ToolShape::RoundInsert},
                                       {"bull_nose", tmm::ToolShape::BullNose}};
const Names<tmm::MultipointMethod> kMethods = {{"vcrf", tmm::MultipointMethod::VCRF},
                                               {"drd", tmm::MultipointMethod::DRD}};
const Names<tmm::TiltRotation> kRotations = {{"pseudo_insert", tmm::TiltRotation::PseudoInsert},
                                             {"global_x", tmm::TiltRotation::GlobalX}};
const Names<tmm::FootprintAnchor> kAnchors = {{"axis", tmm::FootprintAnchor::Axis}, {"tip", tmm::FootprintAnchor::Tip}};

template <class E>
E parse(const Names<E>& names, const char* what, const std::string& name) {
  for (const auto& [n, e] : names)
    if (n == name) return e;
  std::ostringstream msg;
  msg << what << " must be";
  for (std::size_t i = 0; i < names.size(); ++i) msg << (i == 0 ? " '" : i + 1 == names.size() ? " or '" : ", '") << names[i].first << "'";
  msg << ", got '" << name << "'";
  throw std::invalid_argument(msg.str());
}

template <class E>
const std::string& name_of(const Names<E>& names, E e) {
  for (const auto& [n, v] : names)
    if (v == e) return n;
  throw std::logic_error("unnamed enum value");
}

// A readable and writable field of the kernel's options.
template <class T>
void field(py::class_<Options>& c, const char* name, T tmm::MultipointOptions::*member, const char* doc) {
  c.def_property(name, [member](const Options& o) { return o.kernel.*member; },
                 [member](Options& o, T v) { o.kernel.*member = v; }, doc);
}

// A field holding an enum, read and written by name.
template <class E, class Owner>
void named_field(py::class_<Options>& c, const char* name, E Owner::*member, Owner Options::*owner,
                 const Names<E>& names) {
  c.def_property(
      name, [=](const Options& o) { return name_of(names, (o.*owner).*member); },
      [=](Options& o, const std::string& v) { (o.*owner).*member = parse(names, name, v); });
}

// The positions as a dict of arrays, one row per footprint point.
py::dict results_dict(const std::vector<tmm::MultipointResult>& res) {
  const std::size_t n = res.size();
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
}

py::dict position_batch(const tmm::MultipointPositioner& mp, const Arr& xy_in, int threads,
                        const py::object& progress) {
  const Arr xy = check_points(xy_in, 2, "footprint points");
  tmm_bindings::check_range(xy, "footprint points");
  const std::size_t n = static_cast<std::size_t>(xy.shape(0));
  std::vector<tmm::MultipointResult> res(n);
  tmm::BatchOptions options;
  options.threads = threads;
  options.progress = python_progress(progress);
  {
    py::gil_scoped_release release;
    mp.position_batch(xy.data(), n, res.data(), options);
  }
  return results_dict(res);
}

py::array_t<double> tool_distance(const tmm::MultipointPositioner& mp, const Eigen::Vector3d& tip,
                                  const Eigen::Vector3d& axis, const Arr& pts_in) {
  const Arr pts = check_points(pts_in, 3, "points");
  tmm_bindings::check_range(pts, "points");
  tmm::require_rows_in_range(tip.data(), 1, 3, "tip");
  if (!(axis.allFinite() && axis.norm() > 0.0)) throw std::invalid_argument("axis must be a finite direction");
  const std::size_t n = static_cast<std::size_t>(pts.shape(0));
  py::array_t<double> d(static_cast<py::ssize_t>(n));
  const Eigen::Vector3d a = axis.normalized();
  for (std::size_t i = 0; i < n; ++i) {
    const double* p = pts.data() + 3 * i;
    d.mutable_data()[i] = tmm::tool_distance(mp.tool(), tip, a, Eigen::Vector3d(p[0], p[1], p[2]));
  }
  return d;
}

py::array_t<double> clearance(const tmm::MultipointPositioner& mp, const Arr& tips_in, const Arr& axes_in,
                              int threads) {
  const Arr tips = check_points(tips_in, 3, "tips");
  const Arr axes = check_points(axes_in, 3, "axes");
  const std::size_t n = static_cast<std::size_t>(tips.shape(0));
  if (static_cast<std::size_t>(axes.shape(0)) != n)
    throw std::invalid_argument("tips and axes must have as many rows");
  py::array_t<double> out(static_cast<py::ssize_t>(n));
  double* o = out.mutable_data();
  const double* t = tips.data();
  const double* a = axes.data();
  for (std::size_t i = 0; i < n; ++i) {
    const Eigen::Vector3d ti(t[3 * i], t[3 * i + 1], t[3 * i + 2]), ai(a[3 * i], a[3 * i + 1], a[3 * i + 2]);
    if (!ti.allFinite()) throw std::invalid_argument("tips: row " + std::to_string(i) + " is not finite");
    tmm::require_rows_in_range(t + 3 * i, 1, 3, "tips: row " + std::to_string(i) + ", as");
    if (!(ai.allFinite() && ai.norm() > 0.0))
      throw std::invalid_argument("axes: row " + std::to_string(i) + " is not a direction");
  }
  tmm::BatchOptions options;
  options.threads = threads;
  options.progress = python_progress(py::none());  // Ctrl-C
  {
    py::gil_scoped_release release;
    tmm::parallel_chunks(n, 16, options, [&](std::size_t begin, std::size_t end) {
      for (std::size_t i = begin; i < end; ++i) {
        const Eigen::Vector3d axis = Eigen::Vector3d(a[3 * i], a[3 * i + 1], a[3 * i + 2]).normalized();
        o[i] = mp.clearance_real(Eigen::Vector3d(t[3 * i], t[3 * i + 1], t[3 * i + 2]), axis, nullptr,
                                 nullptr);
      }
    });
  }
  return out;
}

// MultipointOptions: keyword-constructible, every field readable and writable (enums by name).
void bind_options(py::module_& m) {
  const tmm::MultipointOptions defaults;  // the kernel's
  py::class_<Options> opts(m, "MultipointOptions",
      "Tool and options of multipoint positioning. Keyword-constructible; every field readable and writable. "
      "Checked (ValueError naming the option) when a MultipointPositioner is built.");
  opts.def(py::init([](double Ro, double Ri, const std::string& shape, const std::string& method,
                          const std::string& rotation, double beta_max, double tol, double sample_spacing,
                          int divisions, int refinements, int drd_divisions, int drd_refinements,
                          int drd_bisections, double extend, const std::string& anchor, int anchor_iterations) {
                Options o;
                o.tool.Ro = Ro;
                o.tool.Ri = Ri;
                o.tool.shape = parse(kShapes, "shape", shape);
                o.kernel.method = parse(kMethods, "method", method);
                o.kernel.rotation = parse(kRotations, "rotation", rotation);
                o.kernel.beta_max = beta_max;
                o.kernel.tol = tol;
                o.kernel.sample_spacing = sample_spacing;
                o.kernel.divisions = divisions;
                o.kernel.refinements = refinements;
                o.kernel.drd_divisions = drd_divisions;
                o.kernel.drd_refinements = drd_refinements;
                o.kernel.drd_bisections = drd_bisections;
                o.kernel.extend = extend;
                o.kernel.anchor = parse(kAnchors, "anchor", anchor);
                o.kernel.anchor_iterations = anchor_iterations;
                return o;
              }),
              py::kw_only(), py::arg("Ro") = 0.0, py::arg("Ri") = 0.0, py::arg("shape") = "round_insert",
              py::arg("method") = "vcrf", py::arg("rotation") = "pseudo_insert", py::arg("beta_max") = defaults.beta_max,
              py::arg("tol") = defaults.tol, py::arg("sample_spacing") = defaults.sample_spacing,
              py::arg("divisions") = defaults.divisions, py::arg("refinements") = defaults.refinements,
              py::arg("drd_divisions") = defaults.drd_divisions, py::arg("drd_refinements") = defaults.drd_refinements,
              py::arg("drd_bisections") = defaults.drd_bisections, py::arg("extend") = defaults.extend,
              py::arg("anchor") = "axis", py::arg("anchor_iterations") = defaults.anchor_iterations);
  opts.def_property(
      "Ro", [](const Options& o) { return o.tool.Ro; }, [](Options& o, double v) { o.tool.Ro = v; },
      "major radius (mm): axis to the pseudo-insert's centre; 0 is a ball");
  opts.def_property(
      "Ri", [](const Options& o) { return o.tool.Ri; }, [](Options& o, double v) { o.tool.Ri = v; },
      "minor radius (mm): the pseudo-insert's (> 0)");
  named_field(opts, "shape", &tmm::TorusTool::shape, &Options::tool, kShapes);
  named_field(opts, "method", &tmm::MultipointOptions::method, &Options::kernel, kMethods);
  named_field(opts, "rotation", &tmm::MultipointOptions::rotation, &Options::kernel, kRotations);
  named_field(opts, "anchor", &tmm::MultipointOptions::anchor, &Options::kernel, kAnchors);
  field(opts, "beta_max", &tmm::MultipointOptions::beta_max, "tilt limit (rad), in (0, pi/2)");
  field(opts, "tol", &tmm::MultipointOptions::tol, "contact gap and penetration tolerance (mm)");
  field(opts, "sample_spacing", &tmm::MultipointOptions::sample_spacing, "surface samples (mm); 0: (Ro + Ri) / 8");
  field(opts, "divisions", &tmm::MultipointOptions::divisions, "VCRF zoom grid divisions");
  field(opts, "refinements", &tmm::MultipointOptions::refinements, "VCRF zoom levels");
  field(opts, "drd_divisions", &tmm::MultipointOptions::drd_divisions, "DRD rays per direction");
  field(opts, "drd_refinements", &tmm::MultipointOptions::drd_refinements, "DRD zoom levels");
  field(opts, "drd_bisections", &tmm::MultipointOptions::drd_bisections, "DRD bisections of the tilt");
  field(opts, "extend", &tmm::MultipointOptions::extend, "surface extension past the face's edges (mm)");
  field(opts, "anchor_iterations", &tmm::MultipointOptions::anchor_iterations, "tip anchor: positions per point");
  opts.def("__repr__", [](const Options& o) {
    std::ostringstream r;
    r.precision(17);
    const tmm::MultipointOptions& k = o.kernel;
    r << "MultipointOptions(Ro=" << o.tool.Ro << ", Ri=" << o.tool.Ri << ", shape='" << name_of(kShapes, o.tool.shape)
      << "', method='" << name_of(kMethods, k.method) << "', rotation='" << name_of(kRotations, k.rotation)
      << "', beta_max=" << k.beta_max << ", tol=" << k.tol << ", sample_spacing=" << k.sample_spacing
      << ", divisions=" << k.divisions << ", refinements=" << k.refinements << ", drd_divisions=" << k.drd_divisions
      << ", drd_refinements=" << k.drd_refinements << ", drd_bisections=" << k.drd_bisections
      << ", extend=" << k.extend << ", anchor='" << name_of(kAnchors, k.anchor)
      << "', anchor_iterations=" << k.anchor_iterations << ")";
    return r.str();
  });
}

}  // namespace

void bind_multipoint(py::module_& m) {
  m.def("multipoint_reasons", &tmm::multipoint_reason_text, "Text of each multipoint reason code.");
  bind_options(m);

  py::class_<tmm::MultipointPositioner, std::shared_ptr<tmm::MultipointPositioner>>(m, "MultipointPositioner",
      "Multipoint positioning of a toroidal cutter on a PatchSurface (seed 001: VCRF or DRD).")
      .def(py::init([](std::shared_ptr<tmm::PatchSurface> surface, const Options& o, const py::object& progress) {
             const auto report = python_progress(progress);
             py::gil_scoped_release release;
             return std::make_shared<tmm::MultipointPositioner>(std::move(surface), o.tool, o.kernel, report);
           }),
           py::arg("surface"), py::arg("options"), py::arg("progress") = py::none(),
           "ValueError naming the option for an invalid tool or option (NaN and infinities included). "
           "progress(fraction) -> bool while the surface samples are built; False cancels (raises Cancelled).")
      .def_property_readonly("options", [](const tmm::MultipointPositioner& mp) { return Options{mp.tool(), mp.options()}; })
      .def("position_batch", &position_batch,
           py::arg("xy"), py::arg("threads") = 0, py::arg("progress") = py::none(),
           "Position the tool at the (n, 2) footprint points; dict of arrays (status 0 two contacts, 1 one "
           "contact, 2 failed; reason codes: multipoint_reasons(); axis_xy: the pre-tilt axis point positioned; "
           "anchor_error: |tip_xy - footprint point| for anchor 'tip'; penetration_real: into the real face; "
           "on_extension: bit 1 P, bit 2 Q on the surface extension). progress(fraction) -> bool; False cancels.")
      .def("tool_distance", &tool_distance,
           py::arg("tip"), py::arg("axis"), py::arg("points"),
           "Signed distance (n,) of points to the tool solid at (tip, axis): negative inside.")
      .def("clearance", &clearance,
           py::arg("tips"), py::arg("axes"), py::arg("threads") = 0,
           "Signed clearance (n,) of the real face from the tool at each (tip, axis): the smallest signed "
           "distance from the face to the tool solid, negative when the face is inside the tool (a gouge), "
           "positive the gap left (exact by Newton within Ri of the tool; +inf where the tool is off the face).")
      .def_property_readonly("sample_count", [](const tmm::MultipointPositioner& mp) { return mp.samples().points().size(); })
      .def_property_readonly("sample_spacing", [](const tmm::MultipointPositioner& mp) { return mp.samples().spacing(); });
}
