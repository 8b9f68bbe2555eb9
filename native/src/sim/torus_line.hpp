// The lowest point of the 5-axis sweep's tool solid on a vertical line (sweep5.cpp; the method is in
// tmm/sim/sweep5.hpp): the torus quartic and the cheap tests the sweep runs per cell, inline here, and the
// exact solvers (Newton where certified, Ferrari, root isolation) in torus_line.cpp. Heights t are measured
// above the torus centre C.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstddef>

#include "tmm/cutter/torus_tool.hpp"
#include "tmm/util/constants.hpp"

namespace tmm::sweep5_detail {

constexpr double kTangentTol = 1e-7;  // mm: a line this close to the torus touches it (zmap.TANGENT_TOL)

// The line at horizontal offset q from C: qa = q . a, qq = |q|^2.
struct Line {
  double qa, qq, az;
};

// Lowest t of {rho <= radius, h >= h_min} (convex) on the line; +inf if missed. rho^2(t) = A t^2 + B t + Cc +
// radius^2, h(t) = qa + t az increasing: the cylinder's interval clipped from below by the plane.
inline double half_cylinder_lowest(const Line& l, double radius, double h_min) {
  const double t_plane = (h_min - l.qa) / l.az;
  const double A = 1.0 - l.az * l.az;
  const double Cc = l.qq - l.qa * l.qa - radius * radius;
  if (A < 1e-14) return Cc <= 0.0 ? t_plane : kInf;  // vertical axis: rho constant on the line
  const double B = -2.0 * l.az * l.qa;
  const double disc = B * B - 4.0 * A * Cc;
  if (disc < 0.0) return kInf;
  const double m = -0.5 * (B + std::copysign(std::sqrt(disc), B));  // stable roots
  const double r1 = m / A, r2 = m != 0.0 ? Cc / m : r1;
  const double lo = std::max(std::min(r1, r2), t_plane);
  return lo <= std::max(r1, r2) ? lo : kInf;
}

struct Quartic {  // t^4 + P t^2 + Q t + R
  double P, Q, R;
  double f(double t) const { return ((t * t + P) * t + Q) * t + R; }
  double df(double t) const { return (4.0 * t * t + 2.0 * P) * t + Q; }
};

// f is convex on (-inf, t]: f'' = 12 t^2 + 2 P >= 0 there (P >= 0: everywhere; else left of -sqrt(-P / 6)).
inline bool convex_left_of(const Quartic& k, double t) { return k.P >= 0.0 || (t <= 0.0 && 6.0 * t * t >= -k.P); }

// Whether the torus meets the line below the cell top (t < t_top), from the quartic alone. Yes: the top is
// inside the tube (f < 0 there: a root lies below; the usual case, the top being the previous instance's
// lowest point). No: f >= 0 at the top, convex and not increasing left of it, so f > 0 all the way down (no
// root and no near-tangent minimum: a line that misses below the top or meets the torus only above it).
enum class Verdict { Yes, No, Unknown };
inline Verdict torus_below(const Quartic& k, double t_top) {
  if (k.f(t_top) < 0.0) return Verdict::Yes;
  if (k.df(t_top) <= 0.0 && convex_left_of(k, t_top)) return Verdict::No;
  return Verdict::Unknown;
}

// The torus quartic of the line (see the header): negative inside the tube, its lowest root the entry.
inline Quartic torus_quartic(const Line& l, double Ro, double Ri) {
  const double R2 = Ro * Ro;
  const double K = l.qq + R2 - Ri * Ri;
  return {2.0 * K - 4.0 * R2 * (1.0 - l.az * l.az), 8.0 * R2 * l.qa * l.az, K * K - 4.0 * R2 * (l.qq - l.qa * l.qa)};
}

// Lowest t of the solid torus (Ro > 0, k its quartic) on the line; +inf if missed. fallback counts the lines
// re-solved by root isolation. t_hint: the cell top (+inf when there is none), see torus_line.cpp.
double torus_lowest(const Quartic& k, const Line& l, double Ro, double Ri, std::size_t* fallback, double t_hint);

// The same without a hint (lowest_on_vertical, a ball in the sweep): Ferrari, as zmap.py solves it.
double torus_lowest(const Line& l, double Ro, double Ri, std::size_t* fallback);

// Lowest t of the whole solid (torus, bull-nose core, shank) on the line.
double solid_lowest(const TorusTool& tool, const Line& l);

}  // namespace tmm::sweep5_detail
