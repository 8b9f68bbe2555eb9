#include "tmm/sim/sweep5.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <memory>
#include <sstream>
#include <stdexcept>
#include <utility>
#include <vector>

#include "tmm/util/range.hpp"
#include "body_check_band.hpp"
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
  Vector3d tip;
  double bylo = kInf, byhi = -kInf;  // the rows the checked bodies reach (none without a body check)
};

Pose make_pose(const TorusTool& tool, const Vector3d& tip, const Vector3d& axis, double stock_top) {
  Pose p;
  p.a = axis;
  p.tip = tip;
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
  std::vector<BodyCollision> bodies;     // the body check's, per move and piece
  Sweep5Stats stats;
};

}  // namespace

double lowest_on_vertical(const TorusTool& tool, const Vector3d& tip, const Vector3d& axis, double x, double y) {
  const Vector3d C = tip + tool.Ri * axis;
  const double qx = x - C.x(), qy = y - C.y();
  const Line l{qx * axis.x() + qy * axis.y(), qx * qx + qy * qy, axis.z()};
  return solid_lowest(tool, l) + C.z();
}

namespace {

// The options and the path (tips, axes normalised, kinds), refused by name when not usable.
void read_path(const TorusTool& tool, const double* tips, const double* axes_in, const MoveKind* kinds,
               std::size_t n, const Sweep5Options& options, std::vector<Vector3d>& tip, std::vector<Vector3d>& axis) {
  tool.validate_solid();
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
  tip.assign(n, Vector3d::Zero());
  axis.assign(n, Vector3d::Zero());
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
}

// The stock's highest cell; every cell refused by name when out of range (the heights are writable from Python).
double stock_top_of(const ZMap& stock) {
  const std::size_t nx = stock.nx();
  const std::vector<double>& z = stock.heights();
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
  return stock_top;
}

// The simulated moves and their sub-steps: no torus point moves more than max_step between instances.
std::vector<Move> plan_moves(const std::vector<Vector3d>& tip, const std::vector<Vector3d>& axis,
                             const MoveKind* kinds, std::size_t n, double reach, double max_step) {
  std::vector<Move> moves;
  for (std::size_t k = 0; k + 1 < n; ++k) {
    if (kinds[k] == MoveKind::Jump) continue;
    Move m;
    m.k = k;
    m.rapid = kinds[k] == MoveKind::Rapid;
    m.first = k == 0 || kinds[k - 1] == MoveKind::Jump;
    m.theta = std::acos(std::clamp(axis[k].dot(axis[k + 1]), -1.0, 1.0));
    const double steps = std::ceil(((tip[k + 1] - tip[k]).norm() + m.theta * reach) / max_step - 1e-12);
    if (!(steps <= kMaxSteps)) {
      std::ostringstream msg;
      msg << "cut_5axis: move " << k << " needs " << steps << " sub-steps of max_step = " << max_step
          << " mm (more than " << kMaxSteps << "): max_step is too small";
      throw std::invalid_argument(msg.str());
    }
    m.steps = std::max<std::size_t>(1, static_cast<std::size_t>(steps));
    moves.push_back(m);
  }
  return moves;
}

// The path's instances and the tool's per-cell tests: what every band shares (read only).
class Stamper {
 public:
  Stamper(ZMap& stock, const TorusTool& tool, const std::vector<Vector3d>& tip, const std::vector<Vector3d>& axis,
          double stock_top, const BodyCheck* check)
      : check_(check), stock_(stock), tool_(tool), tip_(tip), axis_(axis), stock_top_(stock_top), Ro_(tool.Ro), Ri_(tool.Ri),
        Rt_(tool.radius()), core_(tool.shape == ToolShape::BullNose && Ro_ > 0.0), ball_(Ro_ == 0.0),
        // Squared radii and margins of the pruning tests: a line within the tangent tolerance counts as
        // touching.
        Rt2_hit_((Rt_ + kTangentTol + kPruneMargin) * (Rt_ + kTangentTol + kPruneMargin)),
        Ro2_hit_((Ro_ + kPruneMargin) * (Ro_ + kPruneMargin)), Ro2mRi2_(Ro_ * Ro_ - Ri_ * Ri_),
        g_margin_(2.0 * Ri_ * (kTangentTol + kPruneMargin) + 1e-12) {}

