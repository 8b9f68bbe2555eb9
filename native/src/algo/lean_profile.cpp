// Lean passes: the exact profile along a run by adaptive drops, the min-link fit in its band, the checks.
// See tmm/algo/lean_profile.hpp for the method.
#include "tmm/algo/lean_profile.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <sstream>
#include <stdexcept>
#include <string>
#include <utility>

#include "lean_arcs.hpp"
#include "tmm/query/drop_cutter.hpp"
#include "tmm/util/range.hpp"

namespace tmm {

namespace {

constexpr double kVertical = 1e-7;       // mm: a move this short in XY is vertical
constexpr double kNotExact = 1e-6;       // mm: a given sample this far from the exact drop is not on the profile
constexpr double kExactSlack = 1e-9;     // mm: the band at a vertex that stays exact
constexpr double kMaxSlope = 1e4;        // |dz/ds| of a move (steeper: a vertical move, split before)
constexpr double kMaxLeanDrops = 5e7;    // the profile's drops at max_step over all runs, at most
constexpr double kCheckFailure = 0.98;   // of tol: a check point farther from its move fails

struct Point {
  double z0, m;
};
using Polygon = std::vector<Point>;

// Keeps the part of the convex polygon where a * z0 + b * m <= c (Sutherland-Hodgman, one edge).
void clip(const Polygon& in, double a, double b, double c, Polygon& out) {
  out.clear();
  const std::size_t n = in.size();
  for (std::size_t i = 0; i < n; ++i) {
    const Point& p = in[i];
    const Point& q = in[(i + 1) % n];
    const double fp = a * p.z0 + b * p.m - c, fq = a * q.z0 + b * q.m - c;
    if (fp <= 0) out.push_back(p);
    if ((fp < 0 && fq > 0) || (fp > 0 && fq < 0)) {
      const double u = fp / (fp - fq);
      out.push_back({p.z0 + u * (q.z0 - p.z0), p.m + u * (q.m - p.m)});
    }
  }
}

struct Piece {
  std::size_t w, end;  // drop indices of its start and end
  double zlo, zhi;     // the window of its start heights
};

// The band at drop i of a stretch of n drops: the ends exact, never below the floor (a final depth holds).
struct Band {
  const std::vector<double>& e;
  double half;
  double floor;
  double lo(std::size_t i) const {
    return std::max(e[i] - (i == 0 || i + 1 == e.size() ? kExactSlack : half), std::min(floor, e[i]));
  }
  double hi(std::size_t i) const { return e[i] + (i == 0 || i + 1 == e.size() ? kExactSlack : half); }
};

// The farthest drop a line from (t[w], z in [zlo, zhi]) reaches within the band at w+1 .. end, and the window of
// its heights there ([lo, hi] of the lines that do).
std::size_t reach(const std::vector<double>& t, const Band& band, std::size_t w, double zlo, double zhi,
                  double& wlo, double& whi, Polygon& poly, Polygon& next) {
  poly = {{zlo - kExactSlack, -kMaxSlope}, {zhi + kExactSlack, -kMaxSlope}, {zhi + kExactSlack, kMaxSlope},
          {zlo - kExactSlack, kMaxSlope}};
  const std::size_t n = t.size();
  std::size_t j = w + 1;
  for (; j < n; ++j) {
    const double d = t[j] - t[w];
    clip(poly, 1.0, d, band.hi(j), next);
    if (next.size() < 3) break;
    Polygon tmp;
    clip(next, -1.0, -d, -band.lo(j), tmp);
    if (tmp.size() < 3) break;
    poly.swap(tmp);
  }
  const std::size_t end = std::max(j - 1, w + 1);
  if (end == j) {  // not even the next drop (numerically): the line to its exact height
    wlo = whi = band.e[end];
    return end;
  }
  const double d = t[end] - t[w];
  wlo = INFINITY, whi = -INFINITY;
  for (const Point& p : poly) {
    wlo = std::min(wlo, p.z0 + p.m * d);
    whi = std::max(whi, p.z0 + p.m * d);
  }
  wlo = std::max(wlo, band.lo(end));
  whi = std::min(whi, band.hi(end));
  if (wlo > whi) wlo = whi = std::clamp(band.e[end], band.lo(end), band.hi(end));
  return end;
}

// Min-link polyline (vertex indices and heights) through the band about e at t, both ends exact.
void fit(const std::vector<double>& t, const std::vector<double>& e, double half, double floor,
         std::vector<std::size_t>& vi, std::vector<double>& vz) {
  const Band band{e, half, floor};
  const std::size_t n = t.size();
  std::vector<Piece> pieces;
  Polygon poly, next;
  std::size_t w = 0;
  double zlo = e[0], zhi = e[0];
  while (w + 1 < n) {
    double wlo, whi;
    const std::size_t end = reach(t, band, w, zlo, zhi, wlo, whi, poly, next);
    pieces.push_back({w, end, zlo, zhi});
    w = end, zlo = wlo, zhi = whi;
  }
  // Backwards: each start height in the middle of those whose line to the (known) end stays in the band.
  vi.assign(pieces.size() + 1, 0);
  vz.assign(pieces.size() + 1, 0.0);
  vi.back() = n - 1;
  vz.back() = e[n - 1];
  double z_end = e[n - 1];
  for (std::size_t k = pieces.size(); k-- > 0;) {
    const Piece& p = pieces[k];
    const double D = t[p.end] - t[p.w];
    double A = p.zlo, B = p.zhi;
    for (std::size_t j = p.w + 1; j < p.end; ++j) {
      const double g = (t[j] - t[p.w]) / D, f = 1.0 - g;
      if (f <= 1e-15) continue;
      A = std::max(A, (band.lo(j) - z_end * g) / f);
      B = std::min(B, (band.hi(j) - z_end * g) / f);
    }
    const double z0 = k == 0 ? e[0] : 0.5 * (A + B);
    vi[k] = p.w;
    vz[k] = z0;
    z_end = z0;
  }
}

// Least groups of consecutive drops each within the band of one line (the lower bound of the header).
std::size_t stab_count(const std::vector<double>& t, const std::vector<double>& e, double half, double floor) {
  const Band band{e, half, floor};
  const std::size_t n = t.size();
  Polygon poly, next;
  std::size_t groups = 0, w = 0;
  while (w < n) {
    ++groups;
    if (w + 1 == n) break;
    double wlo, whi;
    const std::size_t end = reach(t, band, w, band.lo(w), band.hi(w), wlo, whi, poly, next);
    w = end + 1;
  }
  return groups;
}

struct RunOut {
  std::vector<double> s, z, arc_s, arc_z;
  std::size_t drops = 0, breakpoints = 0, refits = 0, kept_dense = 0, lower_bound = 0, arcs = 0;
};

class RunLean {
 public:
  RunLean(const MeshIndex& index, const Cutter& tool, const LeanOptions& o, double x0, double y0, double ux,
          double uy, bool with_arcs, const ChunkContext& ctx)
      : index_(index), tool_(tool), o_(o), x0_(x0), y0_(y0), ux_(ux), uy_(uy), with_arcs_(with_arcs), ctx_(ctx) {}

