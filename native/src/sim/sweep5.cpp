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
#include "torus_line.hpp"

namespace tmm {

namespace {

using Eigen::Vector3d;
using namespace sweep5_detail;  // NOLINT: the solvers split off from this file

constexpr double kPruneMargin = 1e-9;  // mm: slack of the pruning bounds against rounding
constexpr std::size_t kRowsPerBand = 16;
constexpr double kMaxSteps = 1e12;   // sub-steps of one move beyond which max_step is refused as too small

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
