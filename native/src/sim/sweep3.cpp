#include "tmm/sim/sweep3.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <sstream>
#include <stdexcept>
#include <thread>
#include <vector>

#if defined(__SSE2__)
#include <emmintrin.h>
#endif
// The block tests and the closed-form block evaluation also in AVX2 (four lanes per instruction), chosen at
// run time: the same IEEE operations in the same order per lane (no FMA), so heights are bit-identical to
// the SSE2 path.
#if defined(__SSE2__) && defined(__GNUC__) && (defined(__x86_64__) || defined(__i386__))
#include <immintrin.h>
#define TMM_SWEEP3_AVX2 1
#define TMM_AVX2 __attribute__((target("avx2")))
#endif

#include "tmm/util/range.hpp"

namespace tmm {

namespace {

// Cells per row block. Each block keeps an upper bound of its heights: a move skips the block when even
// its lowest point over the block (the move's lowest tip plus h at the block's nearest distance) is not
// below it, which in a raster is most of the tool's disc (cut already by the previous moves).
constexpr std::size_t kBlock = 8;  // at most 8: a block's lowered cells are the bits of a byte
constexpr double kArcCertificate = 1e-10;  // mm: the arc solve stops when its excess is below this

// One linear move, with what does not depend on the cell.
struct Move {
  double x0, y0, z0, x1, y1, dz, zmin;
  double dirx, diry, L;  // unit XY direction ((1, 0) for a plunge) and XY length (0 for a plunge)
  double sn, cs;         // |dz| / hypot(L, dz) and L / hypot(L, dz): the slope's sine and cosine
  double sign;           // side of the free minimiser: +1 descending (further along is lower), -1 ascending
  double zbase, kz;      // tip height z = zbase + kz s at XY offset s along the move (a plunge: its lowest)
  bool rapid;
};

Move make_move(const double* a, const double* b, bool rapid) {
  Move m;
  m.x0 = a[0], m.y0 = a[1], m.z0 = a[2];
  m.x1 = b[0], m.y1 = b[1];
  m.dz = b[2] - a[2];
  m.zmin = std::min(a[2], b[2]);
  const double dx = b[0] - a[0], dy = b[1] - a[1];
  const double L = std::hypot(dx, dy);
  if (L < kVerticalLength) {  // a plunge (or no motion): the tool's XY stays at the start
    m.dirx = 1.0, m.diry = 0.0, m.L = 0.0, m.sn = 0.0, m.cs = 1.0;
    m.zbase = m.zmin, m.kz = 0.0;
  } else {
    m.dirx = dx / L, m.diry = dy / L, m.L = L;
    const double hyp = std::hypot(L, m.dz);
    m.sn = std::fabs(m.dz) / hyp;
    m.cs = L / hyp;
    m.zbase = m.z0, m.kz = m.dz / L;
  }
  m.sign = m.dz < 0 ? 1.0 : -1.0;
  m.rapid = rapid;
  return m;
}

// Squared XY distance from the point (x0 + ddx, y0 + ddy) to the move's segment.
inline double dist2(const Move& m, double ddx, double ddy) {
  const double u = ddx * m.dirx + ddy * m.diry, q = ddy * m.dirx - ddx * m.diry;
  const double du = u < 0 ? u : (u > m.L ? u - m.L : 0.0);
  return q * q + du * du;
}

// The free minimiser |v*(q)| of  sign * |m| v + h(sqrt(v^2 + q^2))  over the reach, for any profile,
// piece by piece (see the header). Caches the last q: along a row of an axis-aligned move q is constant.
class PieceSolver {
 public:
  explicit PieceSolver(const Cutter& c)
      : R_(c.max_radius()), e_(c.arc_centre_radius()), r_(c.corner_radius()), rho_a_(c.flat_radius()),
        k1_(std::sin(c.beta1()) / std::cos(c.beta1())), vertical_end_(c.beta2() <= 0.0) {
    rho_b_ = vertical_end_ ? e_ + r_ : e_ + r_ * std::cos(c.beta2());
    k2_ = vertical_end_ ? INFINITY : std::cos(c.beta2()) / std::sin(c.beta2());
  }

  void set_move(const Move& m) {
    sn_ = m.sn, cs_ = m.cs;
    last_q_ = NAN;
  }

  double v_abs(double q) {
    if (sn_ == 0.0) return 0.0;  // level move: the nearest tip position is the lowest
    if (q == last_q_) return last_v_;
    last_q_ = q;
    last_v_ = solve(q);
    return last_v_;
  }

 private:
  double solve(double q) {
    const double q2 = q * q;
    const double w = std::sqrt(maxd(R_ * R_ - q2, 0.0));
    if (w == 0.0) return 0.0;
    double v_start = 0.0;
    // phi(v) = h'(rho) v / rho is the slope the move must beat; the root of phi = |m| lies in the first
    // piece whose far end reaches it (phi is non-decreasing). Compared as k v cs >= sn rho: no division.
    if (q < rho_a_) {  // bottom cone (h' = k1) for v in [0, va]
      const double va = std::sqrt(rho_a_ * rho_a_ - q2);
      if (k1_ * va * cs_ >= sn_ * rho_a_) {
        if (q == 0.0) return 0.0;
        return mind(sn_ * q / std::sqrt(k1_ * k1_ * cs_ * cs_ - sn_ * sn_), va);
      }
      v_start = va;
    }
    if (r_ > 0.0 && q < rho_b_) {  // corner arc for v in [v_start, vb]
      const double vb = std::sqrt(rho_b_ * rho_b_ - q2);
      if (vertical_end_ || k2_ * vb * cs_ >= sn_ * rho_b_) {
        if (e_ == 0.0) return std::clamp(sn_ * std::sqrt(maxd(r_ * r_ - q2, 0.0)), v_start, vb);
        return arc_root(q, v_start, vb);
      }
      v_start = vb;
    }
    if (vertical_end_) return w;  // the steep side: the far end of the reach
    if (k2_ * w * cs_ >= sn_ * R_) {  // taper (h' = k2) for v in [v_start, w]
      if (q == 0.0) return v_start;
      return std::clamp(sn_ * q / std::sqrt(k2_ * k2_ * cs_ * cs_ - sn_ * sn_), v_start, w);
    }
    return w;
  }

