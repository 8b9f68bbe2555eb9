#include "tmm/cutter/torus_tool.hpp"

#include <Eigen/Geometry>

#include <algorithm>
#include <cmath>
#include <sstream>
#include <stdexcept>
#include <utility>

#include "tmm/util/range.hpp"

namespace tmm {

using Eigen::Matrix3d;
using Eigen::Vector3d;

namespace {

// A unit vector perpendicular to a.
Vector3d any_perpendicular(const Vector3d& a) {
  const Vector3d t = std::abs(a.x()) < 0.9 ? Vector3d::UnitX() : Vector3d::UnitY();
  return (t - t.dot(a) * a).normalized();
}

// Distance to the circle of radius R about the axis in the plane h = 0, from local (rho, h) coordinates:
// n = unit vector from the nearest circle point, Hessian of the distance function (a torus level set:
// principal curvatures 1/r across, cos(theta)/rho along the circle).
double circle_distance(double R, double rho, double h, const Vector3d& e, const Vector3d& a,
                       const Vector3d& t, Vector3d* grad, Matrix3d* hess) {
  const Vector3d w = (rho - R) * e + h * a;
  const double r = w.norm();
  if (r < 1e-300) {
    if (grad) *grad = -a;
    if (hess) hess->setZero();
    return 0.0;
  }
  const Vector3d n = w / r;
  if (grad) *grad = n;
  if (hess) {
    const Vector3d b = n.cross(t);
    *hess = (b * b.transpose()) / r;
    if (rho > 1e-12) *hess += (n.dot(e) / rho) * (t * t.transpose());
  }
  return r;
}

}  // namespace

namespace {

// Finite radii, Ro >= 0, Ri > 0 (or >= 0 with flat_ok), within the kernel's length range.
void require_radii(double Ro, double Ri, bool flat_ok) {
  for (const auto& [name, value] : {std::pair<const char*, double>{"major radius Ro", Ro}, {"minor radius Ri", Ri}}) {
    if (!std::isfinite(value)) {
      std::ostringstream msg;
      msg << name << " must be finite, got " << value;
      throw std::invalid_argument(msg.str());
    }
  }
  if (Ro < 0.0) throw std::invalid_argument("major radius Ro must be >= 0 (0 is a ball end mill)");
  if (flat_ok && Ri < 0.0) throw std::invalid_argument("minor radius Ri must be >= 0 (0 is a flat end mill)");
  if (!flat_ok && Ri <= 0.0) {
    throw std::invalid_argument(
        "minor radius Ri must be > 0: a flat end mill (Ri = 0) has no pseudo-insert to tilt about, "
        "multipoint positioning needs a toroidal (or ball) cutter");
  }
  require_length(Ro, "major radius Ro");
  if (Ri > 0.0) require_length(Ri, "minor radius Ri");
}

}  // namespace

void TorusTool::validate() const { require_radii(Ro, Ri, false); }

void TorusTool::validate_solid() const {
  require_radii(Ro, Ri, true);
  if (Ri == 0.0 && !(shape == ToolShape::BullNose && Ro > 0.0)) {
    throw std::invalid_argument("a tool with minor radius Ri = 0 must be a bull-nose (flat end mill) with Ro > 0");
  }
}

double TorusTool::profile(double rho) const {
  rho = std::abs(rho);
  if (shape == ToolShape::BullNose && rho <= Ro) return 0.0;
  if (shape == ToolShape::RoundInsert && rho < Ro - Ri) return Ri;  // body over the hollow centre
  const double t = rho - Ro;
  return Ri - std::sqrt(std::fmax(Ri * Ri - t * t, 0.0));
}

double tool_distance(const TorusTool& tool, const Vector3d& tip, const Vector3d& axis, const Vector3d& x,
                     Vector3d* grad, Matrix3d* hess) {
  const double Ro = tool.Ro, Ri = tool.Ri, Rt = Ro + Ri;
  const Vector3d d = x - (tip + Ri * axis);
  const double h = d.dot(axis);  // height above the centre plane
  if (!grad && !hess) {
    // Value only (the gouge scans): no frame vectors.
    const double rho = std::sqrt(std::max(d.squaredNorm() - h * h, 0.0));
    if (tool.shape == ToolShape::BullNose) {
      const double drho = std::max(rho - Ro, 0.0), dh = std::max(-h, 0.0);
      if (drho > 0.0 || dh > 0.0) return std::sqrt(drho * drho + dh * dh) - Ri;
      return -std::min(Ro - rho, h) - Ri;
    }
    const double dt = std::sqrt((rho - Ro) * (rho - Ro) + h * h) - Ri;
    double db;
    if (rho <= Rt) db = (h >= 0.0) ? -std::min(h, Rt - rho) : -h;
    else db = (h >= 0.0) ? rho - Rt : std::sqrt((rho - Rt) * (rho - Rt) + h * h);
    return std::min(dt, db);
  }
  const Vector3d q = d - h * axis;
  const double rho = q.norm();
  const Vector3d e = rho > 1e-12 ? Vector3d(q / rho) : any_perpendicular(axis);
  const Vector3d t = axis.cross(e);
  auto plane = [&](double value) {  // -h - value: below the plane h = -value... gradient -axis
    if (grad) *grad = -axis;
    if (hess) hess->setZero();
    return value;
  };
  auto cylinder = [&](double value) {  // rho - const
    if (grad) *grad = e;
    if (hess) *hess = rho > 1e-12 ? Matrix3d((t * t.transpose()) / rho) : Matrix3d::Zero();
    return value;
  };
  if (tool.shape == ToolShape::BullNose) {
    const double drho = std::max(rho - Ro, 0.0), dh = std::max(-h, 0.0);
    if (drho > 0.0 && dh > 0.0) return circle_distance(Ro, rho, h, e, axis, t, grad, hess) - Ri;
    if (dh > 0.0) return plane(-h - Ri);
    if (drho > 0.0) return cylinder(rho - Ro - Ri);
    return (Ro - rho < h) ? cylinder(rho - Ro - Ri) : plane(-h - Ri);
  }
  // Round insert: min(full torus, body {h >= 0, rho <= Rt}).
  Vector3d g1;
  Matrix3d H1;
  const double dt = circle_distance(Ro, rho, h, e, axis, t, &g1, hess ? &H1 : nullptr) - Ri;
  double db;
  int piece;  // 0 plane below, 1 wall, 2 corner circle
  if (rho <= Rt) {
    if (h >= 0.0) {
      if (h < Rt - rho) {
        db = -h;
        piece = 0;
      } else {
        db = rho - Rt;
        piece = 1;
      }
    } else {
      db = -h;
      piece = 0;
    }
  } else if (h >= 0.0) {
    db = rho - Rt;
    piece = 1;
  } else {
    db = std::hypot(rho - Rt, h);
    piece = 2;
  }
  if (dt <= db) {
    if (grad) *grad = g1;
    if (hess) *hess = H1;
    return dt;
  }
  if (piece == 0) return plane(db);
  if (piece == 1) return cylinder(db);
  return circle_distance(Rt, rho, h, e, axis, t, grad, hess);
}

}  // namespace tmm