  void run(const double* s, const double* z, const std::uint8_t* flags, std::size_t n, bool arcs, RunOut& out) {
    arcs_ = arcs;
    profile(s, z, flags, n, out);
    out.s.push_back(t_[0]);
    out.z.push_back(e_[0]);
    line_to(out, 1);
    std::size_t a = 0;
    for (std::size_t b = 1; b < t_.size(); ++b) {
      if (!fixed_[b] && b + 1 < t_.size()) continue;
      if (keep_[a]) {  // a kept move (both ends fixed: b == a + 1)
        out.s.push_back(t_[b]);
        out.z.push_back(e_[b]);
        line_to(out, 1);
        if (o_.lower_bound) ++out.lower_bound;
      } else {
        stretch(a, b, out);
      }
      a = b;
    }
  }

 private:
  // n line moves (no arc centre) in out's centres when some run has arcs
  void line_to(RunOut& out, std::size_t n) const {
    if (!with_arcs_) return;
    out.arc_s.insert(out.arc_s.end(), n, std::numeric_limits<double>::quiet_NaN());
    out.arc_z.insert(out.arc_z.end(), n, std::numeric_limits<double>::quiet_NaN());
  }

  double exact(double t, int32_t* hint, bool* air) {
    ctx_.throw_if_stopping();  // one run can be long: cancel between its drops
    ++drops_;
    return lean_exact(index_, tool_, o_.drop, x0_ + t * ux_, y0_ + t * uy_, hint, air);
  }

