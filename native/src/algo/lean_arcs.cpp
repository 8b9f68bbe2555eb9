// Lean passes' arcs: see lean_arcs.hpp. In the run's vertical plane (t along the pass, z up) a circle through the
// vertices A and B has one free parameter, its signed curvature k (> 0: bulging up, the centre below). For a drop
// between A and B the arc's height there grows with k, so the band at each drop bounds k by the curvature of the
// circle through A, B and the band's edges there; the intersection over the drops gives the feasible k, and its
// middle is checked in full (midpoints, the arc's bend between drops, the exact drops near the band's edge).
#include "lean_arcs.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <optional>

namespace tmm::lean {

namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
constexpr double kSlack = 1e-12;  // mm: rounding at the band's edge

struct Circle {
  double ct = 0, cz = 0, r = 0, side = 0;  // side +1: the arc above its centre (k > 0); 0: a line
  double z(double t, double ta, double za, double tb, double zb) const {
    if (side == 0) return za + (zb - za) * (t - ta) / (tb - ta);
    return cz + side * std::sqrt(std::max(r * r - (t - ct) * (t - ct), 0.0));
  }
};

// Signed curvature of the circle through a, b and p (> 0: p left of a -> b, above it for b right of a).
double curvature(double at, double az, double bt, double bz, double pt, double pz) {
  const double cross = (bt - at) * (pz - az) - (bz - az) * (pt - at);
  const double d = std::hypot(bt - at, bz - az) * std::hypot(pt - at, pz - az) * std::hypot(bt - pt, bz - pz);
  return d > 0 ? 2.0 * cross / d : 0.0;
}

// The circle of curvature k through a and b whose minor arc is a graph z(t) over [at, bt]; none if it is not.
std::optional<Circle> circle(double at, double az, double bt, double bz, double k, const ArcLimits& lim) {
  if (k == 0) return Circle{};
  const double dt = bt - at, dz = bz - az, L = std::hypot(dt, dz);
  const double r = 1.0 / std::fabs(k);
  if (r < lim.min_radius || r > lim.max_radius || 2 * r <= L) return std::nullopt;
  const double sgn = k > 0 ? 1.0 : -1.0, off = std::sqrt(r * r - 0.25 * L * L);
  const double nt = -dz / L, nz = dt / L;  // left of a -> b
  Circle c{0.5 * (at + bt) - sgn * off * nt, 0.5 * (az + bz) - sgn * off * nz, r, sgn};
  if (sgn * (az - c.cz) <= 0 || sgn * (bz - c.cz) <= 0) return std::nullopt;  // reaches past its side's extreme
  return c;
}

// |z''| of the arc over [a, b]: 1 / (r cos^3) at the steeper end (0 for a line).
double bend(const Circle& c, double za, double zb) {
  if (c.side == 0) return 0.0;
  const double cos_min = std::min(std::fabs(za - c.cz), std::fabs(zb - c.cz)) / c.r;
  return 1.0 / (c.r * cos_min * cos_min * cos_min);
}

double band_lo(const Stretch& p, std::size_t j) { return std::max(p.e[j] - p.half, std::min(p.floor, p.e[j])); }

// The move from drop a (height za) to drop b (zb) as an arc or line within the band, checked without exact drops
// (those come last, in `exact_ok`); none if no curvature fits.
std::optional<Circle> fitting(const Stretch& p, const ArcLimits& lim, std::size_t a, double za, std::size_t b,
                              double zb) {
  const double ta = p.t[a], tb = p.t[b];
  if (tb - ta <= 0) return std::nullopt;
  double klo = -INFINITY, khi = INFINITY;
  for (std::size_t j = a + 1; j < b && klo <= khi; ++j) {
    klo = std::max(klo, curvature(ta, za, tb, zb, p.t[j], band_lo(p, j)));
    khi = std::min(khi, curvature(ta, za, tb, zb, p.t[j], p.e[j] + p.half));
  }
  if (klo > khi) return std::nullopt;
  double k = 0.0;  // a line where one fits
  if (klo > 0 || khi < 0) {
    if (std::fabs(zb - za) > lim.max_chord_slope * (tb - ta)) return std::nullopt;
    k = 0.5 * (klo + khi);
    const double kmin = 1.0 / lim.max_radius;  // flatter than allowed: the flattest the band allows
    if (std::fabs(k) < kmin) k = k > 0 ? std::min(kmin, khi) : std::max(-kmin, klo);
    if (std::fabs(k) < kmin * (1 - 1e-9)) return std::nullopt;
  }
  const std::optional<Circle> c = circle(ta, za, tb, zb, k, lim);
  if (!c) return std::nullopt;
  const double K = bend(*c, za, zb);
  for (std::size_t j = a; j < b; ++j) {
    if (j > a) {
      const double z = c->z(p.t[j], ta, za, tb, zb);
      if (z < band_lo(p, j) - kSlack || z > p.e[j] + p.half + kSlack) return std::nullopt;
    }
    const double L = p.t[j + 1] - p.t[j], tm = 0.5 * (p.t[j] + p.t[j + 1]);
    const double dev = std::fabs(c->z(tm, ta, za, tb, zb) - 0.5 * (p.e[j] + p.e[j + 1])) + K * L * L / 32;
    if (dev > p.half + kSlack) return std::nullopt;
  }
  return c;
}

// The exact drops at the midpoints where the move comes near the band's edge.
bool exact_ok(const Stretch& p, const ExactAt& exact, const Circle& c, std::size_t a, double za, std::size_t b,
              double zb) {
  const double ta = p.t[a], tb = p.t[b], K = bend(c, za, zb);
  for (std::size_t j = a; j < b; ++j) {
    const double L = p.t[j + 1] - p.t[j], tm = 0.5 * (p.t[j] + p.t[j + 1]);
    const double z = c.z(tm, ta, za, tb, zb);
    if (std::fabs(z - 0.5 * (p.e[j] + p.e[j + 1])) + K * L * L / 32 <= p.near) continue;
    double ze = 0;
    if (!exact(tm, p.win[j], ze) || std::fabs(z - ze) + K * L * L / 32 > p.fail) return false;
  }
  return true;
}

}  // namespace

