// Drop along any direction V with the cutter axis in any orientation. Method (docs/drop_direction.md):
// everything is worked in the tool frame with the start tip at the origin; a triangle point q touches the
// cutter at travel t when q - t W lies in the convex solid K (W = V in tool coordinates).
//   vertex: entry of the line q - t W into K. On the part of the line inside the cylinder rho <= max_radius
//           and the slab 0 <= z <= L_C, f(t) = max(h(rho(t)) - z(t), z(t) - L_C) is convex; its first zero is
//           found by golden section (down to a point with f <= 0) then Illinois regula falsi, 1e-12 in t.
//   facet:  the support point of K against the plane (Cutter::facet_contact_radius, or the top rim) gives the
//           travel in closed form; valid if that point, moved to the plane, lies inside the triangle.
//   edge:   the first contact of the whole edge line, by projecting along the edge: the line becomes a point
//           moving into the shadow of K, whose entry time is the maximum over the shadow's supporting lines
//           (normals N perpendicular to the edge) of their crossing times — a quasi-concave function of the
//           normal's direction, maximised by golden section. Every sampled crossing time is a lower bound, so the
//           answer never lies past the true contact. Valid if the contact point lies on the segment; else the
//           convex travel along the edge is smallest at an end, which the vertex case covers.
#include "tmm/query/drop_direction.hpp"

#include <Eigen/Geometry>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <sstream>
#include <stdexcept>
#include <thread>
#include <vector>

#include "tmm/query/drop_contacts.hpp"
#include "tmm/util/range.hpp"