  // Arc centred off the axis: with t = rho - e, phi >= |m| exactly when
  //   P(t) = t^2 rho^2 - cs^2 q^2 t^2 - sn^2 r^2 rho^2 >= 0   (the condition squared, over 1 + m^2),
  // so P's sign brackets the root; Newton on the polynomial, bisection when it leaves the bracket. Stops
  // when |g'(v)| (v_hi - v_lo) <= kArcCertificate: by convexity g(v) - min g <= |g'(v)| |v - v*|, which
  // is at most that.
  double arc_root(double q, double v_lo, double v_hi) {
    const double q2 = q * q;
    double lo = std::clamp(std::sqrt(v_lo * v_lo + q2) - e_, 0.0, r_);
    double hi = std::clamp(rho_b_ - e_, lo, r_);
    const double cq = cs_ * cs_ * q2, sr = sn_ * sn_ * r_ * r_;
    // Start where the arc would touch if it were a ball on the axis of radius r at the offset q - e (no
    // warm start from the previous cell: a cell's height must not depend on which cells came before it).
    const double qe = maxd(q - e_, 0.0);
    double t = std::sqrt(cs_ * cs_ * qe * qe + sn_ * sn_ * r_ * r_);
    if (!(t > lo && t < hi)) t = 0.5 * (lo + hi);
    for (int it = 0; it < 200; ++it) {
      const double rho = t + e_;
      const double P = t * t * (rho * rho - cq) - sr * rho * rho;
      if (P < 0.0) lo = t;
      else hi = t;
      const double dP = 2.0 * (t * (rho * rho - cq) + t * t * rho - sr * rho);
      double tn = t - P / dP;
      if (!(tn > lo && tn < hi)) tn = 0.5 * (lo + hi);
      const double step = tn - t;
      t = tn;
      // Certify the new iterate once the steps are small (Newton's error is then about the step squared).
      if (std::fabs(step) <= 1e-6 * r_ || hi - lo <= 1e-15 * r_) {
        // Both v and the minimiser lie in [v_lo, v_hi]: that width bounds their distance.
        const double rn = t + e_;
        const double v = std::sqrt(maxd(rn * rn - q2, 0.0));
        const double gp = t / std::sqrt(maxd(r_ * r_ - t * t, 0.0)) * (rn > 0 ? v / rn : 0.0) - sn_ / cs_;
        if (std::fabs(gp) * (v_hi - v_lo) <= kArcCertificate || hi - lo <= 1e-15 * r_) {
          return std::clamp(v, v_lo, v_hi);
        }
      }
    }
    return std::clamp(std::sqrt(maxd((t + e_) * (t + e_) - q2, 0.0)), v_lo, v_hi);
  }