  // The instance at sub-step `step` of move m: tip linear, axis by slerp.
  Pose pose_at(const Move& m, std::size_t step) const {
    const double s = static_cast<double>(step) / static_cast<double>(m.steps);
    const Vector3d t = (1.0 - s) * tip_[m.k] + s * tip_[m.k + 1];
    Pose p = make_pose(tool_, t, slerp(axis_[m.k], axis_[m.k + 1], m.theta, s), stock_top_);
    if (check_) body_detail::BodyBand5::y_range(*check_, p.tip, p.a, p.bylo, p.byhi);
    return p;
  }

  // The rows each move's instances reach (progress: this pass is cheap next to the stamping).
  void move_rows(std::vector<Move>& moves, const BatchOptions& batch) const {
    parallel_chunks(moves.size(), 64, batch, [&](std::size_t b, std::size_t e, ChunkContext& ctx) {
      for (std::size_t i = b; i < e; ++i) {
        Move& m = moves[i];
        for (std::size_t step = m.first ? 0 : 1; step <= m.steps; ++step) {
          if ((step & 1023) == 0) {
            if (ctx.stopping()) return;
            ctx.done_within(static_cast<double>(i - b) + static_cast<double>(step) / static_cast<double>(m.steps));
          }
          const Pose p = pose_at(m, step);
          m.ylo = std::min({m.ylo, p.ylo, p.bylo});
          m.yhi = std::max({m.yhi, p.yhi, p.byhi});
        }
      }
    });
  }

  // Band `band` (rows j0..j1): every instance that reaches it, in path order. Progress and cancel between the
  // instances of a move, not only between moves: one move can be long. False when the batch stopped it.
  bool cut_band(const std::vector<Move>& moves, std::size_t band, double done_before, ChunkContext& ctx,
                std::vector<std::pair<std::size_t, double>>& removed, BandResult& out) {
    const std::size_t nx = stock_.nx(), ny = stock_.ny();
    std::vector<double>& z = stock_.heights();
    const std::size_t j0 = band * kRowsPerBand, j1 = std::min(ny, j0 + kRowsPerBand) - 1;
    const double band_ylo = stock_.cy(j0), band_yhi = stock_.cy(j1);
    const std::vector<double> before(z.begin() + static_cast<std::ptrdiff_t>(j0 * nx),
                                     z.begin() + static_cast<std::ptrdiff_t>((j1 + 1) * nx));
    std::unique_ptr<body_detail::BodyBand5> bodies;
    if (check_) bodies = std::make_unique<body_detail::BodyBand5>(stock_, *check_, j0, j1);
    double band_steps = 0.0, steps_done = 0.0;
    for (const Move& m : moves) band_steps += m.yhi < band_ylo || m.ylo > band_yhi ? 0.0 : m.steps + 1.0;
    for (const Move& m : moves) {
      if (m.yhi < band_ylo || m.ylo > band_yhi) continue;
      removed.clear();  // (cell, height before) lowered by this move when it is a rapid
      if (bodies) bodies->start_move(m.k);
      for (std::size_t step = m.first ? 0 : 1; step <= m.steps; ++step, ++steps_done) {
        if (ctx.stopping()) return false;
        ctx.done_within(done_before + steps_done / band_steps);
        const Pose p = pose_at(m, step);
        // The bodies before the instance is stamped: its endless shank would cut what they are tested on.
        if (bodies && !(p.byhi < band_ylo || p.bylo > band_yhi)) bodies->pose(p.tip, p.a);
        if (p.yhi < band_ylo || p.ylo > band_yhi) continue;
        ++out.stats.instances;
        stamp(p, j0, j1, m.rapid, removed, out.stats);
      }
      if (m.rapid && !removed.empty()) {
        double depth = 0.0;
        for (const auto& [c, zb] : removed) depth = std::max(depth, zb - z[c]);
        out.removals.push_back({m.k, depth});
      }
      if (bodies) bodies->finish_move(out.bodies);
    }
    for (std::size_t c = 0; c < before.size(); ++c) out.lowered += z[j0 * nx + c] < before[c];
    return true;
  }