  struct Drop {
    double t, z;
    int32_t w;
  };

  // Drops between (ta, za, wa) and (tb, zb, wb) appended in order up to b; false on air. Bisection in order
  // with an explicit stack of pending right ends (the left end is the last drop pushed). Bounded: each
  // pending end halves the interval, which stops at min_step (> 0) or when no double lies strictly between
  // its ends, so the stack holds at most log2((tb - ta) / min_step) + 1 ends, and at most 2100 whatever the
  // input (the doubles' exponent range) -- on the heap, never the call stack.
  bool refine(double ta, double za, int32_t wa, double tb, double zb, int32_t wb) {
    Drop a{ta, za, wa};
    std::vector<Drop> pending{{tb, zb, wb}};
    while (!pending.empty()) {
      const Drop b = pending.back();
      const double len = b.t - a.t, tm = 0.5 * (a.t + b.t);
      if (len <= o_.min_step || !(tm > a.t && tm < b.t)) {
        push(b.t, b.z, b.w);
        a = b;
        pending.pop_back();
        continue;
      }
      int32_t wm = a.w;
      bool air = false;
      const double zm = exact(tm, &wm, &air);
      if (air) return false;
      // every change of the triangle holding the cutter is located to min_step: cheaper rules (refining it
      // only where the midpoint leaves the chord) let two turns hide each other and the fit leave the band by 4 %
      const bool split = len > o_.max_step || std::fabs(zm - 0.5 * (a.z + b.z)) > eps_ || a.w != b.w || wm != a.w;
      if (split) {
        pending.push_back({tm, zm, wm});
        continue;
      }
      push(tm, zm, wm);
      push(b.t, b.z, b.w);
      a = b;
      pending.pop_back();
    }
    return true;
  }

  void push(double t, double e, int32_t w) {
    t_.push_back(t);
    e_.push_back(e);
    win_.push_back(w);
    fixed_.push_back(0);
    keep_.push_back(0);
  }

  // The dense exact profile t_, e_ with its fixed vertices and kept moves.
  void profile(const double* s, const double* z, const std::uint8_t* flags, std::size_t n, RunOut& out) {
    eps_ = o_.rep_fraction * o_.tol;
    std::vector<int32_t> w(n, -1);
    std::vector<std::uint8_t> off(n, 0);  // not on the exact profile (air, a refined corner): stays, moves kept
    int32_t hint = -1;
    for (std::size_t i = 0; i < n; ++i) {
      bool air = false;
      const double ze = exact(s[i], &hint, &air);
      w[i] = hint;
      off[i] = air || std::fabs(ze - z[i]) > kNotExact;
    }
    push(s[0], z[0], w[0]);
    fixed_[0] = 1;
    for (std::size_t i = 0; i + 1 < n; ++i) {
      const bool kept = (flags[i] & kLeanKeep) || off[i] || off[i + 1] || s[i + 1] - s[i] <= kVertical;
      const std::size_t before = t_.size();
      if (kept || !refine(s[i], z[i], w[i], s[i + 1], z[i + 1], w[i + 1])) {
        t_.resize(before), e_.resize(before), win_.resize(before), fixed_.resize(before), keep_.resize(before);
        push(s[i + 1], z[i + 1], w[i + 1]);
        keep_[before - 1] = 1;
        fixed_[before - 1] = fixed_[before] = 1;
      }
      if (flags[i + 1] & kLeanFixed) fixed_.back() = 1;
    }
    fixed_.back() = 1;
    for (std::size_t i = 0; i + 1 < win_.size(); ++i) breakpoints_ += !keep_[i] && win_[i] != win_[i + 1];
    out.drops += drops_;
    out.breakpoints += breakpoints_;
    drops_ = breakpoints_ = 0;
  }