  double R_, e_, r_, rho_a_, rho_b_ = 0, k1_, k2_ = 0;
  bool vertical_end_;
  double sn_ = 0, cs_ = 1, last_q_ = NAN, last_v_ = 0;
};

// Per-profile pieces of the cell update, inlined into the row loop.
struct BallProfile {  // h = r - sqrt(r^2 - rho^2): reach and minimiser without the solver
  double r, r2;
  static constexpr bool kSseValue = true, kSseSolve = true;
  explicit BallProfile(const Cutter& c) : r(c.corner_radius()), r2(r * r) {}
  void set_move(const Move&) {}
  double reach2(double lift) const { return lift < r ? lift * (2.0 * r - lift) : INFINITY; }
  double v_abs(const Move& m, double q) const { return m.sn * std::sqrt(maxd(r2 - q * q, 0.0)); }
  double h(double rho2) const { return r - std::sqrt(maxd(r2 - rho2, 0.0)); }
#if defined(__SSE2__)
  __m128d reach2_sse(__m128d lift) const {  // as reach2; a lift <= 0 gives a reach <= 0
    const __m128d vr = _mm_set1_pd(r), in = _mm_cmplt_pd(lift, vr);
    const __m128d q = _mm_mul_pd(lift, _mm_sub_pd(_mm_add_pd(vr, vr), lift));
    return _mm_or_pd(_mm_and_pd(in, q), _mm_andnot_pd(in, _mm_set1_pd(INFINITY)));
  }
  __m128d v_abs_sse(const Move& m, __m128d q2) const {
    return _mm_mul_pd(_mm_set1_pd(m.sn), _mm_sqrt_pd(_mm_max_pd(_mm_sub_pd(_mm_set1_pd(r2), q2), _mm_setzero_pd())));
  }
  __m128d value_sse(__m128d zt, __m128d rho2) const {
    const __m128d d = _mm_max_pd(_mm_sub_pd(_mm_set1_pd(r2), rho2), _mm_setzero_pd());
    return _mm_add_pd(zt, _mm_sub_pd(_mm_set1_pd(r), _mm_sqrt_pd(d)));
  }
#endif
#if defined(TMM_SWEEP3_AVX2)
  TMM_AVX2 __m256d reach2_avx(__m256d lift) const {
    const __m256d vr = _mm256_set1_pd(r), in = _mm256_cmp_pd(lift, vr, _CMP_LT_OQ);
    const __m256d q = _mm256_mul_pd(lift, _mm256_sub_pd(_mm256_add_pd(vr, vr), lift));
    return _mm256_blendv_pd(_mm256_set1_pd(INFINITY), q, in);
  }
  TMM_AVX2 __m256d v_abs_avx(const Move& m, __m256d q2) const {
    const __m256d d = _mm256_max_pd(_mm256_sub_pd(_mm256_set1_pd(r2), q2), _mm256_setzero_pd());
    return _mm256_mul_pd(_mm256_set1_pd(m.sn), _mm256_sqrt_pd(d));
  }
  TMM_AVX2 __m256d value_avx(__m256d zt, __m256d rho2) const {
    const __m256d d = _mm256_max_pd(_mm256_sub_pd(_mm256_set1_pd(r2), rho2), _mm256_setzero_pd());
    return _mm256_add_pd(zt, _mm256_sub_pd(_mm256_set1_pd(r), _mm256_sqrt_pd(d)));
  }
#endif
};

struct FlatProfile {  // h = 0: the lowest tip still within reach
  double R2;
  static constexpr bool kSseValue = true, kSseSolve = true;
  explicit FlatProfile(const Cutter& c) : R2(c.max_radius() * c.max_radius()) {}
  void set_move(const Move&) {}
  double reach2(double) const { return INFINITY; }
  double v_abs(const Move& m, double q) const { return m.sn > 0.0 ? std::sqrt(maxd(R2 - q * q, 0.0)) : 0.0; }
  double h(double) const { return 0.0; }
#if defined(__SSE2__)
  __m128d reach2_sse(__m128d lift) const {  // everywhere within the reach when the lift is positive
    const __m128d up = _mm_cmpgt_pd(lift, _mm_setzero_pd());
    return _mm_or_pd(_mm_and_pd(up, _mm_set1_pd(INFINITY)), _mm_andnot_pd(up, _mm_set1_pd(-1.0)));
  }
  __m128d v_abs_sse(const Move& m, __m128d q2) const {
    if (!(m.sn > 0.0)) return _mm_setzero_pd();
    return _mm_sqrt_pd(_mm_max_pd(_mm_sub_pd(_mm_set1_pd(R2), q2), _mm_setzero_pd()));
  }
  __m128d value_sse(__m128d zt, __m128d) const { return zt; }
#endif
#if defined(TMM_SWEEP3_AVX2)
  TMM_AVX2 __m256d reach2_avx(__m256d lift) const {
    const __m256d up = _mm256_cmp_pd(lift, _mm256_setzero_pd(), _CMP_GT_OQ);
    return _mm256_blendv_pd(_mm256_set1_pd(-1.0), _mm256_set1_pd(INFINITY), up);
  }
  TMM_AVX2 __m256d v_abs_avx(const Move& m, __m256d q2) const {
    if (!(m.sn > 0.0)) return _mm256_setzero_pd();
    return _mm256_sqrt_pd(_mm256_max_pd(_mm256_sub_pd(_mm256_set1_pd(R2), q2), _mm256_setzero_pd()));
  }
  TMM_AVX2 __m256d value_avx(__m256d zt, __m256d) const { return zt; }
#endif
};

struct GeneralProfile {
  const Cutter& c;
  PieceSolver solver;
  double R;
  static constexpr bool kSseValue = false, kSseSolve = false;
  explicit GeneralProfile(const Cutter& cutter) : c(cutter), solver(cutter), R(cutter.max_radius()) {}
  void set_move(const Move& m) { solver.set_move(m); }
  double reach2(double lift) const { return c.reach2(lift); }
  double v_abs(const Move&, double q) { return solver.v_abs(q); }
  double h(double rho2) const { return c.height(mind(std::sqrt(rho2), R)); }
};

// Bull-nose: v*(q) by the solver (once per row along the rows, else per cell on the scalar path), the rest
// in closed form: h = r - sqrt(r^2 - (rho - e)^2) beyond the flat, zero on it.
struct BullProfile : GeneralProfile {
  static constexpr bool kSseValue = true, kSseSolve = false;
  double e, r;
  explicit BullProfile(const Cutter& cutter)
      : GeneralProfile(cutter), e(cutter.arc_centre_radius()), r(cutter.corner_radius()) {}
#if defined(__SSE2__)
  __m128d reach2_sse(__m128d lift) const {  // rho = e + sqrt(r^2 - (r - lift)^2) on the arc
    const __m128d zero = _mm_setzero_pd(), vr = _mm_set1_pd(r);
    const __m128d a = _mm_sub_pd(vr, lift);
    const __m128d rho = _mm_add_pd(_mm_set1_pd(e), _mm_sqrt_pd(_mm_max_pd(_mm_sub_pd(_mm_mul_pd(vr, vr), _mm_mul_pd(a, a)), zero)));
    const __m128d arc = _mm_mul_pd(rho, rho), up = _mm_cmpgt_pd(lift, zero), over = _mm_cmpge_pd(lift, vr);
    const __m128d in = _mm_or_pd(_mm_and_pd(over, _mm_set1_pd(INFINITY)), _mm_andnot_pd(over, arc));
    return _mm_or_pd(_mm_and_pd(up, in), _mm_andnot_pd(up, _mm_set1_pd(-1.0)));
  }
  __m128d v_abs_sse(const Move&, __m128d) const { return _mm_setzero_pd(); }  // not used: kSseSolve
  __m128d value_sse(__m128d zt, __m128d rho2) const {
    const __m128d zero = _mm_setzero_pd(), vr = _mm_set1_pd(r);
    const __m128d t = _mm_max_pd(_mm_sub_pd(_mm_sqrt_pd(rho2), _mm_set1_pd(e)), zero);
    const __m128d d = _mm_max_pd(_mm_sub_pd(_mm_mul_pd(vr, vr), _mm_mul_pd(t, t)), zero);
    return _mm_add_pd(zt, _mm_sub_pd(vr, _mm_sqrt_pd(d)));
  }
#endif
#if defined(TMM_SWEEP3_AVX2)
  TMM_AVX2 __m256d reach2_avx(__m256d lift) const {
    const __m256d zero = _mm256_setzero_pd(), vr = _mm256_set1_pd(r);
    const __m256d a = _mm256_sub_pd(vr, lift);
    const __m256d rho = _mm256_add_pd(
        _mm256_set1_pd(e), _mm256_sqrt_pd(_mm256_max_pd(_mm256_sub_pd(_mm256_mul_pd(vr, vr), _mm256_mul_pd(a, a)), zero)));
    const __m256d arc = _mm256_mul_pd(rho, rho), up = _mm256_cmp_pd(lift, zero, _CMP_GT_OQ);
    const __m256d over = _mm256_cmp_pd(lift, vr, _CMP_GE_OQ);
    return _mm256_blendv_pd(_mm256_set1_pd(-1.0), _mm256_blendv_pd(arc, _mm256_set1_pd(INFINITY), over), up);
  }
  TMM_AVX2 __m256d v_abs_avx(const Move&, __m256d) const { return _mm256_setzero_pd(); }  // not used
  TMM_AVX2 __m256d value_avx(__m256d zt, __m256d rho2) const {
    const __m256d zero = _mm256_setzero_pd(), vr = _mm256_set1_pd(r);
    const __m256d t = _mm256_max_pd(_mm256_sub_pd(_mm256_sqrt_pd(rho2), _mm256_set1_pd(e)), zero);
    const __m256d d = _mm256_max_pd(_mm256_sub_pd(_mm256_mul_pd(vr, vr), _mm256_mul_pd(t, t)), zero);
    return _mm256_add_pd(zt, _mm256_sub_pd(vr, _mm256_sqrt_pd(d)));
  }
#endif
};

// Index range [lo, hi] of the cell centres g0 + (i + 0.5) cell in [a, b], clamped to [0, n); false if none.
// Widened by a hair: the exact distance test per cell decides. (Integer conversion after clamping to a small
// range: std::floor and std::ceil are calls without SSE4.1, and this runs for every row of every move.)
bool index_range(double a, double b, double g0, double cell, std::size_t n, std::size_t& lo, std::size_t& hi) {
  const double fl = (a - g0) / cell - 0.5 - 1e-9, fh = (b - g0) / cell - 0.5 + 1e-9;
  const double top = static_cast<double>(n) - 1;
  if (!(fl <= fh) || fh < 0.0 || fl > top) return false;
  const double cl = maxd(fl, 0.0), ch = mind(fh, top);  // in [0, n - 1]: safe to convert
  std::size_t l = static_cast<std::size_t>(cl);
  if (static_cast<double>(l) < cl) ++l;  // ceil
  const std::size_t h = static_cast<std::size_t>(ch);  // floor (ch >= 0)
  if (l > h) return false;
  lo = l, hi = h;
  return true;
}

// The x-interval of the row y = Y inside the move's capsule (segment grown by R): the hull of the end
// discs' chords and of the crossings of the two long sides.
bool capsule_row(const Move& m, double Y, double R, double& xlo, double& xhi) {
  xlo = INFINITY, xhi = -INFINITY;
  const double R2 = R * R;
  const double d0 = Y - m.y0, d1 = Y - m.y1;
  if (d0 * d0 <= R2) {
    const double hw = std::sqrt(R2 - d0 * d0);
    xlo = mind(xlo, m.x0 - hw), xhi = maxd(xhi, m.x0 + hw);
  }
  if (m.L > 0.0) {
    if (d1 * d1 <= R2) {
      const double hw = std::sqrt(R2 - d1 * d1);
      xlo = mind(xlo, m.x1 - hw), xhi = maxd(xhi, m.x1 + hw);
    }
    if (m.diry != 0.0) {
      for (const double w : {-R, R}) {  // sides p0 + s dir + w (-diry, dirx), s in [0, L]
        const double s = (d0 - w * m.dirx) / m.diry;
        if (s >= 0.0 && s <= m.L) {
          const double x = m.x0 + s * m.dirx - w * m.diry;
          xlo = mind(xlo, x), xhi = maxd(xhi, x);
        }
      }
    }
  }
  return xlo <= xhi;
}

// A band of rows and what it learns while cutting.
struct BandResult {
  std::size_t lowered = 0;
  std::vector<RapidCollision> removals;  // rapids that removed anything, in move order
};

class BandCutter {
 public:
  BandCutter(ZMap& stock, std::size_t j0, std::size_t j1)
      : z_(stock), j0_(j0), j1_(j1), nx_(stock.nx()), nblk_((stock.nx() + kBlock - 1) / kBlock),
        bx_lo_(nblk_), bx_hi_(nblk_), bmax_((j1 - j0 + 1) * nblk_, -INFINITY),
        lowered_((j1 - j0 + 1) * nblk_, 0), cx_(nx_) {
    for (std::size_t i = 0; i < nx_; ++i) cx_[i] = stock.cx(i);
    for (std::size_t b = 0; b < nblk_; ++b) {
      bx_lo_[b] = stock.cx(b * kBlock);
      bx_hi_[b] = stock.cx(std::min(nx_, (b + 1) * kBlock) - 1);
    }
    for (std::size_t j = j0; j <= j1; ++j)
      for (std::size_t b = 0; b < nblk_; ++b) refresh_block(j, b);
  }