 private:
  // One instance on rows j0..j1: each cell of its footprint lowered to the tool's lowest point on its line.
  void stamp(const Pose& p, std::size_t j0, std::size_t j1, bool rapid,
             std::vector<std::pair<std::size_t, double>>& removed, Sweep5Stats& stats) {
    const std::size_t nx = stock_.nx();
    double* z = stock_.heights().data();
    const double x0 = stock_.x0(), y0 = stock_.y0(), cell = stock_.cell();
    const double cx = p.C.x(), cy = p.C.y(), cz = p.C.z();
    const double jlo = std::max(static_cast<double>(j0), std::ceil((p.ylo - y0) / cell - 0.5));
    const double jhi = std::min(static_cast<double>(j1), std::floor((p.yhi - y0) / cell - 0.5));
    for (double jd = jlo; jd <= jhi; ++jd) {
      const auto j = static_cast<std::size_t>(jd);
      const double y = stock_.cy(j), qy = y - cy;
      const auto [xlo, xhi] = stadium_row(p, Rt_, y);
      if (!(xlo <= xhi)) continue;
      const double ilo = std::max(0.0, std::ceil((xlo - x0) / cell - 0.5));
      const double ihi = std::min(static_cast<double>(nx) - 1.0, std::floor((xhi - x0) / cell - 0.5));
      if (ilo > ihi) continue;
      double* row = z + j * nx;
      const auto i0 = static_cast<std::size_t>(ilo), i1 = static_cast<std::size_t>(ihi);
      stats.cells_tested += i1 - i0 + 1;
      for (std::size_t i = i0; i <= i1; ++i) {
        const double zc = row[i];
        if (zc <= p.zmin) continue;  // already below everything of this instance
        const double zl = lowest_below(p, stock_.cx(i) - cx, qy, zc - cz, stats) + cz;
        if (zl < zc) {
          ++stats.lowerings;
          if (rapid) removed.emplace_back(j * nx + i, zc);
          row[i] = zl;
        }
      }
    }
  }

  // The lowest point (above the centre C) of the instance's solid on the vertical line at (qx, qy) from C,
  // whose cell top lies dz above C; inf when the line misses every part below the top.
  double lowest_below(const Pose& p, double qx, double qy, double dz, Sweep5Stats& stats) const {
    const double ax = p.a.x(), ay = p.a.y(), az = p.a.z();
    const double sb2 = p.sin_b * p.sin_b;
    const double Ro = Ro_, Ri = Ri_;
    const double qa = qx * ax + qy * ay;
    const double hp = qa + dz * az;  // the cell top's height above the centre plane
    if (hp < -Ri - kPruneMargin) return kInf;  // the solid has h >= -Ri, and h falls down the line
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
    const bool shank = hp >= 0.0 && rho2_min(0.0, hp / az) <= Rt2_hit_;
    const bool flat = core_ && rho2_min(0.0, (hp + Ri) / az) <= Ro2_hit_;
    // The quartic decides most lines at the price of one evaluation; the bounds decide the rest.
    const Line l{qa, qq, az};
    const Quartic quartic = ball_ ? Quartic{} : torus_quartic(l, Ro, Ri);
    const Verdict verdict = Ri <= 0.0 ? Verdict::No : ball_ ? Verdict::Unknown : torus_below(quartic, dz);
    bool torus = verdict == Verdict::Yes;  // a flat end mill (Ri = 0): the rim is the core's edge
    if (verdict == Verdict::Unknown && qq <= Rt2_hit_) {
      const double w = std::sqrt(Rt2_hit_ - qq);
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
          const double G = sv * sv - 2.0 * (dz + Ro * k) * sv + dd + Ro2mRi2_ - 2.0 * Ro * (ru - k * u);
          return G <= g_margin_;
        };
        torus = may_enter(lo, mid, r_lo, r_mid) || may_enter(mid, hi, r_mid, r_hi);
      }
    }
    if (!(torus || shank || flat)) return kInf;
    double t = kInf;
    if (torus) {
      ++stats.exact_solves;
      std::size_t* fallback = &stats.fallback_solves;
      t = ball_ ? torus_lowest(l, Ro, Ri, fallback) : torus_lowest(quartic, l, Ro, Ri, fallback, dz);
    }
    if (shank) t = std::min(t, half_cylinder_lowest(l, Rt_, 0.0));
    if (flat) t = std::min(t, half_cylinder_lowest(l, Ro, -Ri));
    return t;
  }

  const BodyCheck* check_;
  ZMap& stock_;
  const TorusTool& tool_;
  const std::vector<Vector3d>& tip_;
  const std::vector<Vector3d>& axis_;
  const double stock_top_;
  const double Ro_, Ri_, Rt_;
  const bool core_, ball_;
  const double Rt2_hit_, Ro2_hit_, Ro2mRi2_, g_margin_;
};

