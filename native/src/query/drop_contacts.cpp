#include "tmm/query/drop_contacts.hpp"

#include <algorithm>
#include <cmath>

namespace tmm {

namespace {

// Distance from the axis of the cutter point touching a plane whose unit normal has horizontal length nxy
// and vertical component nz > 0.
inline double plane_contact_radius(const Cutter& c, double nxy, double nz) {
  return nxy > 1e-15 ? c.facet_contact_radius(nxy, nz) : 0.0;
}

}  // namespace

double plane_drop(const Cutter& c, double x, double y, const double* p0, const double* p1, const double* p2,
                  const double* n, bool& inside) {
  inside = false;
  const double nz = n[2];
  if (nz <= 1e-12) return kNoContact;  // vertical or downward facing: edges give the contact
  const double nxy = std::sqrt(n[0] * n[0] + n[1] * n[1]);
  double cx = x, cy = y;
  const double rho = plane_contact_radius(c, nxy, nz);
  if (nxy > 1e-15) {
    cx -= rho * n[0] / nxy;  // uphill: the plane rises against n_xy
    cy -= rho * n[1] / nxy;
  }
  inside = inside_xy(p0, p1, p2, cx, cy);
  // Plane height at the contact point, then down by the cutter profile there.
  const double zc = p0[2] - (n[0] * (cx - p0[0]) + n[1] * (cy - p0[1])) / nz;
  return zc - c.height(rho);
}

double facet_drop(const Cutter& c, double x, double y, const double* p0, const double* p1,
                  const double* p2, const double* n, double zmax, double above) {
  // The contact point lies in the triangle, so no higher than its highest corner: the tip is at most zmax
  // lowered by h at the contact radius. The margin covers the rounding of the plane's height and of the
  // inside test's tolerance, so a true contact is never cut.
  if (n[2] > 1e-12 && zmax < kInf && above > kNoContact &&
      zmax - c.height(plane_contact_radius(c, std::sqrt(n[0] * n[0] + n[1] * n[1]), n[2])) + 1e-9 * (1.0 + std::fabs(zmax)) <= above)
    return kNoContact;
  bool inside = false;
  const double z = plane_drop(c, x, y, p0, p1, p2, n, inside);
  return inside && z > above ? z : kNoContact;
}

namespace {

// Maximum of g(u) = z0 + m u - h(sqrt(d2 + u^2)) on [lo, hi] for any convex non-decreasing profile h.
// g is concave, so g' = m - u h'(rho) / rho decreases: the maximum is at an end or at the root of g'
// (at rho = 0 a cone's kink makes g' jump; the subgradient m is used there and bisection converges).
// Being concave, g lies below its tangents at both ends: where they meet bounds the maximum (a contact no
// higher than `above` is not solved) and starts the Newton iteration close to the root.
double profile_edge_max(const Cutter& c, double d2, double z0, double m, double lo, double hi, double above) {
  auto g = [&](double u) { return z0 + m * u - c.height(std::sqrt(d2 + u * u)); };
  auto dg = [&](double u) {
    const double rho = std::sqrt(d2 + u * u);
    if (rho == 0.0) return m;
    return m - u * c.slope(rho) / rho;
  };
  const double slope_lo = dg(lo), slope_hi = dg(hi);
  if (!(slope_lo > 0)) return g(lo);
  if (!(slope_hi < 0)) return g(hi);
  double a = lo, b = hi;
  double u = 0.5 * (a + b);
  {
    const double g_lo = g(lo), g_hi = g(hi);
    double bound = kInf;  // a vertical tangent (the arc turning vertical at an end) bounds nothing
    if (std::isfinite(slope_lo) && std::isfinite(slope_hi)) {
      u = std::clamp((g_hi - g_lo + slope_lo * lo - slope_hi * hi) / (slope_lo - slope_hi), lo, hi);
      bound = g_lo + slope_lo * (u - lo);
    } else if (std::isfinite(slope_lo)) {
      bound = g_lo + slope_lo * (hi - lo);
    } else if (std::isfinite(slope_hi)) {
      bound = g_hi + slope_hi * (lo - hi);
    }
    if (bound + 1e-12 <= above) return kNoContact;  // margin: the bound's own rounding
    if (!(u > lo && u < hi)) u = 0.5 * (lo + hi);
  }
  for (int it = 0; it < 200 && b - a > 1e-12; ++it) {
    const double du = dg(u);
    if (du > 0) a = u; else b = u;
    if (du == 0) break;
    // Newton step on g' with g'' = -(h'' (u/rho)^2 + h' d^2 / rho^3); bisect when it leaves (a, b).
    const double rho = std::sqrt(d2 + u * u);
    double next = 0.5 * (a + b);
    if (rho > 0.0) {
      const double d2g = -(c.curvature(rho) * u * u / (rho * rho) + c.slope(rho) * d2 / (rho * rho * rho));
      if (d2g < 0 && std::isfinite(d2g)) {
        const double newton = u - du / d2g;
        if (newton > a && newton < b) next = newton;
      }
    }
    if (std::fabs(next - u) < 1e-13) {
      // A short Newton step means convergence, except on a bottom cone (k1 > 0) no flatter than the edge
      // (|m| >= k1): there g' = m - k1 u / rho keeps the sign of m, the root lies beyond the cone, and the
      // step is short only because the axis is (within rounding) on the edge's line, d ~ 1e-16, where
      // g'' ~ -k1 d^2 / rho^3 is huge near the apex. Bisect on instead of stopping at the apex.
      const double k1 = c.slope(0.0);
      if (!(k1 > 0.0 && std::fabs(m) >= k1 && rho <= c.flat_radius())) { u = next; break; }
      next = 0.5 * (a + b);
    }
    u = next;
  }
  return g(u);
}

// The ball's edge contact, g(u) = z0 + m u - R + sqrt(s^2 - u^2) at its maximum u* = s m / sqrt(1 + m^2) on
// the edge's chord through the shadow, in lengths scaled by the edge's XY length L (U = u L) so that the
// three roots (L, the 3D length L3 and s L) are independent and the only division is 1 / L^2; inside the
// chord g(u*) = z0 - R + s L3 / L. dz: p2 - p1 in z; dot: (p1 - axis) . e_xy; cross2: the squared cross
// product (s L)^2 = R^2 L^2 - cross2.
double ball_edge_drop(double R, double z1, double dz, double dot, double L2, double cross2) {
  const double Q = R * R * L2 - cross2;
  if (!(Q >= 0)) return kNoContact;
  const double sL = std::sqrt(Q), L = std::sqrt(L2), L3 = std::sqrt(L2 + dz * dz);
  const double lo = maxd(dot, -sL), hi = std::min(dot + L2, sL);  // the chord within the edge, scaled
  if (lo > hi) return kNoContact;
  const double inv_L2 = 1.0 / L2;
  const double z0 = z1 - dz * dot * inv_L2;  // the edge's height at the foot of the axis
  const double top = sL * dz;                // u* L3, scaled
  if (top >= lo * L3 && top <= hi * L3) return z0 - R + sL * L3 * inv_L2;
  const double U = top < lo * L3 ? lo : hi;
  return z0 + dz * U * inv_L2 - R + std::sqrt(maxd(Q - U * U, 0.0)) * L * inv_L2;
}

}  // namespace

double edge_drop(const Cutter& c, double x, double y, const double* p1, const double* p2, double above) {
  const double ex = p2[0] - p1[0], ey = p2[1] - p1[1];
  const double L2 = ex * ex + ey * ey;
  const double R = c.max_radius();
  if (L2 < 1e-24) {  // vertical edge: its top vertex is the contact
    return std::max(vertex_drop(c, x, y, p1), vertex_drop(c, x, y, p2));
  }
  const double sx = p1[0] - x, sy = p1[1] - y;
  // Rejections before any root: the axis' distance from the edge line is d = cross / L. Beyond R, no
  // contact; and the contact is at most the higher end lowered by h(|d|), which is no higher than `above`
  // exactly when d^2 >= reach2(top - above).
  const double cross = ex * sy - ey * sx;
  const double cross2 = cross * cross;
  if (cross2 > R * R * L2) return kNoContact;
  if (!(cross2 < c.reach2(maxd(p1[2], p2[2]) - above) * L2)) return kNoContact;
  if (c.kind() == CutterKind::Ball) return ball_edge_drop(R, p1[2], p2[2] - p1[2], ex * sx + ey * sy, L2, cross2);
  const double L = std::sqrt(L2);
  const double wx = ex / L, wy = ey / L;
  const double u1 = sx * wx + sy * wy;      // position of p1 along the edge, 0 at the foot of the axis
  const double d = wx * sy - wy * sx;       // signed distance of the axis from the edge line (XY)
  const double d2 = d * d;
  if (d2 > R * R) return kNoContact;
  const double s = std::sqrt(R * R - d2);   // half-chord of the cutter's shadow along the edge
  const double lo = std::max(u1, -s), hi = std::min(u1 + L, s);
  if (lo > hi) return kNoContact;
  const double m = (p2[2] - p1[2]) / L;     // slope of the edge
  const double z0 = p1[2] - m * u1;         // edge height at u = 0
  switch (c.kind()) {
    case CutterKind::Flat:                  // the line's highest point over the flat disc chord
      return z0 + m * (m > 0 ? hi : lo);
    case CutterKind::Ball:                  // solved above
    case CutterKind::Bull:
    case CutterKind::General:
      return profile_edge_max(c, d2, z0, m, lo, hi, above);
  }
  return kNoContact;
}

}  // namespace tmm