  template <class Profile>
  void cut(Profile& prof, const Move& m, double R, BandResult& out) {
    prof.set_move(m);
    std::size_t ja, jb;
    if (!index_range(mind(m.y0, m.y1) - R, maxd(m.y0, m.y1) + R, z_.y0(), z_.cell(), z_.ny(), ja, jb)) return;
    ja = std::max(ja, j0_), jb = std::min(jb, j1_);
    const double R2 = R * R, cell = z_.cell();
    double removed = 0.0;
    for (std::size_t j = ja; j <= jb; ++j) {
      const double Y = z_.cy(j), ddy = Y - m.y0;
      double xlo, xhi;
      std::size_t ia, ib;
      if (!capsule_row(m, Y, R, xlo, xhi) || !index_range(xlo, xhi, z_.x0(), cell, nx_, ia, ib)) continue;
      // Where along the row the distance to the segment is least (the lowest such x for a move along the
      // row): the distance is convex along the row, so a block's nearest point is this clamped into it.
      double xs;
      if (m.L == 0.0 || m.diry == 0.0) {
        xs = m.L == 0.0 ? m.x0 : mind(m.x0, m.x1);
      } else {
        const double s = ddy / m.diry;
        xs = s <= 0.0 ? m.x0 : (s >= m.L ? m.x1 : m.x0 + s * m.dirx);
      }
      // Along a move parallel to the rows q is the same for the whole row: solve v*(q) once.
      const bool q_const = m.diry == 0.0;
      double va_row = -1.0;  // solved at the row's first block that may be lowered
      double* row = &z_.at(0, j);
      double* bmax = &bmax_[(j - j0_) * nblk_];
      std::uint8_t* low = &lowered_[(j - j0_) * nblk_];
      // Blocks the move may lower, 64 at a time as a bit mask (the tests are branch-free), then those.
      for (std::size_t bb = ia / kBlock, blast = ib / kBlock; bb <= blast; bb += 64) {
       std::uint64_t mask = block_mask(prof, m, ddy, xs, bmax, bb, std::min(blast, bb + 63));
       for (; mask != 0; mask &= mask - 1) {
        const std::size_t b = bb + static_cast<std::size_t>(__builtin_ctzll(mask));
        const std::size_t ca = b * kBlock, cb = std::min(nx_, ca + kBlock);  // the whole block [ca, cb)
        if (q_const && va_row < 0.0) va_row = prof.v_abs(m, std::fabs(ddy * m.dirx));
#if defined(__SSE2__)
        if constexpr (Profile::kSseValue) {
          if (cb - ca == kBlock && (q_const || Profile::kSseSolve)) {
#if defined(TMM_SWEEP3_AVX2)
            if (avx2_) {
              block_avx(prof, m, ddy, q_const, va_row, row, low[b], ca, R2, removed, bmax[b]);
              continue;
            }
#endif
            block_sse(prof, m, ddy, q_const, va_row, row, low[b], ca, R2, removed, bmax[b]);
            continue;
          }
        }
#endif
        for (std::size_t i = ca; i < cb; ++i) {
          const double ddx = z_.cx(i) - m.x0;
          const double u = ddx * m.dirx + ddy * m.diry, q = ddy * m.dirx - ddx * m.diry;
          const double du = u < 0 ? u : (u > m.L ? u - m.L : 0.0);
          const double d2 = q * q + du * du;
          const double zc = row[i];
          // The solve costs: first the bound by the move's lowest point.
          if (!(d2 <= R2 && zc - m.zmin > 0.0 && d2 < prof.reach2(zc - m.zmin))) continue;
          const double v = std::clamp(m.sign * prof.v_abs(m, std::fabs(q)), -u, m.L - u);
          const double zt = m.zbase + m.kz * std::clamp(u + v, 0.0, m.L);
          const double val = zt + prof.h(mind(v * v + q * q, R2));
          if (val < zc) {
            row[i] = val;
            low[b] |= static_cast<std::uint8_t>(1u << (i - ca));
            removed = maxd(removed, zc - val);
          }
        }
        refresh_block(j, b);
       }
      }
    }
    if (m.rapid && removed > 0.0) out.removals.push_back({current_move_, removed});
  }