  // The dense drops a..b (a and b fixed, none between) as lean vertices appended to out (after a).
  void stretch(std::size_t a, std::size_t b, RunOut& out) {
    std::vector<double> t(t_.begin() + a, t_.begin() + b + 1), e(e_.begin() + a, e_.begin() + b + 1);
    std::vector<int32_t> win(win_.begin() + a, win_.begin() + b + 1);
    if (o_.lower_bound) out.lower_bound += stab_count(t, e, o_.tol, o_.drop.clamp_floor);
    std::vector<std::size_t> vi;
    std::vector<double> vz;
    for (int round = 0;; ++round) {
      fit(t, e, o_.fit_fraction * o_.tol, o_.drop.clamp_floor, vi, vz);
      // the checks: midpoints of the drop intervals where a move comes near the edge of the fit's band
      std::vector<std::pair<double, double>> add;  // (t, exact z) of failed checks
      std::vector<int32_t> add_w;
      const double near = (2 * o_.fit_fraction - 1) * o_.tol;
      for (std::size_t k = 0; k + 1 < vi.size(); ++k) {
        const double ta = t[vi[k]], tb = t[vi[k + 1]];
        for (std::size_t j = vi[k]; j < vi[k + 1]; ++j) {
          if (t[j + 1] - t[j] <= 2 * kVertical) continue;
          const double tm = 0.5 * (t[j] + t[j + 1]);
          const double zl = vz[k] + (vz[k + 1] - vz[k]) * (tm - ta) / (tb - ta);
          if (std::fabs(zl - 0.5 * (e[j] + e[j + 1])) <= near) continue;
          int32_t h = win[j];
          bool air = false;
          const double ze = exact(tm, &h, &air);
          if (air || std::fabs(zl - ze) > kCheckFailure * o_.tol) {
            add.emplace_back(tm, ze);
            add_w.push_back(air ? -2 : h);
          }
        }
      }
      if (add.empty()) break;
      const bool air = std::find(add_w.begin(), add_w.end(), -2) != add_w.end();
      if (round >= o_.rounds || air) {  // every drop: a polyline within rep_fraction x tol of the profile
        ++kept_dense_;
        vi.resize(t.size());
        vz = e;
        for (std::size_t j = 0; j < t.size(); ++j) vi[j] = j;
        break;
      }
      ++refits_;
      // insert the failed check points as drops (they are in order of t, each between two drops)
      std::vector<double> t2, e2;
      std::vector<int32_t> w2;
      std::size_t q = 0;
      for (std::size_t j = 0; j < t.size(); ++j) {
        while (q < add.size() && add[q].first < t[j]) {
          t2.push_back(add[q].first), e2.push_back(add[q].second), w2.push_back(add_w[q]);
          ++q;
        }
        t2.push_back(t[j]), e2.push_back(e[j]), w2.push_back(win[j]);
      }
      t.swap(t2), e.swap(e2), win.swap(w2);
    }
    if (arcs_) {
      const lean::Stretch p{t, e, win, o_.fit_fraction * o_.tol, o_.drop.clamp_floor,
                            (2 * o_.fit_fraction - 1) * o_.tol, kCheckFailure * o_.tol};
      const lean::ArcLimits limits{o_.arc_min_radius, o_.arc_max_radius, o_.arc_max_slope};
      std::vector<double> cs, cz;
      out.arcs += lean::merge_arcs(p, limits, [this](double tm, int32_t h, double& z) {
        bool air = false;
        z = exact(tm, &h, &air);
        return !air;
      }, vi, vz, cs, cz);
      out.arc_s.insert(out.arc_s.end(), cs.begin() + 1, cs.end());
      out.arc_z.insert(out.arc_z.end(), cz.begin() + 1, cz.end());
    } else {
      line_to(out, vi.size() - 1);
    }
    for (std::size_t k = 1; k < vi.size(); ++k) {
      out.s.push_back(t[vi[k]]);
      out.z.push_back(vz[k]);
    }
    out.drops += drops_;
    out.refits += refits_;
    out.kept_dense += kept_dense_;
    drops_ = refits_ = kept_dense_ = 0;
  }

