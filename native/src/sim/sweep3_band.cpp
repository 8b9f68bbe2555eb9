// The 3-axis sweep's cell update over one band of rows: per move, the rows its capsule crosses, the blocks of
// cells it may lower (a bound per block), and per cell the exact lowest point of the swept profile (scalar,
// SSE2 or AVX2: the same operations in the same order, so the same heights).
#include "sweep3_band.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <memory>
#include <vector>

#include "body_check_band.hpp"
#include "sweep3_profiles.hpp"

namespace tmm {
namespace sweep3_detail {

namespace {

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

// The band's moves with one profile (its pieces inlined into the row loop).
template <class Profile>
void cut_moves(BandCutter& band, Profile& profile, const double* tips, const MoveKind* kinds,
               const std::uint32_t* moves, std::size_t count, double R, double done_before, ChunkContext& ctx,
               BandResult& out, body_detail::BodyBand3* bodies) {
  const double in_band = static_cast<double>(count);
  for (std::size_t e = 0; e < count; ++e) {
    // Progress and cancel between the moves of a band (a band can hold the whole path).
    if (ctx.stopping()) return;
    ctx.done_within(done_before + static_cast<double>(e) / in_band);
    const std::size_t k = moves[e];
    band.set_move_index(k);
    if (bodies) bodies->move(k, tips + 3 * k, tips + 3 * k + 3, out.bodies);  // the stock before the move
    band.cut(profile, make_move(tips + 3 * k, tips + 3 * k + 3, kinds[k] == MoveKind::Rapid), R, out);
  }
}

}  // namespace

void cut_band(ZMap& stock, const Cutter& cutter, const double* tips, const MoveKind* kinds,
              const std::uint32_t* moves, std::size_t count, std::size_t j0, std::size_t j1, double done_before,
              ChunkContext& ctx, BandResult& out, const BodyCheck* check) {
  BandCutter band(stock, j0, j1);
  std::unique_ptr<body_detail::BodyBand3> bodies;
  if (check) bodies = std::make_unique<body_detail::BodyBand3>(stock, cutter, *check, j0, j1);
  const double R = cutter.max_radius();
  if (cutter.kind() == CutterKind::Ball) {
    BallProfile p(cutter);
    cut_moves(band, p, tips, kinds, moves, count, R, done_before, ctx, out, bodies.get());
  } else if (cutter.kind() == CutterKind::Flat) {
    FlatProfile p(cutter);
    cut_moves(band, p, tips, kinds, moves, count, R, done_before, ctx, out, bodies.get());
  } else if (cutter.kind() == CutterKind::Bull) {
    BullProfile p(cutter);
    cut_moves(band, p, tips, kinds, moves, count, R, done_before, ctx, out, bodies.get());
  } else {
    GeneralProfile p(cutter);
    cut_moves(band, p, tips, kinds, moves, count, R, done_before, ctx, out, bodies.get());
  }
  out.lowered = band.lowered();
}

}  // namespace sweep3_detail
}  // namespace tmm