  // Bit t set when block bb + t (bb + t <= be, at most 64 blocks) may be lowered by the move: when its
  // largest height is above the move's lowest point over it, the lowest tip plus h at the block's nearest
  // point (xs clamped into the block; the distance to the segment is convex along the row).
  template <class Profile>
  std::uint64_t block_mask(const Profile& prof, const Move& m, double ddy, double xs, const double* bmax,
                           std::size_t bb, std::size_t be) const {
    std::uint64_t mask = 0;
    std::size_t b = bb;
#if defined(TMM_SWEEP3_AVX2)
    if constexpr (Profile::kSseValue) {
      if (avx2_) b = block_mask_avx(prof, m, ddy, xs, bmax, bb, be, mask);
    }
#endif
#if defined(__SSE2__)
    if constexpr (Profile::kSseValue) {
      const __m128d zero = _mm_setzero_pd(), vL = _mm_set1_pd(m.L), vxs = _mm_set1_pd(xs);
      const __m128d vx0 = _mm_set1_pd(m.x0), vdx = _mm_set1_pd(m.dirx), vdy = _mm_set1_pd(m.diry);
      const __m128d ddy_dx = _mm_set1_pd(ddy * m.dirx), ddy_dy = _mm_set1_pd(ddy * m.diry);
      const __m128d vzmin = _mm_set1_pd(m.zmin);
      for (; b + 1 <= be; b += 2) {
        const __m128d xn = _mm_min_pd(_mm_max_pd(_mm_loadu_pd(&bx_lo_[b]), vxs), _mm_loadu_pd(&bx_hi_[b]));
        const __m128d ddx = _mm_sub_pd(xn, vx0);
        const __m128d u = _mm_add_pd(_mm_mul_pd(ddx, vdx), ddy_dy);
        const __m128d q = _mm_sub_pd(ddy_dx, _mm_mul_pd(ddx, vdy));
        const __m128d du = _mm_add_pd(_mm_min_pd(u, zero), _mm_max_pd(_mm_sub_pd(u, vL), zero));
        const __m128d d2 = _mm_add_pd(_mm_mul_pd(q, q), _mm_mul_pd(du, du));
        const __m128d reach = prof.reach2_sse(_mm_sub_pd(_mm_loadu_pd(bmax + b), vzmin));
        mask |= static_cast<std::uint64_t>(_mm_movemask_pd(_mm_cmplt_pd(d2, reach))) << (b - bb);
      }
    }
#endif
    for (; b <= be; ++b) {
      const double lift = bmax[b] - m.zmin;
      if (!(lift > 0.0)) continue;
      const double xn = mind(maxd(bx_lo_[b], xs), bx_hi_[b]);
      if (dist2(m, xn - m.x0, ddy) < prof.reach2(lift)) mask |= std::uint64_t{1} << (b - bb);
    }
    return mask;
  }

#if defined(__SSE2__)
  // The closed-form profiles on a whole block, two cells per instruction and without branches (the
  // square roots of neighbouring cells overlap). The same arithmetic as the scalar path.
  template <class Profile>
  void block_sse(const Profile& prof, const Move& m, double ddy, bool q_const, double va_row, double* row,
                 std::uint8_t& low, std::size_t i0, double R2, double& removed, double& block_max) const {
    const __m128d zero = _mm_setzero_pd(), vR2 = _mm_set1_pd(R2), vL = _mm_set1_pd(m.L);
    const __m128d vdx = _mm_set1_pd(m.dirx), vdy = _mm_set1_pd(m.diry), vddy = _mm_set1_pd(ddy);
    const __m128d vsign = _mm_set1_pd(m.sign), vzb = _mm_set1_pd(m.zbase), vkz = _mm_set1_pd(m.kz);
    const __m128d vx0 = _mm_set1_pd(m.x0);
    const __m128d ddy_dx = _mm_mul_pd(vddy, vdx), ddy_dy = _mm_mul_pd(vddy, vdy);
    __m128d vrem = _mm_set1_pd(removed), vmax = _mm_set1_pd(-INFINITY);
    int taken = 0;
    for (std::size_t p = 0; p < kBlock; p += 2) {
      const std::size_t i = i0 + p;
      const __m128d ddx = _mm_sub_pd(_mm_loadu_pd(&cx_[i]), vx0);
      const __m128d u = _mm_add_pd(_mm_mul_pd(ddx, vdx), ddy_dy);
      const __m128d q = _mm_sub_pd(ddy_dx, _mm_mul_pd(ddx, vdy));
      const __m128d du = _mm_add_pd(_mm_min_pd(u, zero), _mm_max_pd(_mm_sub_pd(u, vL), zero));
      const __m128d q2 = _mm_mul_pd(q, q);
      const __m128d d2 = _mm_add_pd(q2, _mm_mul_pd(du, du));
      const __m128d va = q_const ? _mm_set1_pd(va_row) : prof.v_abs_sse(m, q2);
      const __m128d v = _mm_min_pd(_mm_max_pd(_mm_mul_pd(vsign, va), _mm_sub_pd(zero, u)), _mm_sub_pd(vL, u));
      const __m128d s = _mm_min_pd(_mm_max_pd(_mm_add_pd(u, v), zero), vL);
      const __m128d zt = _mm_add_pd(vzb, _mm_mul_pd(vkz, s));
      const __m128d rho2 = _mm_min_pd(_mm_add_pd(_mm_mul_pd(v, v), q2), vR2);
      const __m128d val = prof.value_sse(zt, rho2);
      const __m128d zc = _mm_loadu_pd(row + i);
      const __m128d take = _mm_and_pd(_mm_cmple_pd(d2, vR2), _mm_cmplt_pd(val, zc));
      const __m128d nz = _mm_or_pd(_mm_and_pd(take, val), _mm_andnot_pd(take, zc));
      _mm_storeu_pd(row + i, nz);
      vrem = _mm_max_pd(vrem, _mm_sub_pd(zc, nz));
      vmax = _mm_max_pd(vmax, nz);
      taken |= _mm_movemask_pd(take) << p;
    }
    low |= static_cast<std::uint8_t>(taken);
    removed = maxd(_mm_cvtsd_f64(vrem), _mm_cvtsd_f64(_mm_unpackhi_pd(vrem, vrem)));
    block_max = maxd(_mm_cvtsd_f64(vmax), _mm_cvtsd_f64(_mm_unpackhi_pd(vmax, vmax)));
  }
#endif

#if defined(TMM_SWEEP3_AVX2)
  // block_mask's test four blocks at a time from bb on, while at least four are left: sets their bits in
  // mask and returns the first block not tested.
  template <class Profile>
  TMM_AVX2 std::size_t block_mask_avx(const Profile& prof, const Move& m, double ddy, double xs,
                                      const double* bmax, std::size_t bb, std::size_t be,
                                      std::uint64_t& mask) const {
    const __m256d zero = _mm256_setzero_pd(), vL = _mm256_set1_pd(m.L), vxs = _mm256_set1_pd(xs);
    const __m256d vx0 = _mm256_set1_pd(m.x0), vdx = _mm256_set1_pd(m.dirx), vdy = _mm256_set1_pd(m.diry);
    const __m256d ddy_dx = _mm256_set1_pd(ddy * m.dirx), ddy_dy = _mm256_set1_pd(ddy * m.diry);
    const __m256d vzmin = _mm256_set1_pd(m.zmin);
    std::size_t b = bb;
    for (; b + 3 <= be; b += 4) {
      const __m256d xn = _mm256_min_pd(_mm256_max_pd(_mm256_loadu_pd(&bx_lo_[b]), vxs), _mm256_loadu_pd(&bx_hi_[b]));
      const __m256d ddx = _mm256_sub_pd(xn, vx0);
      const __m256d u = _mm256_add_pd(_mm256_mul_pd(ddx, vdx), ddy_dy);
      const __m256d q = _mm256_sub_pd(ddy_dx, _mm256_mul_pd(ddx, vdy));
      const __m256d du = _mm256_add_pd(_mm256_min_pd(u, zero), _mm256_max_pd(_mm256_sub_pd(u, vL), zero));
      const __m256d d2 = _mm256_add_pd(_mm256_mul_pd(q, q), _mm256_mul_pd(du, du));
      const __m256d reach = prof.reach2_avx(_mm256_sub_pd(_mm256_loadu_pd(bmax + b), vzmin));
      mask |= static_cast<std::uint64_t>(_mm256_movemask_pd(_mm256_cmp_pd(d2, reach, _CMP_LT_OQ))) << (b - bb);
    }
    return b;
  }