std::size_t merge_arcs(const Stretch& p, const ArcLimits& limits, const ExactAt& exact, std::vector<std::size_t>& vi,
                       std::vector<double>& vz, std::vector<double>& ct, std::vector<double>& cz) {
  const std::size_t n = vi.size();
  std::vector<std::size_t> oi{vi[0]};
  std::vector<double> oz{vz[0]}, oct{kNaN}, ocz{kNaN};
  std::size_t arcs = 0;
  auto holds = [&](std::size_t a, double za, std::size_t b, double zb) -> std::optional<Circle> {
    std::optional<Circle> c = fitting(p, limits, vi[a], za, vi[b], zb);
    if (c && !exact_ok(p, exact, *c, vi[a], za, vi[b], zb)) c.reset();
    return c;
  };
  struct Candidate {
    std::size_t q;
    double z;
    Circle move;                 // from the current vertex to q
    std::optional<Circle> next;  // from q at z to q + 1 at its fitted height, where z is not that height
  };
  // The fit's lines sit anywhere in the band; an arc through two of them at its edge has no room, so a merged
  // move may end at the exact height of its end vertex (the band's middle) when the move after it still holds.
  std::size_t k = 0;
  double hk = vz[0];
  Circle after{};  // the move k -> k + 1 at vz[k + 1] known to hold: the fit's line, or one checked from hk
  while (k + 1 < n) {
    std::vector<Candidate> found;
    for (std::size_t q = k + 1; q < n; ++q) {
      bool any = false;
      const double heights[2] = {p.e[vi[q]], vz[q]};
      for (int h = q + 1 < n && heights[0] != heights[1] ? 0 : 1; h < 2 && !any; ++h) {
        const double zq = heights[h];
        const std::optional<Circle> c = fitting(p, limits, vi[k], hk, vi[q], zq);
        if (!c) continue;
        std::optional<Circle> next;
        if (h == 0 && !(next = holds(q, zq, q + 1, vz[q + 1]))) continue;
        found.push_back({q, zq, *c, next});
        any = true;
      }
      if (!any && q > k + 1) break;
    }
    const Candidate* chosen = nullptr;
    for (auto it = found.rbegin(); it != found.rend() && !chosen; ++it)
      if (exact_ok(p, exact, it->move, vi[k], hk, vi[it->q], it->z)) chosen = &*it;
    const Candidate fallback{k + 1, vz[k + 1], after, std::nullopt};
    if (!chosen) chosen = &fallback;
    const bool arc = chosen->move.side != 0;
    oi.push_back(vi[chosen->q]);
    oz.push_back(chosen->z);
    oct.push_back(arc ? chosen->move.ct : kNaN);
    ocz.push_back(arc ? chosen->move.cz : kNaN);
    arcs += arc;
    after = chosen->next.value_or(Circle{});
    k = chosen->q;
    hk = chosen->z;
  }
  vi.swap(oi), vz.swap(oz), ct.swap(oct), cz.swap(ocz);
  return arcs;
}

}  // namespace tmm::lean