// Merges the bands: cells lowered and counters summed, the deepest removal per rapid over all bands (max:
// independent of the order) reported when deeper than the tolerance.
void merge_bands(const std::vector<BandResult>& bands, const std::vector<Move>& moves, double collision_tol,
                 SimReport& report, Sweep5Stats& stats) {
  std::vector<RapidCollision> all;
  std::vector<BodyCollision> bodies;
  for (const BandResult& b : bands) {
    bodies.insert(bodies.end(), b.bodies.begin(), b.bodies.end());
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
    if (c.depth > collision_tol) report.collisions.push_back(c);
  }
  for (const Move& m : moves) stats.instances += m.steps + (m.first ? 1 : 0);
  report.body_collisions = merge_body_collisions(std::move(bodies));
}

}  // namespace

SimReport cut_5axis(ZMap& stock, const TorusTool& tool, const double* tips, const double* axes_in,
                    const MoveKind* kinds, std::size_t n, const Sweep5Options& options, const BatchOptions& batch,
                    Sweep5Stats* stats_out) {
  std::vector<Vector3d> tip, axis;
  read_path(tool, tips, axes_in, kinds, n, options, tip, axis);
  if (options.body_check) validate(*options.body_check);
  const double stock_top = stock_top_of(stock);
  const double reach = std::hypot(tool.radius(), 2.0 * tool.Ri);
  std::vector<Move> moves = plan_moves(tip, axis, kinds, n, reach, options.max_step);
  SimReport report;
  report.moves_cut = moves.size();
  Stamper stamper(stock, tool, tip, axis, stock_top, options.body_check);
  stamper.move_rows(moves, BatchOptions{batch.threads, progress_phase(batch.progress, 0.0, 0.02)});

  // Bands of rows, each cutting every instance that reaches it, in path order; the bands in parallel (the
  // heights do not depend on the thread count).
  const std::size_t nbands = (stock.ny() + kRowsPerBand - 1) / kRowsPerBand;
  std::vector<BandResult> bands(nbands);
  const BatchOptions cut{batch.threads, progress_phase(batch.progress, 0.02, 1.0)};
  parallel_chunks(nbands, 1, cut, [&](std::size_t b0, std::size_t b1, ChunkContext& ctx) {
    std::vector<std::pair<std::size_t, double>> removed;
    for (std::size_t band = b0; band < b1; ++band)
      if (!stamper.cut_band(moves, band, static_cast<double>(band - b0), ctx, removed, bands[band])) return;
  });

  Sweep5Stats stats;
  merge_bands(bands, moves, options.collision_tol, report, stats);
  if (stats_out) *stats_out = stats;
  return report;
}

}  // namespace tmm
