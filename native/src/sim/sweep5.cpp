#include "tmm/sim/sweep5.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <sstream>
#include <stdexcept>
#include <utility>
#include <vector>

#include "tmm/util/range.hpp"

namespace tmm {

namespace {

using Eigen::Vector3d;

constexpr double kTangentTol = 1e-7;  // mm: a line this close to the torus touches it (zmap.TANGENT_TOL)
constexpr double kDoubtTol = 0.05;    // mm: candidates this close but not on it are re-solved (zmap.DOUBT_TOL)
constexpr int kNewtonSteps = 3;       // polish of each quartic root (zmap.NEWTON_STEPS)
constexpr double kPruneMargin = 1e-9;  // mm: slack of the pruning bounds against rounding
constexpr std::size_t kRowsPerBand = 16;
constexpr double kMaxSteps = 1e12;   // sub-steps of one move beyond which max_step is refused as too small

// ---------------------------------------------------------------------------------------------------------
// Lowest point of the solid on a vertical line, heights t above the torus centre C.
// ---------------------------------------------------------------------------------------------------------

// The line at horizontal offset q from C: qa = q . a, qq = |q|^2.
struct Line {
  double qa, qq, az;
};

// Lowest t of {rho <= radius, h >= h_min} (convex) on the line; +inf if missed. rho^2(t) = A t^2 + B t + Cc +
// radius^2, h(t) = qa + t az increasing: the cylinder's interval clipped from below by the plane.
double half_cylinder_lowest(const Line& l, double radius, double h_min) {
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

// f is convex on (-inf, t]: f'' = 12 t^2 + 2 P >= 0 there (P >= 0: everywhere; else left of -sqrt(-P / 6)).
bool convex_left_of(const Quartic& k, double t) { return k.P >= 0.0 || (t <= 0.0 && 6.0 * t * t >= -k.P); }

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

// Whether the torus meets the line below the cell top (t < t_top), from the quartic alone. Yes: the top is
// inside the tube (f < 0 there: a root lies below; the usual case, the top being the previous instance's
// lowest point). No: f >= 0 at the top, convex and not increasing left of it, so f > 0 all the way down (no
// root and no near-tangent minimum: a line that misses below the top or meets the torus only above it).
enum class Verdict { Yes, No, Unknown };
Verdict torus_below(const Quartic& k, double t_top) {
  if (k.f(t_top) < 0.0) return Verdict::Yes;
  if (k.df(t_top) <= 0.0 && convex_left_of(k, t_top)) return Verdict::No;
  return Verdict::Unknown;
}

// The torus quartic of the line (see the header): negative inside the tube, its lowest root the entry.
Quartic torus_quartic(const Line& l, double Ro, double Ri) {
  const double R2 = Ro * Ro;
  const double K = l.qq + R2 - Ri * Ri;
  return {2.0 * K - 4.0 * R2 * (1.0 - l.az * l.az), 8.0 * R2 * l.qa * l.az, K * K - 4.0 * R2 * (l.qq - l.qa * l.qa)};
}

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
  double t = std::min(torus_lowest(l, tool.Ro, tool.Ri, nullptr), half_cylinder_lowest(l, tool.radius(), 0.0));
  if (tool.shape == ToolShape::BullNose && tool.Ro > 0.0) t = std::min(t, half_cylinder_lowest(l, tool.Ro, -tool.Ri));
  return t;
}

// ---------------------------------------------------------------------------------------------------------
// Motion and instances.
// ---------------------------------------------------------------------------------------------------------

// One tool instance: what the cells under it share.
struct Pose {
  Vector3d C, a;     // torus centre, unit axis
  double sin_b = 0;  // sine of the tilt: rho drifts at most this fast along a vertical line
  double zmin = 0;   // lowest point of the solid
  double ex = 0, ey = 0;  // the footprint is the stadium of radius Ro + Ri about C_xy .. C_xy + (ex, ey)
  double ylo = 0, yhi = 0;
};

Pose make_pose(const TorusTool& tool, const Vector3d& tip, const Vector3d& axis, double stock_top) {
  Pose p;
  p.a = axis;
  p.C = tip + tool.Ri * axis;
  const double az = axis.z(), Rt = tool.radius();
  p.sin_b = std::sqrt(std::max(1.0 - az * az, 0.0));
  p.zmin = p.C.z() - tool.Ro * p.sin_b - tool.Ri;  // the torus' lowest point: nothing of the solid is lower
  // The shank can reach a cell only below the stock's top: its points at height h above the centre plane are
  // at z >= C_z + h a_z - Rt sin(b).
  const double h_max = std::max(0.0, (stock_top - p.C.z() + Rt * p.sin_b) / az);
  p.ex = h_max * axis.x();
  p.ey = h_max * axis.y();
  p.ylo = std::min(p.C.y(), p.C.y() + p.ey) - Rt;
  p.yhi = std::max(p.C.y(), p.C.y() + p.ey) + Rt;
  return p;
}

struct Move {
  std::size_t k = 0;     // index of the move k -> k + 1
  std::size_t steps = 1;  // sub-steps
  bool first = false;    // stamps its start instance too (the previous move is not simulated)
  bool rapid = false;
  double theta = 0;      // angle between the end axes
  double ylo = kInf, yhi = -kInf;  // rows met by any of its instances
};

Vector3d slerp(const Vector3d& a0, const Vector3d& a1, double theta, double s) {
  if (theta < 1e-9) return a0;
  const Vector3d v = (std::sin((1.0 - s) * theta) * a0 + std::sin(s * theta) * a1) / std::sin(theta);
  return v.normalized();
}

[[noreturn]] void refuse_row(const char* what, std::size_t row, const double* v, const char* why) {
  std::ostringstream msg;
  msg << "cut_5axis: " << what << " row " << row << " (" << v[0] << ", " << v[1] << ", " << v[2] << ") " << why;
  throw std::invalid_argument(msg.str());
}

// The x range of the footprint stadium on the row at y (empty: lo > hi).
std::pair<double, double> stadium_row(const Pose& p, double Rt, double y) {
  double lo = kInf, hi = -kInf;
  auto disk = [&](double cx, double cy) {
    const double dy = y - cy;
    if (std::abs(dy) > Rt) return;
    const double w = std::sqrt(Rt * Rt - dy * dy);
    lo = std::min(lo, cx - w);
    hi = std::max(hi, cx + w);
  };
  const double cx = p.C.x(), cy = p.C.y();
  disk(cx, cy);
  const double L = std::hypot(p.ex, p.ey);
  if (L > 0.0) {
    disk(cx + p.ex, cy + p.ey);
    // The rectangle 0 <= u.(x - C) <= L, |n.(x - C)| <= Rt, u = e / L, n = (-u_y, u_x), on the row.
    const double ux = p.ex / L, uy = p.ey / L, dy = y - cy;
    double a = -kInf, b = kInf;
    auto clip = [&](double coef, double offset, double vlo, double vhi) {  // vlo <= coef x' + offset <= vhi
      if (std::abs(coef) < 1e-15) {
        if (offset < vlo || offset > vhi) a = kInf;
        return;
      }
      double x1 = (vlo - offset) / coef, x2 = (vhi - offset) / coef;
      if (x1 > x2) std::swap(x1, x2);
      a = std::max(a, x1);
      b = std::min(b, x2);
    };
    clip(ux, uy * dy, 0.0, L);
    clip(-uy, ux * dy, -Rt, Rt);
    if (a <= b) {
      lo = std::min(lo, cx + a);
      hi = std::max(hi, cx + b);
    }
  }
  return {lo, hi};
}

struct BandResult {
  std::size_t lowered = 0;
  std::vector<RapidCollision> removals;  // rapids that removed anything in this band
  Sweep5Stats stats;
};

}  // namespace

double lowest_on_vertical(const TorusTool& tool, const Vector3d& tip, const Vector3d& axis, double x, double y) {
  const Vector3d C = tip + tool.Ri * axis;
  const double qx = x - C.x(), qy = y - C.y();
  const Line l{qx * axis.x() + qy * axis.y(), qx * qx + qy * qy, axis.z()};
  return solid_lowest(tool, l) + C.z();
}

SimReport cut_5axis(ZMap& stock, const TorusTool& tool, const double* tips, const double* axes_in,
                    const MoveKind* kinds, std::size_t n, const Sweep5Options& options, const BatchOptions& batch,
                    Sweep5Stats* stats_out) {
  tool.validate();
  if (!(std::isfinite(options.max_step) && options.max_step > 0.0)) {
    std::ostringstream msg;
    msg << "cut_5axis: max_step must be > 0 mm and finite, got " << options.max_step;
    throw std::invalid_argument(msg.str());
  }
  if (!(std::isfinite(options.collision_tol) && options.collision_tol >= 0.0)) {
    std::ostringstream msg;
    msg << "cut_5axis: collision_tol must be >= 0 mm and finite, got " << options.collision_tol;
    throw std::invalid_argument(msg.str());
  }
  if (n > 0 && (!tips || !axes_in)) throw std::invalid_argument("cut_5axis: tips and axes must not be null");
  if (n > 1 && !kinds) throw std::invalid_argument("cut_5axis: kinds must not be null for 2 or more points");
  std::vector<Vector3d> tip(n), axis(n);
  for (std::size_t r = 0; r < n; ++r) {
    const double* t = tips + 3 * r;
    const double* a = axes_in + 3 * r;
    if (!(std::isfinite(t[0]) && std::isfinite(t[1]) && std::isfinite(t[2]))) refuse_row("tips", r, t, "is not finite");
    if (!(in_range(t[0]) && in_range(t[1]) && in_range(t[2])))
      refuse_row("tips", r, t, out_of_range_text().c_str());
    if (!(std::isfinite(a[0]) && std::isfinite(a[1]) && std::isfinite(a[2]))) refuse_row("axes", r, a, "is not finite");
    const Vector3d v(a[0], a[1], a[2]);
    const double len = v.norm();
    if (!(len > 1e-12) || !std::isfinite(len)) refuse_row("axes", r, a, "is zero (an axis must be a direction)");
    tip[r] = Vector3d(t[0], t[1], t[2]);
    axis[r] = v / len;
    if (!(axis[r].z() > 1e-6)) {
      refuse_row("axes", r, a, "does not point upwards (a_z must be > 0: the tool points down onto the z-map)");
    }
  }
  for (std::size_t k = 0; k + 1 < n; ++k) {
    const auto v = static_cast<std::uint8_t>(kinds[k]);
    if (v > static_cast<std::uint8_t>(MoveKind::Jump)) {
      std::ostringstream msg;
      msg << "cut_5axis: kinds[" << k << "] = " << static_cast<int>(v)
          << " is not a move kind (0 cut, 1 rapid, 2 jump)";
      throw std::invalid_argument(msg.str());
    }
  }
  const std::size_t nx = stock.nx(), ny = stock.ny();
  std::vector<double>& z = stock.heights();
  double stock_top = -kInf;
  for (std::size_t c = 0; c < z.size(); ++c) {
    if (!in_range(z[c])) {
      std::ostringstream msg;
      msg << "cut_5axis: stock cell (" << c % nx << ", " << c / nx << ") height " << z[c] << " "
          << out_of_range_text();
      throw std::invalid_argument(msg.str());
    }
    stock_top = std::max(stock_top, z[c]);
  }

  const double Ro = tool.Ro, Ri = tool.Ri, Rt = tool.radius();
  const double reach = std::hypot(Rt, 2.0 * Ri);
  const bool core = tool.shape == ToolShape::BullNose && Ro > 0.0;
  const bool ball = Ro == 0.0;
  // Squared radii and margins of the pruning tests: a line within the tangent tolerance counts as touching.
  const double Rt2_hit = (Rt + kTangentTol + kPruneMargin) * (Rt + kTangentTol + kPruneMargin);
  const double Ro2_hit = (Ro + kPruneMargin) * (Ro + kPruneMargin);
  const double Ro2mRi2 = Ro * Ro - Ri * Ri;
  const double g_margin = 2.0 * Ri * (kTangentTol + kPruneMargin) + 1e-12;

  // The simulated moves, their sub-steps and the rows their instances reach.
  std::vector<Move> moves;
  SimReport report;
  for (std::size_t k = 0; k + 1 < n; ++k) {
    if (kinds[k] == MoveKind::Jump) continue;
    Move m;
    m.k = k;
    m.rapid = kinds[k] == MoveKind::Rapid;
    m.first = k == 0 || kinds[k - 1] == MoveKind::Jump;
    m.theta = std::acos(std::clamp(axis[k].dot(axis[k + 1]), -1.0, 1.0));
    const double steps = std::ceil(((tip[k + 1] - tip[k]).norm() + m.theta * reach) / options.max_step - 1e-12);
    if (!(steps <= kMaxSteps)) {
      std::ostringstream msg;
      msg << "cut_5axis: move " << k << " needs " << steps << " sub-steps of max_step = " << options.max_step
          << " mm (more than " << kMaxSteps << "): max_step is too small";
      throw std::invalid_argument(msg.str());
    }
    m.steps = std::max<std::size_t>(1, static_cast<std::size_t>(steps));
    moves.push_back(m);
  }
  report.moves_cut = moves.size();
  auto pose_at = [&](const Move& m, std::size_t step) {
    const double s = static_cast<double>(step) / static_cast<double>(m.steps);
    const Vector3d t = (1.0 - s) * tip[m.k] + s * tip[m.k + 1];
    return make_pose(tool, t, slerp(axis[m.k], axis[m.k + 1], m.theta, s), stock_top);
  };
  {
    // Progress: this pass is cheap next to the stamping (a pose per instance against a footprint's cells).
    const BatchOptions rows{batch.threads, progress_phase(batch.progress, 0.0, 0.02)};
    parallel_chunks(moves.size(), 64, rows, [&](std::size_t b, std::size_t e, ChunkContext& ctx) {
      for (std::size_t i = b; i < e; ++i) {
        Move& m = moves[i];
        for (std::size_t step = m.first ? 0 : 1; step <= m.steps; ++step) {
          if ((step & 1023) == 0) {
            if (ctx.stopping()) return;
            ctx.done_within(static_cast<double>(i - b) + static_cast<double>(step) / static_cast<double>(m.steps));
          }
          const Pose p = pose_at(m, step);
          m.ylo = std::min(m.ylo, p.ylo);
          m.yhi = std::max(m.yhi, p.yhi);
        }
      }
    });
  }

  // Bands of rows, each cutting every instance that reaches it, in path order.
  const std::size_t nbands = (ny + kRowsPerBand - 1) / kRowsPerBand;
  std::vector<BandResult> bands(nbands);
  const double x0 = stock.x0(), y0 = stock.y0(), cell = stock.cell();
  const BatchOptions cut{batch.threads, progress_phase(batch.progress, 0.02, 1.0)};
  parallel_chunks(nbands, 1, cut, [&](std::size_t b0, std::size_t b1, ChunkContext& ctx) {
    std::vector<std::pair<std::size_t, double>> removed;  // (cell, height before) lowered by the current rapid
    for (std::size_t band = b0; band < b1; ++band) {
      BandResult& out = bands[band];
      const std::size_t j0 = band * kRowsPerBand, j1 = std::min(ny, j0 + kRowsPerBand) - 1;
      const double band_ylo = stock.cy(j0), band_yhi = stock.cy(j1);
      const std::vector<double> before(z.begin() + static_cast<std::ptrdiff_t>(j0 * nx),
                                       z.begin() + static_cast<std::ptrdiff_t>((j1 + 1) * nx));
      // Progress and cancel between the instances of a move, not only between moves: one move can be long.
      double band_steps = 0.0, steps_done = 0.0;
      for (const Move& m : moves) band_steps += m.yhi < band_ylo || m.ylo > band_yhi ? 0.0 : m.steps + 1.0;
      for (const Move& m : moves) {
        if (m.yhi < band_ylo || m.ylo > band_yhi) continue;
        removed.clear();
        for (std::size_t step = m.first ? 0 : 1; step <= m.steps; ++step, ++steps_done) {
          if (ctx.stopping()) return;
          ctx.done_within(static_cast<double>(band - b0) + steps_done / band_steps);
          const Pose p = pose_at(m, step);
          if (p.yhi < band_ylo || p.ylo > band_yhi) continue;
          ++out.stats.instances;
          const double ax = p.a.x(), ay = p.a.y(), az = p.a.z();
          const double cx = p.C.x(), cy = p.C.y(), cz = p.C.z();
          const double sb2 = p.sin_b * p.sin_b;
          const double jlo = std::max(static_cast<double>(j0), std::ceil((p.ylo - y0) / cell - 0.5));
          const double jhi = std::min(static_cast<double>(j1), std::floor((p.yhi - y0) / cell - 0.5));
          for (double jd = jlo; jd <= jhi; ++jd) {
            const auto j = static_cast<std::size_t>(jd);
            const double y = stock.cy(j), qy = y - cy;
            const auto [xlo, xhi] = stadium_row(p, Rt, y);
            if (!(xlo <= xhi)) continue;
            const double ilo = std::max(0.0, std::ceil((xlo - x0) / cell - 0.5));
            const double ihi = std::min(static_cast<double>(nx) - 1.0, std::floor((xhi - x0) / cell - 0.5));
            if (ilo > ihi) continue;
            double* row = z.data() + j * nx;
            const auto i0 = static_cast<std::size_t>(ilo), i1 = static_cast<std::size_t>(ihi);
            out.stats.cells_tested += i1 - i0 + 1;
            for (std::size_t i = i0; i <= i1; ++i) {
              const double zc = row[i];
              if (zc <= p.zmin) continue;  // already below everything of this instance
              const double qx = stock.cx(i) - cx, dz = zc - cz;
              const double qa = qx * ax + qy * ay;
              const double hp = qa + dz * az;  // the cell top's height above the centre plane
              if (hp < -Ri - kPruneMargin) continue;  // the solid has h >= -Ri, and h falls down the line
              // Going down the line from the cell top by s, h = h_p - a_z s and rho^2(s) = rho_p^2 - 2 m s +
              // sin^2(b) s^2 (m = r_p . e_perp = dz - a_z h_p): rho is convex in s. Each part is tested on the
              // stretch of the line where it can be (the torus: |h| <= Ri inside the ball |x - C| <= Ro + Ri).
              const double qq = qx * qx + qy * qy;
              const double dd = qq + dz * dz;  // |p - C|^2
              const double rho2 = dd - hp * hp, mm = dz - az * hp;
              auto rho2_at = [&](double sv) { return std::max(rho2 - 2.0 * mm * sv + sb2 * sv * sv, 0.0); };
              auto rho2_min = [&](double lo, double hi) {  // min of rho^2 over s in [lo, hi]
                return rho2_at(sb2 > 0.0 ? std::clamp(mm / sb2, lo, hi) : lo);
              };
              // The shank {rho <= Rt, h >= 0} and the flat core {rho <= Ro, h >= -Ri}: exact tests.
              const bool shank = hp >= 0.0 && rho2_min(0.0, hp / az) <= Rt2_hit;
              const bool flat = core && rho2_min(0.0, (hp + Ri) / az) <= Ro2_hit;
              // The quartic decides most lines at the price of one evaluation; the bounds decide the rest.
              const Line l{qa, qq, az};
              const Quartic quartic = ball ? Quartic{} : torus_quartic(l, Ro, Ri);
              const Verdict verdict = ball ? Verdict::Unknown : torus_below(quartic, dz);
              bool torus = verdict == Verdict::Yes;
              if (verdict == Verdict::Unknown && qq <= Rt2_hit) {
                const double w = std::sqrt(Rt2_hit - qq);
                const double lo = std::max({0.0, (hp - Ri) / az, dz - w}), hi = std::min((hp + Ri) / az, dz + w);
                // Inside the torus: |x - C|^2 + Ro^2 - Ri^2 <= 2 Ro rho, and rho lies under its chord on each
                // half of [lo, hi]: the quadratic G(s) = |x - C|^2 + Ro^2 - Ri^2 - 2 Ro chord(s) <= 0 somewhere.
                if (lo <= hi) {
                  const double mid = 0.5 * (lo + hi);
                  const double r_lo = std::sqrt(rho2_at(lo)), r_mid = std::sqrt(rho2_at(mid));
                  const double r_hi = std::sqrt(rho2_at(hi));
                  auto may_enter = [&](double u, double v, double ru, double rv) {
                    const double k = v - u > 1e-12 ? (rv - ru) / (v - u) : 0.0;
                    const double sv = std::clamp(dz + Ro * k, u, v);
                    const double G = sv * sv - 2.0 * (dz + Ro * k) * sv + dd + Ro2mRi2 - 2.0 * Ro * (ru - k * u);
                    return G <= g_margin;
                  };
                  torus = may_enter(lo, mid, r_lo, r_mid) || may_enter(mid, hi, r_mid, r_hi);
                }
              }
              if (!(torus || shank || flat)) continue;
              double t = kInf;
              if (torus) {
                ++out.stats.exact_solves;
                std::size_t* fallback = &out.stats.fallback_solves;
                t = ball ? torus_lowest(l, Ro, Ri, fallback) : torus_lowest(quartic, l, Ro, Ri, fallback, dz);
              }
              if (shank) t = std::min(t, half_cylinder_lowest(l, Rt, 0.0));
              if (flat) t = std::min(t, half_cylinder_lowest(l, Ro, -Ri));
              const double zl = t + cz;
              if (zl < zc) {
                ++out.stats.lowerings;
                if (m.rapid) removed.emplace_back(j * nx + i, zc);
                row[i] = zl;
              }
            }
          }
        }
        if (m.rapid && !removed.empty()) {
          double depth = 0.0;
          for (const auto& [c, zb] : removed) depth = std::max(depth, zb - z[c]);
          out.removals.push_back({m.k, depth});
        }
      }
      for (std::size_t c = 0; c < before.size(); ++c) out.lowered += z[j0 * nx + c] < before[c];
    }
  });

  // Merge the bands: deepest removal per rapid over all bands (max: independent of the order).
  std::vector<RapidCollision> all;
  Sweep5Stats stats;
  for (const BandResult& b : bands) {
    report.cells_lowered += b.lowered;
    all.insert(all.end(), b.removals.begin(), b.removals.end());
    stats.cells_tested += b.stats.cells_tested;
    stats.exact_solves += b.stats.exact_solves;
    stats.fallback_solves += b.stats.fallback_solves;
    stats.lowerings += b.stats.lowerings;
  }
  std::sort(all.begin(), all.end(), [](const RapidCollision& a, const RapidCollision& b) {
    return a.move < b.move || (a.move == b.move && a.depth > b.depth);
  });
  for (const RapidCollision& c : all) {
    if (!report.collisions.empty() && report.collisions.back().move == c.move) continue;  // the deepest came first
    if (c.depth > options.collision_tol) report.collisions.push_back(c);
  }
  for (const Move& m : moves) stats.instances += m.steps + (m.first ? 1 : 0);
  if (stats_out) *stats_out = stats;
  return report;
}

}  // namespace tmm
