// The exact solvers of tmm/sim/torus_line.hpp: the lowest root of the torus quartic on a vertical line.
#include "torus_line.hpp"

#include <algorithm>
#include <cmath>

namespace tmm::sweep5_detail {

namespace {

constexpr double kDoubtTol = 0.05;    // mm: candidates this close but not on it are re-solved (zmap.DOUBT_TOL)
constexpr int kNewtonSteps = 3;       // polish of each quartic root (zmap.NEWTON_STEPS)

// Distance of the line point at height t to the tube (zero on the torus surface).
double tube_gap(double t, const Line& l, double Ro, double Ri) {
  const double h = l.qa + t * l.az;
  const double rho = std::sqrt(std::max(l.qq + t * t - h * h, 0.0));
  return std::abs(std::sqrt((rho - Ro) * (rho - Ro) + h * h) - Ri);
}

// Real parts of the four roots (Ferrari; a complex pair gives its real part, checked by the caller).
void ferrari(const Quartic& k, double out[4]) {
  const double P = k.P, Q = k.Q, R = k.R;
  // Resolvent: (t^2 + y)^2 = (2y - P) t^2 - Q t + y^2 - R is a square when
  // y^3 - P/2 y^2 - R y + (4 P R - Q^2) / 8 = 0; its largest root has 2y - P >= 0.
  const double a = -0.5 * P, b = -R, c = (4.0 * P * R - Q * Q) / 8.0;
  const double p = b - a * a / 3.0;
  const double q = 2.0 * a * a * a / 27.0 - a * b / 3.0 + c;
  const double p3 = p / 3.0;
  const double D = 0.25 * q * q + p3 * p3 * p3;
  double y;
  if (D > 0.0) {
    const double sq = std::sqrt(D);
    y = std::cbrt(-0.5 * q + sq) + std::cbrt(-0.5 * q - sq);
  } else {
    const double r = std::sqrt(std::max(-p3, 0.0));
    const double cosarg = r > 0.0 ? std::clamp(-0.5 * q / (r * r * r), -1.0, 1.0) : 0.0;
    y = 2.0 * r * std::cos(std::acos(cosarg) / 3.0);
  }
  y -= a / 3.0;
  for (int i = 0; i < 2; ++i) {  // polish the resolvent root
    const double f = ((y + a) * y + b) * y + c, df = (3.0 * y + 2.0 * a) * y + b;
    if (std::abs(df) > 1e-300) y -= f / df;
  }
  y = std::max(y, 0.5 * P);
  // (t^2 + y)^2 = (s t - h)^2, s^2 = 2y - P, h^2 = y^2 - R, 2 s h = Q: h from Q / (2 s) when s is the larger
  // (well conditioned), else from sqrt(y^2 - R) with the sign of Q (s ~ 0: Q ~ 0, biquadratic).
  const double s = std::sqrt(2.0 * y - P);
  const double h2 = std::copysign(std::sqrt(std::max(y * y - R, 0.0)), Q);
  const double h = s > std::abs(h2) ? Q / (2.0 * s) : h2;
  // t^2 - s t + (y + h) = 0 and t^2 + s t + (y - h) = 0.
  const double bb[2] = {-s, s}, cc[2] = {y + h, y - h};
  for (int j = 0; j < 2; ++j) {
    const double sd = std::sqrt(std::max(bb[j] * bb[j] - 4.0 * cc[j], 0.0));
    out[2 * j] = 0.5 * (-bb[j] - sd);
    out[2 * j + 1] = 0.5 * (-bb[j] + sd);
  }
}

// Real roots of the depressed cubic x^3 + p x + q (1 or 3, Newton-polished); returns their number.
int cubic_roots(double p, double q, double out[3]) {
  const double p3 = p / 3.0, D = 0.25 * q * q + p3 * p3 * p3;
  int n;
  if (D > 0.0) {
    const double u = std::cbrt(-0.5 * q - std::copysign(std::sqrt(D), q));  // no cancellation
    out[0] = u != 0.0 ? u - p3 / u : 0.0;
    n = 1;
  } else {
    const double r = std::sqrt(std::max(-p3, 0.0));
    const double phi = std::acos(r > 0.0 ? std::clamp(-0.5 * q / (r * r * r), -1.0, 1.0) : 0.0);
    for (int k = 0; k < 3; ++k) out[k] = 2.0 * r * std::cos((phi - 2.0 * M_PI * k) / 3.0);
    n = 3;
  }
  for (int k = 0; k < n; ++k) {
    for (int i = 0; i < 2; ++i) {
      const double x = out[k], df = 3.0 * x * x + p;
      if (std::abs(df) > 1e-300) out[k] = x - (x * x * x + p * x + q) / df;
    }
  }
  std::sort(out, out + n);
  return n;
}

// The root of k in [lo, hi] where k is monotone and changes sign (safeguarded Newton).
double bracketed_root(const Quartic& k, double lo, double hi, double flo) {
  double t = 0.5 * (lo + hi);
  for (int it = 0; it < 200; ++it) {
    const double f = k.f(t);
    if (f == 0.0) return t;
    if ((f < 0.0) == (flo < 0.0)) lo = t;
    else hi = t;
    const double d = k.df(t);
    double next = d != 0.0 ? t - f / d : 0.5 * (lo + hi);
    if (!(next > lo && next < hi)) next = 0.5 * (lo + hi);
    if (std::abs(next - t) <= 1e-15 * (1.0 + std::abs(t)) || hi - lo <= 1e-15 * (1.0 + std::abs(t))) return next;
    t = next;
  }
  return t;
}

// Lowest t on the torus by isolating the real roots of the quartic between its critical points (the
// fallback for doubtful lines). Local minima of the quartic above zero are the near-tangent candidates
// (zmap.py's eigenvalue real parts); all candidates are accepted by their distance to the tube.
double isolated_lowest(const Quartic& k, const Line& l, double Ro, double Ri) {
  double crit[3];
  const int nc = cubic_roots(0.5 * k.P, 0.25 * k.Q, crit);
  // Fujiwara's bound on the roots of t^4 + P t^2 + Q t + R.
  const double B = 2.0 * std::max({std::sqrt(std::abs(k.P)), std::cbrt(std::abs(k.Q)),
                                   std::sqrt(std::sqrt(0.5 * std::abs(k.R)))}) + 1.0;
  double pts[5];
  int np = 0;
  pts[np++] = -B;
  for (int i = 0; i < nc; ++i) pts[np++] = std::clamp(crit[i], -B, B);
  pts[np++] = B;
  double best = kInf;
  auto consider = [&](double t) {
    if (t < best && tube_gap(t, l, Ro, Ri) <= kTangentTol) best = t;
  };
  for (int i = 0; i + 1 < np; ++i) {
    const double lo = pts[i], hi = pts[i + 1];
    const double flo = k.f(lo), fhi = k.f(hi);
    if (flo == 0.0) consider(lo);
    else if ((flo < 0.0) != (fhi < 0.0) && fhi != 0.0) consider(bracketed_root(k, lo, hi, flo));
    else if (fhi == 0.0) consider(hi);
  }
  for (int i = 0; i < nc; ++i) {
    const double t = crit[i];
    if (12.0 * t * t + 2.0 * k.P >= 0.0) consider(t);  // a local minimum: touching if close enough
  }
  return best;
}

// Lowest t of the solid torus on the line by Ferrari (the general path); +inf if missed. fallback counts the
// lines re-solved by root isolation.
double ferrari_lowest(const Quartic& k, const Line& l, double Ro, double Ri, std::size_t* fallback) {
  double roots[4];
  ferrari(k, roots);
  std::sort(roots, roots + 4);
  // From the lowest candidate up: the first on the torus is the entry (a polish moves a candidate by at most
  // 3e-3 mm, so candidates that close above it are polished too). A doubtful candidate below it sends the
  // line to the fallback; one above it cannot hide a lower root (a missed root shows next to its candidate).
  constexpr double kPolishReach = kNewtonSteps * 1e-3;
  double best = kInf;
  bool doubt = false;
  for (double t : roots) {
    if (t > best + 2.0 * kPolishReach) break;
    for (int i = 0; i < kNewtonSteps; ++i) {
      const double d = k.df(t);
      // Keep the polish local (a double root makes Newton slow, never far).
      if (std::abs(d) > 1e-300) t -= std::clamp(k.f(t) / d, -1e-3, 1e-3);
    }
    const double g = tube_gap(t, l, Ro, Ri);
    if (g <= kTangentTol) best = std::min(best, t);
    else if (g < kDoubtTol && t < best) doubt = true;
  }
  if (!doubt) return best;
  if (fallback) ++*fallback;
  return isolated_lowest(k, l, Ro, Ri);
}

// The lowest real root of k by Newton from t, when it can be certified: f convex on (-inf, t], f(t) > 0 and
// f'(t) < 0 mean f > 0 left of t (convex and decreasing there), so no root and no local minimum (no
// near-tangent touch) lies below t. Newton then climbs monotonically to the lowest root: each tangent lies
// below the convex f, so every iterate stays left of the root, and each is certified again the same way.
// Returns false when a check fails (the start is not below the root, f turns or leaves its convex part
// before reaching zero: a near-tangent line or a root beyond the inflection) - the caller then uses Ferrari.
bool newton_lowest(const Quartic& k, double t, double& root) {
  constexpr int kMaxIter = 40;
  for (int it = 0; it < kMaxIter; ++it) {
    if (!convex_left_of(k, t)) return false;
    const double f = k.f(t), d = k.df(t);
    if (f <= 0.0) {  // rounding put the iterate on (or a hair past) the root it approached from the left
      if (it == 0) return false;  // the start itself is not certified below the root
      root = t;
      return true;
    }
    if (!(d < 0.0)) return false;
    const double step = -f / d, t1 = t + step;
    if (!convex_left_of(k, t1)) return false;  // past the inflection: the tangent no longer certifies t1
    // Stop when the next step, f(t1) / |f'(t1)|, is below 1e-13 mm: with M the largest f'' on [t, t1] (at an
    // end: f'' is a parabola), f(t1) <= M step^2 / 2 and |f'(t1)| >= |f'(t)| - M step.
    const double M = std::max(6.0 * t * t, 6.0 * t1 * t1) * 2.0 + 2.0 * k.P;
    const double slope = -d - M * step;
    t = t1;
    // slope > 1e-3 M: f' is not near zero, so the root is within twice that next step, and it is well
    // conditioned (no second root within ~1e-3 mm). Near-double roots (lines grazing the tube) are left to
    // Ferrari and its near-tangent rules, so that both paths agree to rounding.
    if (slope > 1e-3 * M && 0.5 * M * step * step <= 1e-13 * slope) {
      root = t;
      return true;
    }
  }
  return false;
}

}  // namespace

// Lowest t of the solid torus (Ro > 0, k its quartic) on the line; +inf if missed. fallback counts the lines
// re-solved by root isolation. t_hint: the cell top, usually inside the tube (k < 0 there: the previous
// instance's root, a few micrometres above this one's); +inf when there is none. Newton starts from the
// hint's tangent, else 0.1 mm below the hint, else at the torus' own lower bound on the line; Ferrari solves
// what Newton cannot certify (the same root: the lowest real one).
double torus_lowest(const Quartic& k, const Line& l, double Ro, double Ri, std::size_t* fallback, double t_hint) {
  // Every torus point has h >= -Ri and |x - C| <= Ro + Ri: no root below t_lb.
  const double Rt = Ro + Ri;
  const double t_lb = std::max((-Ri - l.qa) / l.az, -std::sqrt(std::max(Rt * Rt - l.qq, 0.0))) - 1e-9;
  double root;
  if (t_hint < kInf) {
    // From the hint inside the tube (f < 0), its tangent's zero: left of the root where f is convex (the
    // tangent lies below f), typically a few micrometres from it, so Newton needs a step or two more.
    const double f = k.f(t_hint), d = k.df(t_hint);
    const double t_tangent = f < 0.0 && d < 0.0 ? t_hint - f / d : kInf;
    if (t_tangent > t_lb && t_tangent < kInf && newton_lowest(k, t_tangent, root)) return root;
    constexpr double kHintDrop = 0.1;  // mm below the hint: more than a cell usually falls between instances
    const double t_near = t_hint - kHintDrop;
    if (t_near > t_lb && newton_lowest(k, t_near, root)) return root;
  }
  if (newton_lowest(k, t_lb, root)) return root;
  return ferrari_lowest(k, l, Ro, Ri, fallback);
}

// The same without a hint (lowest_on_vertical, a ball in the sweep): Ferrari, as zmap.py solves it, so that
// lowest_on_vertical stays its exact port (on a steep entry where Ferrari's root is off by up to the 1e-7 mm
// touching tolerance, Newton's exact root would differ from zmap.py's by that much).
double torus_lowest(const Line& l, double Ro, double Ri, std::size_t* fallback) {
  if (Ro == 0.0) return l.qq <= Ri * Ri ? -std::sqrt(Ri * Ri - l.qq) : kInf;  // a ball
  return ferrari_lowest(torus_quartic(l, Ro, Ri), l, Ro, Ri, fallback);
}

// Lowest t of the whole solid (torus, bull-nose core, shank) on the line.
double solid_lowest(const TorusTool& tool, const Line& l) {
  double t = half_cylinder_lowest(l, tool.radius(), 0.0);
  if (tool.Ri > 0.0) t = std::min(t, torus_lowest(l, tool.Ro, tool.Ri, nullptr));  // Ri = 0: the rim, the core's edge
  if (tool.shape == ToolShape::BullNose && tool.Ro > 0.0) t = std::min(t, half_cylinder_lowest(l, tool.Ro, -tool.Ri));
  return t;
}

}  // namespace tmm::sweep5_detail