  // block_sse four cells at a time.
  template <class Profile>
  TMM_AVX2 void block_avx(const Profile& prof, const Move& m, double ddy, bool q_const, double va_row,
                          double* row, std::uint8_t& low, std::size_t i0, double R2, double& removed,
                          double& block_max) const {
    const __m256d zero = _mm256_setzero_pd(), vR2 = _mm256_set1_pd(R2), vL = _mm256_set1_pd(m.L);
    const __m256d vdx = _mm256_set1_pd(m.dirx), vdy = _mm256_set1_pd(m.diry), vddy = _mm256_set1_pd(ddy);
    const __m256d vsign = _mm256_set1_pd(m.sign), vzb = _mm256_set1_pd(m.zbase), vkz = _mm256_set1_pd(m.kz);
    const __m256d vx0 = _mm256_set1_pd(m.x0);
    const __m256d ddy_dx = _mm256_mul_pd(vddy, vdx), ddy_dy = _mm256_mul_pd(vddy, vdy);
    __m256d vrem = _mm256_set1_pd(removed), vmax = _mm256_set1_pd(-INFINITY);
    int taken = 0;
    for (std::size_t p = 0; p < kBlock; p += 4) {
      const std::size_t i = i0 + p;
      const __m256d ddx = _mm256_sub_pd(_mm256_loadu_pd(&cx_[i]), vx0);
      const __m256d u = _mm256_add_pd(_mm256_mul_pd(ddx, vdx), ddy_dy);
      const __m256d q = _mm256_sub_pd(ddy_dx, _mm256_mul_pd(ddx, vdy));
      const __m256d du = _mm256_add_pd(_mm256_min_pd(u, zero), _mm256_max_pd(_mm256_sub_pd(u, vL), zero));
      const __m256d q2 = _mm256_mul_pd(q, q);
      const __m256d d2 = _mm256_add_pd(q2, _mm256_mul_pd(du, du));
      const __m256d va = q_const ? _mm256_set1_pd(va_row) : prof.v_abs_avx(m, q2);
      const __m256d v = _mm256_min_pd(_mm256_max_pd(_mm256_mul_pd(vsign, va), _mm256_sub_pd(zero, u)),
                                      _mm256_sub_pd(vL, u));
      const __m256d s = _mm256_min_pd(_mm256_max_pd(_mm256_add_pd(u, v), zero), vL);
      const __m256d zt = _mm256_add_pd(vzb, _mm256_mul_pd(vkz, s));
      const __m256d rho2 = _mm256_min_pd(_mm256_add_pd(_mm256_mul_pd(v, v), q2), vR2);
      const __m256d val = prof.value_avx(zt, rho2);
      const __m256d zc = _mm256_loadu_pd(row + i);
      const __m256d take = _mm256_and_pd(_mm256_cmp_pd(d2, vR2, _CMP_LE_OQ), _mm256_cmp_pd(val, zc, _CMP_LT_OQ));
      const __m256d nz = _mm256_blendv_pd(zc, val, take);
      _mm256_storeu_pd(row + i, nz);
      vrem = _mm256_max_pd(vrem, _mm256_sub_pd(zc, nz));
      vmax = _mm256_max_pd(vmax, nz);
      taken |= _mm256_movemask_pd(take) << p;
    }
    low |= static_cast<std::uint8_t>(taken);
    const __m128d rem2 = _mm_max_pd(_mm256_castpd256_pd128(vrem), _mm256_extractf128_pd(vrem, 1));
    const __m128d max2 = _mm_max_pd(_mm256_castpd256_pd128(vmax), _mm256_extractf128_pd(vmax, 1));
    removed = maxd(_mm_cvtsd_f64(rem2), _mm_cvtsd_f64(_mm_unpackhi_pd(rem2, rem2)));
    block_max = maxd(_mm_cvtsd_f64(max2), _mm_cvtsd_f64(_mm_unpackhi_pd(max2, max2)));
  }
#endif