  const MeshIndex& index_;
  const Cutter& tool_;
  const LeanOptions& o_;
  double x0_, y0_, ux_, uy_;
  bool with_arcs_;  // some run has arcs: every vertex gets a centre (NaN for lines)
  const ChunkContext& ctx_;
  double eps_ = 0.0;
  bool arcs_ = false;  // this run fits arcs
  std::vector<double> t_, e_;
  std::vector<int32_t> win_;
  std::vector<std::uint8_t> fixed_, keep_;
  std::size_t drops_ = 0, breakpoints_ = 0, refits_ = 0, kept_dense_ = 0;
};

void require(bool ok, const std::string& what) {
  if (!ok) throw std::invalid_argument(what);
}

std::string value(const char* name, double v, const char* range) {
  std::ostringstream m;
  m << name << " must be " << range << ", got " << v;
  return m.str();
}

void validate(const LeanRuns& r, const LeanOptions& o) {
  require(std::isfinite(o.tol) && o.tol > 0 && o.tol <= 1.0, value("lean tolerance (mm)", o.tol, "in (0, 1]"));
  require(std::isfinite(o.max_step) && o.max_step > 0, value("lean max_step (mm)", o.max_step, "> 0"));
  require(std::isfinite(o.min_step) && o.min_step > 0 && o.min_step <= o.max_step,
          value("lean min_step (mm)", o.min_step, "in (0, max_step]"));
  require(o.rep_fraction > 0 && o.rep_fraction < 0.5, value("lean rep_fraction", o.rep_fraction, "in (0, 0.5)"));
  require(o.fit_fraction > 0.5 && o.fit_fraction + 2 * o.rep_fraction < 1.0,
          value("lean fit_fraction", o.fit_fraction, "in (0.5, 1 - 2 rep_fraction)"));
  require(o.rounds >= 0 && o.rounds <= 100, value("lean rounds", o.rounds, "in [0, 100]"));
  require_in_range(o.drop.drop_floor, "lean drop_floor");
  require_in_range(o.drop.z_shift, "lean z_shift");
  // -inf: no clamp, no air
  if (o.drop.clamp_floor != -kInf) require_in_range(o.drop.clamp_floor, "lean clamp_floor");
  if (o.drop.air_below != -kInf) require_in_range(o.drop.air_below, "lean air_below");
  require(!r.offsets.empty() && r.offsets.front() == 0 && r.offsets.back() == r.s.size(),
          "lean runs: offsets must start at 0 and end at the sample count");
  const std::size_t runs = r.offsets.size() - 1;
  require(r.origin.size() == 2 * runs && r.dir.size() == 2 * runs, "lean runs: 2 origin and 2 dir values per run");
  require(r.z.size() == r.s.size() && r.flags.size() == r.s.size(), "lean runs: s, z and flags of equal length");
  require(r.arcs.empty() || r.arcs.size() == runs, "lean runs: arcs must be empty or one flag per run");
  require(std::isfinite(o.arc_min_radius) && o.arc_min_radius > 0 && o.arc_max_radius > o.arc_min_radius &&
              o.arc_max_slope > 0,
          value("lean arc radius (mm)", o.arc_min_radius, "> 0, below arc_max_radius (and arc_max_slope > 0)"));
  double drops = 0;
  for (std::size_t k = 0; k < runs; ++k) {
    const std::size_t a = r.offsets[k], b = r.offsets[k + 1];
    require(b >= a + 2, "lean runs: every run needs 2 samples at least (run " + std::to_string(k) + ")");
    require(std::fabs(std::hypot(r.dir[2 * k], r.dir[2 * k + 1]) - 1.0) < 1e-9,
            "lean runs: dir must be a unit vector (run " + std::to_string(k) + ")");
    require_rows_in_range(&r.origin[2 * k], 1, 2, "lean runs: origin of run " + std::to_string(k));
    require_rows_in_range(&r.s[a], b - a, 1, "lean runs: s of run " + std::to_string(k) + ", sample");
    require_rows_in_range(&r.z[a], b - a, 1, "lean runs: z of run " + std::to_string(k) + ", sample");
    for (std::size_t i = a; i < b; ++i)
      require(std::isfinite(r.s[i]) && std::isfinite(r.z[i]) && (i == a || r.s[i] >= r.s[i - 1] - kVertical),
              "lean runs: s must be finite and non-decreasing (run " + std::to_string(k) + ")");
    drops += (r.s[b - 1] - r.s[a]) / o.max_step + (b - a);
  }
  require(drops <= kMaxLeanDrops,
          value("lean work (exact drops at max_step)", drops, "at most 5e7: raise max_step or split the job"));
}

}  // namespace

double lean_exact(const MeshIndex& index, const Cutter& tool, const LeanDrop& drop, double x, double y,
                  int32_t* hint, bool* air) {
  const double raw = drop_point(index, tool, x, y, drop.drop_floor, nullptr, hint) + drop.z_shift;
  if (air) *air = raw <= drop.air_below;
  return std::max(raw, drop.clamp_floor);
}

LeanResult lean_profiles(const MeshIndex& index, const Cutter& tool, const LeanRuns& runs,
                         const LeanOptions& options, const BatchOptions& batch) {
  validate(runs, options);
  const std::size_t n = runs.offsets.size() - 1;
  std::vector<RunOut> outs(n);
  parallel_chunks(n, 4, batch, [&](std::size_t begin, std::size_t end, ChunkContext& ctx) {
    for (std::size_t k = begin; k < end; ++k) {
      const std::size_t a = runs.offsets[k];
      RunLean lean(index, tool, options, runs.origin[2 * k], runs.origin[2 * k + 1], runs.dir[2 * k],
                   runs.dir[2 * k + 1], !runs.arcs.empty(), ctx);
      lean.run(&runs.s[a], &runs.z[a], &runs.flags[a], runs.offsets[k + 1] - a, !runs.arcs.empty() && runs.arcs[k],
               outs[k]);
    }
  });
  LeanResult r;
  r.offsets.reserve(n + 1);
  r.offsets.push_back(0);
  for (RunOut& o : outs) {
    r.s.insert(r.s.end(), o.s.begin(), o.s.end());
    r.z.insert(r.z.end(), o.z.begin(), o.z.end());
    r.arc_s.insert(r.arc_s.end(), o.arc_s.begin(), o.arc_s.end());
    r.arc_z.insert(r.arc_z.end(), o.arc_z.begin(), o.arc_z.end());
    r.offsets.push_back(r.s.size());
    r.arcs += o.arcs;
    r.drops += o.drops;
    r.breakpoints += o.breakpoints;
    r.refits += o.refits;
    r.kept_dense += o.kept_dense;
    r.lower_bound += o.lower_bound;
    o = RunOut();  // freed as we go
  }
  return r;
}

}  // namespace tmm