namespace tmm {

using Eigen::Vector3d;

namespace {

constexpr double kInfinity = std::numeric_limits<double>::infinity();
constexpr double kTravelTol = 1e-12;       // mm, bracket width of the vertex entry
constexpr double kUnitTol = 1e-9;          // |norm - 1| accepted for axis and direction
using direction_detail::kParallelAxisTol;
using direction_detail::require_finite_length;
using direction_detail::require_unit;

}  // namespace

ToolFrame::ToolFrame(const Vector3d& axis) : a(axis.normalized()) {
  // For axis = +Z exactly this is the world frame, so the -Z drop is reproduced bit for bit.
  const Vector3d ref = std::fabs(a.x()) < 0.9 ? Vector3d::UnitX() : Vector3d::UnitY();
  e1 = (ref - ref.dot(a) * a).normalized();
  e2 = a.cross(e1);
}

namespace direction_detail {

void require_unit(const Vector3d& v, const char* what) {
  const double n = v.norm();
  if (!(std::isfinite(n) && std::fabs(n - 1.0) <= kUnitTol)) {
    std::ostringstream msg;
    msg << what << " must be a finite unit vector, got (" << v.x() << ", " << v.y() << ", " << v.z()
        << ") of length " << n;
    throw std::invalid_argument(msg.str());
  }
}

Support support(const Cutter& c, const Vector3d& d_in) {
  // (sqrt of sums of squares rather than hypot: this is the inner loop of the edge solver.)
  const double h2 = d_in.x() * d_in.x() + d_in.y() * d_in.y();
  const double inv = 1.0 / std::sqrt(h2 + d_in.z() * d_in.z());
  const double hl = std::sqrt(h2);
  const Vector3d d = d_in * inv;
  const double nr = hl * inv;
  const double ux = hl > 0 ? d_in.x() / hl : 1.0, uy = hl > 0 ? d_in.y() / hl : 0.0;
  double rho, z;
  if (d.z() > 0) {  // upwards: the top rim (the cap's centre when d is the axis itself)
    const double Lc = c.cutting_length();
    if (!std::isfinite(Lc)) return {Vector3d(0, 0, kInfinity), kInfinity};
    rho = nr > 0 ? c.max_radius() : 0.0;
    z = Lc;
  } else if (d.z() == 0) {  // sideways: the widest circle (its lowest point when it is a cylinder band)
    rho = c.max_radius();
    z = c.height(rho);
  } else {  // downwards: the profile point whose outward normal is d
    rho = c.facet_contact_radius(nr, -d.z());
    z = c.height(rho);
  }
  const Vector3d X(rho * ux, rho * uy, z);
  return {X, d_in.dot(X)};
}

double vertex_travel(const Cutter& c, const Vector3d& q, const Vector3d& W, double cap) {
  if (q.dot(W) - support(c, W).value >= cap) return kNoTravel;  // as in edge_travel
  const double rmax = c.max_radius(), Lc = c.cutting_length();
  const double wxy2 = W.x() * W.x() + W.y() * W.y();
  if (wxy2 <= 1e-28) {  // moving along the axis: rho is constant
    const double rho = std::hypot(q.x(), q.y());
    if (rho > rmax) return kNoTravel;
    double t;
    if (W.z() < 0) t = (q.z() - c.height(rho)) / W.z();  // rises into the lower surface
    else if (!std::isfinite(Lc)) t = -kInfinity;         // inside the endless cutter from the start
    else t = (q.z() - Lc) / W.z();                       // falls through the top cap
    return t < cap ? t : kNoTravel;
  }
  // The line's part inside the cylinder rho <= rmax...
  const double tc = (q.x() * W.x() + q.y() * W.y()) / wxy2;
  const double dx = q.x() - tc * W.x(), dy = q.y() - tc * W.y();
  const double d2 = dx * dx + dy * dy;
  if (d2 > rmax * rmax) return kNoTravel;
  const double half = std::sqrt((rmax * rmax - d2) / wxy2);
  double lo = tc - half, hi = tc + half;
  // ...and the slab 0 <= z(t) <= L_C, z(t) = q.z - t W.z.
  if (W.z() > 0) {
    lo = std::max(lo, (q.z() - Lc) / W.z());
    hi = std::min(hi, q.z() / W.z());
  } else if (W.z() < 0) {
    lo = std::max(lo, q.z() / W.z());
    hi = std::min(hi, (q.z() - Lc) / W.z());
  } else if (q.z() < 0 || q.z() > Lc) {
    return kNoTravel;
  }
  hi = std::min(hi, cap);  // only an earlier contact matters
  if (!(lo < hi)) return kNoTravel;
  // f <= 0 exactly inside K; convex in t (h convex non-decreasing, rho convex, the cap linear).
  auto f = [&](double t) {
    const double z = q.z() - t * W.z();
    const double x = q.x() - t * W.x(), y = q.y() - t * W.y();
    const double rho = std::min(std::sqrt(x * x + y * y), rmax);
    return std::max(c.height(rho) - z, z - Lc);
  };
  // Whether the left derivative of f at t is <= 0 (every active term non-increasing); false when unsure.
  auto nonincreasing_at = [&](double t) {
    const double z = q.z() - t * W.z();
    const double x = q.x() - t * W.x(), y = q.y() - t * W.y();
    const double rho = std::sqrt(x * x + y * y);
    if (!(rho > 0)) return false;  // the cone's kink on the axis
    const double rr = std::min(rho, rmax);
    const double low = c.height(rr) - z, top = z - Lc;
    bool ok = true;
    if (low >= top) ok = c.slope(rr) * (-(x * W.x() + y * W.y()) / rho) + W.z() <= 0;  // NaN: false
    if (top >= low) ok = ok && -W.z() <= 0;
    return ok;
  };
  double flo = f(lo);
  if (flo <= 0) return lo;  // enters through the side wall or the top cap
  // A point inside: golden section on the convex f, stopping at the first f <= 0.
  double inside = std::nan("");
  const double fhi = f(hi);
  if (fhi <= 0) {
    inside = hi;
  } else if (nonincreasing_at(hi)) {
    // f'(hi-) <= 0: f >= f(hi) > 0 on the whole interval (convexity), no contact before hi.
  } else {
    const double g = 0.5 * (std::sqrt(5.0) - 1.0);
    double a = lo, b = hi;
    double x1 = b - g * (b - a), x2 = a + g * (b - a);
    double f1 = f(x1), f2 = f(x2);
    for (int it = 0; it < 200; ++it) {
      if (f1 <= 0) { inside = x1; break; }
      if (f2 <= 0) { inside = x2; break; }
      if (b - a <= kTravelTol) break;
      if (f1 < f2) {
        b = x2; x2 = x1; f2 = f1;
        x1 = b - g * (b - a); f1 = f(x1);
      } else {
        a = x1; x1 = x2; f1 = f2;
        x2 = a + g * (b - a); f2 = f(x2);
      }
    }
  }
  if (std::isnan(inside)) return kNoTravel;  // the line passes K by (its minimum of f is > 0)
  // The single crossing in (lo, inside]: Illinois regula falsi, keeping the outside end as the answer so
  // the cutter never ends inside the triangle.
  double a = lo, b = inside, fa = flo, fb = f(inside);
  int side = 0;
  for (int it = 0; it < 200 && b - a > kTravelTol + 4e-16 * std::fabs(a); ++it) {
    double m = (fa * b - fb * a) / (fa - fb);
    if (!(m > a && m < b)) m = 0.5 * (a + b);
    if (it % 8 == 7) m = 0.5 * (a + b);  // guaranteed halving now and then
    const double fm = f(m);
    if (fm > 0) {
      a = m; fa = fm;
      if (side == -1) fb *= 0.5;
      side = -1;
    } else {
      b = m; fb = fm;
      if (side == 1) fa *= 0.5;
      side = 1;
    }
  }
  return a;
}

double edge_travel(const Cutter& c, const Vector3d& q1, const Vector3d& q2, const Vector3d& W, double cap,
                   Vector3d* contact_normal) {
  // Cheap bound first: q(s) - t W = X in K gives t = (q(s) - X) . W >= min q . W - max_K X . W.
  if (std::min(q1.dot(W), q2.dot(W)) - support(c, W).value >= cap) return kNoTravel;
  const Vector3d E = q2 - q1;
  const double L = E.norm();
  if (!(L > 0)) return kNoTravel;
  const Vector3d e = E / L;
  const Vector3d Wp = W - W.dot(e) * e;  // the motion seen along the edge
  const double wp = Wp.norm();
  if (wp < 1e-13) return kNoTravel;  // sliding along itself: an end touches first (vertex case)
  const Vector3d v = Wp / wp, w = e.cross(v);
  // The path must pass between the shadow's two supporting lines parallel to the motion.
  if (w.dot(q1) > support(c, w).value || -w.dot(q1) > support(c, -w).value) return kNoTravel;
  // Crossing time of the supporting line with normal N(tau) = (1 - tau^2) v + 2 tau w, tau in (-1, 1): the
  // half-angle tangent of theta in (-pi/2, pi/2), so no trigonometry; the ratio does not need |N| = 1.
  auto normal = [&](double tau) { return Vector3d((1 - tau * tau) * v + (2 * tau) * w); };
  auto crossing = [&](double tau, Support* s) {
    const Vector3d N = normal(tau);
    const Support sp = support(c, N);
    if (s) *s = sp;
    return (N.dot(q1) - sp.value) / (wp * (1 - tau * tau));
  };
  // Golden section to a bracket of ~1e-12 in tau: the crossing times are smooth at a maximum on a curved
  // part of K and flat (a plateau) at a corner, so the travel is within ~1e-11 mm, and never late.
  const double g = 0.5 * (std::sqrt(5.0) - 1.0);
  double a = -1.0, b = 1.0;
  double x1 = b - g * (b - a), x2 = a + g * (b - a);
  double f1 = crossing(x1, nullptr), f2 = crossing(x2, nullptr);
  double best_th = f1 >= f2 ? x1 : x2, best = std::max(f1, f2);
  for (int it = 0; it < 60 && b - a > 1e-13; ++it) {
    if (best >= cap) return kNoTravel;  // every crossing time bounds the contact from below
    if (f1 >= f2) {
      b = x2; x2 = x1; f2 = f1;
      x1 = b - g * (b - a); f1 = crossing(x1, nullptr);
      if (f1 > best) { best = f1; best_th = x1; }
    } else {
      a = x1; x1 = x2; f1 = f2;
      x2 = a + g * (b - a); f2 = crossing(x2, nullptr);
      if (f2 > best) { best = f2; best_th = x2; }
    }
  }
  Support s;
  const double t = crossing(best_th, &s);
  if (!std::isfinite(t) || !std::isfinite(s.value)) return kNoTravel;
  // Where along the edge the line touches. The contact lies in the meridian half-plane of N; where K's face
  // for N is a segment (a cone or taper generator, the cylinder band) the support point is only one end of
  // it, so the line's crossing with that meridian plane locates the contact. A line (nearly) parallel to the
  // meridian plane falls back to the support point, which then lies on the contact set.
  const Vector3d N = normal(best_th);
  const double nr = std::sqrt(N.x() * N.x() + N.y() * N.y());
  const Vector3d m = nr > 0 ? Vector3d(-N.y() / nr, N.x() / nr, 0.0) : Vector3d::Zero();
  const Vector3d origin = q1 - t * W;  // the line at the contact travel: origin + lambda E
  double u;
  if (std::fabs(e.dot(m)) > 1e-3) u = -origin.dot(m) / E.dot(m);
  else u = (s.point - origin).dot(E) / (L * L);
  if (!(u >= 0 && u <= 1) || !(t < cap)) return kNoTravel;
  // Guard against a lost contact (a line nearly parallel to the motion's plane): the contact must be in K's
  // bounding ball about the tip (loosely: only garbage is to be caught).
  const double reach = std::hypot(c.max_radius(), c.cutting_length());
  if (!((origin + u * E).norm() <= 1.01 * reach)) return kNoTravel;
  if (contact_normal) *contact_normal = N;  // the supporting plane of K that the line meets
  return t;
}

double facet_travel(const Cutter& c, const Vector3d& q0, const Vector3d& q1, const Vector3d& q2,
                    const Vector3d& W, double cap) {
  Vector3d n = (q1 - q0).cross(q2 - q0);
  const double len = n.norm();
  if (!(len > 0)) return kNoTravel;
  n /= len;
  double nw = n.dot(W);
  if (nw > 0) {  // the side facing the incoming cutter
    n = -n;
    nw = -nw;
  }
  if (nw > -1e-12) return kNoTravel;  // plane parallel to the motion: edges and vertices touch first
  const Support s = support(c, -n);  // the point of K deepest towards the plane
  if (!std::isfinite(s.value)) return kNoTravel;
  const double t = n.dot(q0 - s.point) / nw;
  if (!(t < cap)) return kNoTravel;
  const Vector3d y = s.point + t * W;  // the contact point on the plane
  const double w0 = n.dot((q1 - y).cross(q2 - y));
  const double w1 = n.dot((q2 - y).cross(q0 - y));
  const double w2 = n.dot((q0 - y).cross(q1 - y));
  const double area = w0 + w1 + w2;
  const double eps = 1e-12 * std::fabs(area);
  if (area > 0 ? (w0 < -eps || w1 < -eps || w2 < -eps) : (w0 > eps || w1 > eps || w2 > eps)) return kNoTravel;
  return t;
}

namespace {

// K's outward normal at the point x of its surface (not unit): the top cap, the side, or the profile below.
Vector3d surface_normal(const Cutter& c, const Vector3d& x) {
  const double rho = std::sqrt(x.x() * x.x() + x.y() * x.y()), rmax = c.max_radius();
  const double rr = std::min(rho, rmax);
  if (x.z() - c.cutting_length() > c.height(rr) - x.z()) return Vector3d::UnitZ();
  if (!(rho > 0)) return -Vector3d::UnitZ();
  if (rho >= rmax) return Vector3d(x.x() / rho, x.y() / rho, 0.0);
  const double k = c.slope(rr) / rho;
  return Vector3d(k * x.x(), k * x.y(), -1.0);
}

}  // namespace

double triangle_travel(const Cutter& c, const Vector3d& q0, const Vector3d& q1, const Vector3d& q2,
                       const Vector3d& W, double cap, unsigned edges, Vector3d* normal) {
  const double facet = facet_travel(c, q0, q1, q2, W, cap);
  double t = std::min(cap, facet);
  const Vector3d* q[3] = {&q0, &q1, &q2};
  int vertex = -1, edge = -1;
  for (int k = 0; k < 3; ++k) {
    const double v = vertex_travel(c, *q[k], W, t);
    if (v < t) t = v, vertex = k;
  }
  Vector3d n;
  for (int k = 0; k < 3; ++k)
    if (edges & (1u << k)) {
      const double e = edge_travel(c, *q[k], *q[(k + 1) % 3], W, t, normal ? &n : nullptr);
      if (e < t) t = e, edge = k;
    }
  if (!(t < cap)) return kNoTravel;
  if (normal && edge < 0) {
    if (vertex >= 0) {
      n = surface_normal(c, *q[vertex] - t * W);
    } else {  // the facet: its normal facing away from the incoming K
      n = (q1 - q0).cross(q2 - q0);
      if (n.dot(W) < 0) n = -n;
    }
  }
  if (normal) *normal = n;
  return t;
}

void require_finite_length(const Cutter& c) {
  if (!std::isfinite(c.cutting_length()))
    throw std::invalid_argument("a drop with the cutter axis not opposite to the direction needs a cutter with a "
                                "finite cutting length (the shank is not modelled)");
}

}  // namespace direction_detail

namespace {

// V = -axis: the exact -Z contacts (facet, concave edge form, vertices) in the tool frame; travel = -tip z.
double along_axis_tool_frame(const Cutter& c, const Vector3d& q0, const Vector3d& q1, const Vector3d& q2) {
  Vector3d n = (q1 - q0).cross(q2 - q0);
  const double len = n.norm();
  n = len > 0 ? Vector3d(n / len) : Vector3d::Zero();
  if (n.z() < 0) n = -n;
  double z = facet_drop(c, 0.0, 0.0, q0.data(), q1.data(), q2.data(), n.data());
  z = std::max(z, edge_drop(c, 0.0, 0.0, q0.data(), q1.data()));
  z = std::max(z, edge_drop(c, 0.0, 0.0, q1.data(), q2.data()));
  z = std::max(z, edge_drop(c, 0.0, 0.0, q2.data(), q0.data()));
  return -z;
}

}  // namespace

double drop_along_general(const Cutter& cutter, const Vector3d& tip_start, const Vector3d& axis,
                          const Vector3d& V, const Vector3d& p0, const Vector3d& p1, const Vector3d& p2) {
  require_unit(axis, "cutter axis");
  require_unit(V, "drop direction");
  require_finite_length(cutter);
  const ToolFrame fr(axis);
  return direction_detail::triangle_travel(cutter, fr.to_tool(p0 - tip_start), fr.to_tool(p1 - tip_start),
                            fr.to_tool(p2 - tip_start), fr.to_tool(V.normalized()));
}

double drop_along(const Cutter& cutter, const Vector3d& tip_start, const Vector3d& axis, const Vector3d& V,
                  const Vector3d& p0, const Vector3d& p1, const Vector3d& p2) {
  require_unit(axis, "cutter axis");
  require_unit(V, "drop direction");
  const ToolFrame fr(axis);
  const Vector3d q0 = fr.to_tool(p0 - tip_start), q1 = fr.to_tool(p1 - tip_start), q2 = fr.to_tool(p2 - tip_start);
  if ((axis + V).norm() <= kParallelAxisTol) return along_axis_tool_frame(cutter, q0, q1, q2);
  require_finite_length(cutter);
  return direction_detail::triangle_travel(cutter, q0, q1, q2, fr.to_tool(V.normalized()));
}

double drop_along(const Cutter& cutter, const Vector3d& tip_start, const Vector3d& axis, const Vector3d& V,
                  const IndexedTriangle& t) {
  return drop_along(cutter, tip_start, axis, V, Vector3d(t.p[0]), Vector3d(t.p[1]), Vector3d(t.p[2]));
}

// ---- the index ----------------------------------------------------------------------------------------

namespace {

Eigen::Matrix3d rotation_to_minus_z(const Vector3d& V) {
  const Vector3d down(0, 0, -1);
  if (V == down) return Eigen::Matrix3d::Identity();  // the plain drop-cutter frame, bit for bit
  return Eigen::Quaterniond::FromTwoVectors(V, down).toRotationMatrix();
}

std::shared_ptr<const MeshIndex> rotated_index(const VerticesRef& vertices, const TrianglesRef& triangles,
                                               const Eigen::Matrix3d& rot, int threads) {
  if (rot.isIdentity(0.0)) return std::make_shared<const MeshIndex>(vertices, triangles, threads);
  const Vertices rotated = vertices * rot.transpose();
  return std::make_shared<const MeshIndex>(rotated, triangles, threads);
}

}  // namespace

direction_detail::RotatedStarts::RotatedStarts(const DirectionalIndex& index, const double* starts, std::size_t n,
                                              double max_travel)
    : xy(2 * n), z(n), floors(n) {
  for (std::size_t i = 0; i < n; ++i) {
    const Vector3d s = index.rotation() * Vector3d(starts[3 * i], starts[3 * i + 1], starts[3 * i + 2]);
    xy[2 * i] = s.x();
    xy[2 * i + 1] = s.y();
    z[i] = s.z();
    floors[i] = s.z() - max_travel;
  }
}

DirectionalIndex::DirectionalIndex(const VerticesRef& vertices, const TrianglesRef& triangles, const Vector3d& V,
                                   int threads)
    : V_(V) {
  require_unit(V, "drop direction");
  validate(vertices, triangles);  // in the model's frame, before the rotation: messages name its values
  V_ = V.normalized();
  rot_ = rotation_to_minus_z(V_);
  index_ = rotated_index(vertices, triangles, rot_, threads);
}

}  // namespace tmm