  void set_move_index(std::size_t k) { current_move_ = k; }

  std::size_t lowered() const {
    std::size_t n = 0;
    for (const std::uint8_t f : lowered_) n += static_cast<std::size_t>(__builtin_popcount(f));
    return n;
  }

 private:
  void refresh_block(std::size_t j, std::size_t b) {
    const double* row = &z_.at(0, j);
    double mx = -INFINITY;
    for (std::size_t i = b * kBlock, e = std::min(nx_, i + kBlock); i < e; ++i) mx = maxd(mx, row[i]);
    bmax_[(j - j0_) * nblk_ + b] = mx;
  }

  ZMap& z_;
  std::size_t j0_, j1_, nx_, nblk_;
  std::vector<double> bx_lo_, bx_hi_;   // per block: x of its first and last cell centres
  std::vector<double> bmax_;            // per row block: the largest height in it
  std::vector<std::uint8_t> lowered_;   // per row block: bit i - (first cell) set when cell i was lowered
  std::vector<double> cx_;              // per column: x of the cell centres
#if defined(TMM_SWEEP3_AVX2)
  bool avx2_ = __builtin_cpu_supports("avx2");
#endif
  std::size_t current_move_ = 0;
};

[[noreturn]] void refuse(const std::string& what) { throw std::invalid_argument(what); }

}  // namespace

SimReport cut_3axis(ZMap& stock, const Cutter& cutter, const double* tips, const MoveKind* kinds,
                    std::size_t n, const Sweep3Options& options, const BatchOptions& batch) {
  if (!(std::isfinite(options.collision_tol) && options.collision_tol >= 0.0)) {
    std::ostringstream msg;
    msg << "collision_tol must be finite and >= 0 mm, got " << options.collision_tol;
    refuse(msg.str());
  }
  SimReport report;
  if (n < 2) return report;
  if (!tips) refuse("tips must not be null");
  if (!kinds) refuse("kinds must not be null when there are moves");
  if (n - 1 > std::numeric_limits<std::uint32_t>::max()) refuse("too many moves (above 4294967295)");
  for (std::size_t k = 0; k < n; ++k) {
    const double* p = tips + 3 * k;
    if (!(std::isfinite(p[0]) && std::isfinite(p[1]) && std::isfinite(p[2]))) {
      std::ostringstream msg;
      msg << "tip " << k << " is not finite: (" << p[0] << ", " << p[1] << ", " << p[2] << ")";
      refuse(msg.str());
    }
    if (!(in_range(p[0]) && in_range(p[1]) && in_range(p[2]))) {
      std::ostringstream msg;
      msg << "tip " << k << " (" << p[0] << ", " << p[1] << ", " << p[2]
          << ") " << out_of_range_text();
      refuse(msg.str());
    }
  }
  for (std::size_t k = 0; k + 1 < n; ++k) {
    const auto v = static_cast<unsigned>(kinds[k]);
    if (v > static_cast<unsigned>(MoveKind::Jump)) {
      std::ostringstream msg;
      msg << "kind of move " << k << " is " << v << ": not a move kind (0 cut, 1 rapid, 2 jump)";
      refuse(msg.str());
    }
  }

  const std::size_t ny = stock.ny();
  // The heights are writable from Python: a NaN or huge cell would stay or spread as garbage.
  const std::vector<double>& heights = stock.heights();
  for (std::size_t c = 0; c < heights.size(); ++c) {
    if (in_range(heights[c])) continue;
    std::ostringstream msg;
    msg << "stock cell (" << c % stock.nx() << ", " << c / stock.nx() << ") height " << heights[c] << " "
        << out_of_range_text();
    refuse(msg.str());
  }
  const int threads = batch.threads > 0 ? batch.threads
                                        : static_cast<int>(std::max(1u, std::thread::hardware_concurrency()));
  std::size_t band_rows = options.band_rows;
  if (band_rows == 0) band_rows = std::max<std::size_t>(8, (ny + 8 * threads - 1) / (8 * threads));
  const std::size_t bands = (ny + band_rows - 1) / band_rows;

  // Moves per band (CSR, in move order): those whose footprint's rows meet the band.
  const double R = cutter.max_radius();
  std::vector<std::size_t> count(bands + 1, 0);
  std::vector<std::uint32_t> first_band(n - 1), last_band(n - 1);
  for (std::size_t k = 0; k + 1 < n; ++k) {
    first_band[k] = 1, last_band[k] = 0;
    if (kinds[k] == MoveKind::Jump) continue;
    ++report.moves_cut;
    const double* a = tips + 3 * k;
    const double* b = a + 3;
    std::size_t ia, ib, ja, jb;
    if (!index_range(mind(a[0], b[0]) - R, maxd(a[0], b[0]) + R, stock.x0(), stock.cell(), stock.nx(), ia, ib) ||
        !index_range(mind(a[1], b[1]) - R, maxd(a[1], b[1]) + R, stock.y0(), stock.cell(), ny, ja, jb))
      continue;
    first_band[k] = static_cast<std::uint32_t>(ja / band_rows);
    last_band[k] = static_cast<std::uint32_t>(jb / band_rows);
    for (std::size_t bd = first_band[k]; bd <= last_band[k]; ++bd) ++count[bd + 1];
  }
  for (std::size_t bd = 0; bd < bands; ++bd) count[bd + 1] += count[bd];
  std::vector<std::uint32_t> moves(count[bands]);
  {
    std::vector<std::size_t> fill(count.begin(), count.end() - 1);
    for (std::size_t k = 0; k + 1 < n; ++k)
      for (std::size_t bd = first_band[k]; bd <= last_band[k]; ++bd) moves[fill[bd]++] = static_cast<std::uint32_t>(k);
  }
  first_band = {};
  last_band = {};

  std::vector<BandResult> results(bands);
  parallel_chunks(bands, 1, batch, [&](std::size_t b0, std::size_t b1, ChunkContext& ctx) {
    for (std::size_t bd = b0; bd < b1; ++bd) {
      BandCutter band(stock, bd * band_rows, std::min(ny, (bd + 1) * band_rows) - 1);
      auto run = [&](auto& profile) {
        const double in_band = static_cast<double>(count[bd + 1] - count[bd]);
        for (std::size_t e = count[bd]; e < count[bd + 1]; ++e) {
          // Progress and cancel between the moves of a band (a band can hold the whole path).
          if (ctx.stopping()) return;
          ctx.done_within(static_cast<double>(bd - b0) + static_cast<double>(e - count[bd]) / in_band);
          const std::size_t k = moves[e];
          band.set_move_index(k);
          band.cut(profile, make_move(tips + 3 * k, tips + 3 * k + 3, kinds[k] == MoveKind::Rapid), R,
                   results[bd]);
        }
      };
      if (cutter.kind() == CutterKind::Ball) {
        BallProfile p(cutter);
        run(p);
      } else if (cutter.kind() == CutterKind::Flat) {
        FlatProfile p(cutter);
        run(p);
      } else if (cutter.kind() == CutterKind::Bull) {
        BullProfile p(cutter);
        run(p);
      } else {
        GeneralProfile p(cutter);
        run(p);
      }
      results[bd].lowered = band.lowered();
    }
  });

  std::vector<RapidCollision> removals;
  for (const BandResult& r : results) {
    report.cells_lowered += r.lowered;
    removals.insert(removals.end(), r.removals.begin(), r.removals.end());
  }
  std::sort(removals.begin(), removals.end(),
            [](const RapidCollision& a, const RapidCollision& b) { return a.move < b.move; });
  for (std::size_t i = 0; i < removals.size();) {
    RapidCollision c = removals[i];
    for (++i; i < removals.size() && removals[i].move == c.move; ++i) c.depth = maxd(c.depth, removals[i].depth);
    if (c.depth > options.collision_tol) report.collisions.push_back(c);
  }
  return report;
}

}  // namespace tmm
