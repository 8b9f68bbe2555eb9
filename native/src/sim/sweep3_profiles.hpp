// The 3-axis sweep's moves and the cutter's profile pieces (internal to src/sim): what the per-cell update
// needs of a move and of the profile, the closed forms per profile and the certified solve on off-axis arcs.
// Split from the band's cell update (sweep3_band.cpp) and the tiling and threading (sweep3.cpp).
#pragma once

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>

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

#include "tmm/cutter/cutter.hpp"
#include "tmm/sim/sweep3.hpp"

namespace tmm {
namespace sweep3_detail {

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

inline Move make_move(const double* a, const double* b, bool rapid) {
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

}  // namespace sweep3_detail
}  // namespace tmm
