#include "tmm/position/multipoint.hpp"

#include <Eigen/Dense>

#include <atomic>
#include <chrono>
#include <limits>
#include <sstream>
#include <stdexcept>
#include <thread>

namespace tmm {

using Eigen::Matrix2d;
using Eigen::Matrix3d;

namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();
constexpr double kPi = 3.14159265358979323846;

// A unit vector perpendicular to a.
Vector3d any_perpendicular(const Vector3d& a) {
  const Vector3d t = std::abs(a.x()) < 0.9 ? Vector3d::UnitX() : Vector3d::UnitY();
  return (t - t.dot(a) * a).normalized();
}

// Distance to the circle of radius R about the axis in the plane h = 0, from local (rho, h) coordinates:
// n = unit vector from the nearest circle point, Hessian of the distance function (a torus level set:
// principal curvatures 1/r across, cos(theta)/rho along the circle).
double circle_distance(double R, double rho, double h, const Vector3d& e, const Vector3d& a,
                       const Vector3d& t, Vector3d* grad, Matrix3d* hess) {
  const Vector3d w = (rho - R) * e + h * a;
  const double r = w.norm();
  if (r < 1e-300) {
    if (grad) *grad = -a;
    if (hess) hess->setZero();
    return 0.0;
  }
  const Vector3d n = w / r;
  if (grad) *grad = n;
  if (hess) {
    const Vector3d b = n.cross(t);
    *hess = (b * b.transpose()) / r;
    if (rho > 1e-12) *hess += (n.dot(e) / rho) * (t * t.transpose());
  }
  return r;
}

}  // namespace

void TorusTool::validate() const {
  if (!std::isfinite(Ro) || !std::isfinite(Ri)) throw std::invalid_argument("tool radii must be finite");
  if (Ro < 0.0) throw std::invalid_argument("major radius Ro must be >= 0 (0 is a ball end mill)");
  if (Ri <= 0.0) {
    throw std::invalid_argument(
        "minor radius Ri must be > 0: a flat end mill (Ri = 0) has no pseudo-insert to tilt about, "
        "multipoint positioning needs a toroidal (or ball) cutter");
  }
}

double TorusTool::profile(double rho) const {
  rho = std::abs(rho);
  if (shape == ToolShape::BullNose && rho <= Ro) return 0.0;
  if (shape == ToolShape::RoundInsert && rho < Ro - Ri) return Ri;  // body over the hollow centre
  const double t = rho - Ro;
  return Ri - std::sqrt(std::fmax(Ri * Ri - t * t, 0.0));
}

double tool_distance(const TorusTool& tool, const Vector3d& tip, const Vector3d& axis, const Vector3d& x,
                     Vector3d* grad, Matrix3d* hess) {
  const double Ro = tool.Ro, Ri = tool.Ri, Rt = Ro + Ri;
  const Vector3d d = x - (tip + Ri * axis);
  const double h = d.dot(axis);  // height above the centre plane
  if (!grad && !hess) {
    // Value only (the gouge scans): no frame vectors.
    const double rho = std::sqrt(std::max(d.squaredNorm() - h * h, 0.0));
    if (tool.shape == ToolShape::BullNose) {
      const double drho = std::max(rho - Ro, 0.0), dh = std::max(-h, 0.0);
      if (drho > 0.0 || dh > 0.0) return std::sqrt(drho * drho + dh * dh) - Ri;
      return -std::min(Ro - rho, h) - Ri;
    }
    const double dt = std::sqrt((rho - Ro) * (rho - Ro) + h * h) - Ri;
    double db;
    if (rho <= Rt) db = (h >= 0.0) ? -std::min(h, Rt - rho) : -h;
    else db = (h >= 0.0) ? rho - Rt : std::sqrt((rho - Rt) * (rho - Rt) + h * h);
    return std::min(dt, db);
  }
  const Vector3d q = d - h * axis;
  const double rho = q.norm();
  const Vector3d e = rho > 1e-12 ? Vector3d(q / rho) : any_perpendicular(axis);
  const Vector3d t = axis.cross(e);
  auto plane = [&](double value) {  // -h - value: below the plane h = -value... gradient -axis
    if (grad) *grad = -axis;
    if (hess) hess->setZero();
    return value;
  };
  auto cylinder = [&](double value) {  // rho - const
    if (grad) *grad = e;
    if (hess) *hess = rho > 1e-12 ? Matrix3d((t * t.transpose()) / rho) : Matrix3d::Zero();
    return value;
  };
  if (tool.shape == ToolShape::BullNose) {
    const double drho = std::max(rho - Ro, 0.0), dh = std::max(-h, 0.0);
    if (drho > 0.0 && dh > 0.0) return circle_distance(Ro, rho, h, e, axis, t, grad, hess) - Ri;
    if (dh > 0.0) return plane(-h - Ri);
    if (drho > 0.0) return cylinder(rho - Ro - Ri);
    return (Ro - rho < h) ? cylinder(rho - Ro - Ri) : plane(-h - Ri);
  }
  // Round insert: min(full torus, body {h >= 0, rho <= Rt}).
  Vector3d g1;
  Matrix3d H1;
  const double dt = circle_distance(Ro, rho, h, e, axis, t, &g1, hess ? &H1 : nullptr) - Ri;
  double db;
  int piece;  // 0 plane below, 1 wall, 2 corner circle
  if (rho <= Rt) {
    if (h >= 0.0) {
      if (h < Rt - rho) {
        db = -h;
        piece = 0;
      } else {
        db = rho - Rt;
        piece = 1;
      }
    } else {
      db = -h;
      piece = 0;
    }
  } else if (h >= 0.0) {
    db = rho - Rt;
    piece = 1;
  } else {
    db = std::hypot(rho - Rt, h);
    piece = 2;
  }
  if (dt <= db) {
    if (grad) *grad = g1;
    if (hess) *hess = H1;
    return dt;
  }
  if (piece == 0) return plane(db);
  if (piece == 1) return cylinder(db);
  return circle_distance(Rt, rho, h, e, axis, t, grad, hess);
}

const std::vector<std::string>& multipoint_reason_text() {
  static const std::vector<std::string> text = {
      "two contacts",
      "no surface under the tool",
      "ball end mill (Ro = 0): tilting about the centre does not move the tool",
      "first contact on the flat bottom: tilting about the pseudo-insert would gouge, axis kept vertical",
      "first contact under the hollow centre of the round-insert tool: no pseudo-insert, axis kept vertical",
      "no second contact up to the tilt limit: tilted to the limit, one contact",
      "second contact coincides with the first: the surface curvature at P limits the tilt (convex or flat "
      "region), one contact",
      "refinement of the second contact did not converge",
      "gouge: the final check found the surface inside the tool beyond tolerance",
      "seed's rotation about global X: approximate tilt, contacts not kept",
  };
  return text;
}

// ---------------------------------------------------------------------------------------------------------
// Surface samples

SurfaceSamples::SurfaceSamples(const PatchSurface& surface, double spacing, double cell) {
  if (!(spacing > 0.0) || !(cell > 0.0)) throw std::invalid_argument("sample spacing must be > 0");
  // Sample counts from the control polygon lengths (they bound the curve lengths).
  constexpr std::size_t kMaxSamples = 4000000;
  std::vector<std::pair<int, int>> counts;
  for (;;) {
    counts.clear();
    std::size_t total = 0;
    for (int i = 0; i < surface.nu(); ++i) {
      for (int j = 0; j < surface.nv(); ++j) {
        const BezierPatch& p = surface.patch(i, j);
        double lu = 0.0, lv = 0.0;
        for (int b = 0; b <= p.degree_v(); ++b) {
          double l = 0.0;
          for (int a = 0; a < p.degree_u(); ++a) l += (p.pole(a + 1, b) - p.pole(a, b)).norm();
          lu = std::max(lu, l);
        }
        for (int a = 0; a <= p.degree_u(); ++a) {
          double l = 0.0;
          for (int b = 0; b < p.degree_v(); ++b) l += (p.pole(a, b + 1) - p.pole(a, b)).norm();
          lv = std::max(lv, l);
        }
        const int mu = std::clamp(static_cast<int>(std::ceil(lu / spacing)), 2, 4000);
        const int mv = std::clamp(static_cast<int>(std::ceil(lv / spacing)), 2, 4000);
        counts.emplace_back(mu, mv);
        total += static_cast<std::size_t>(mu + 1) * static_cast<std::size_t>(mv + 1);
      }
    }
    if (total <= kMaxSamples) break;
    spacing *= 1.5;
  }
  spacing_ = spacing;
  Box3 box;
  int k = 0;
  for (int i = 0; i < surface.nu(); ++i) {
    for (int j = 0; j < surface.nv(); ++j, ++k) {
      const auto [mu, mv] = counts[static_cast<std::size_t>(k)];
      const double U0 = surface.breaks_u()[i], U1 = surface.breaks_u()[i + 1];
      const double V0 = surface.breaks_v()[j], V1 = surface.breaks_v()[j + 1];
      step_.emplace_back((U1 - U0) / mu, (V1 - V0) / mv);
      const BezierPatch& p = surface.patch(i, j);
      for (int a = 0; a <= mu; ++a) {
        for (int b = 0; b <= mv; ++b) {
          const double u = static_cast<double>(a) / mu, v = static_cast<double>(b) / mv;
          pts_.push_back(p.point(u, v));
          uv_.emplace_back(U0 + u * (U1 - U0), V0 + v * (V1 - V0));
          patch_.push_back(k);
          box.extend(pts_.back());
        }
      }
    }
  }
  cell_ = cell;
  x0_ = box.lo.x();
  y0_ = box.lo.y();
  nx_ = std::max(1, static_cast<int>(std::ceil((box.hi.x() - x0_) / cell_)) + 1);
  ny_ = std::max(1, static_cast<int>(std::ceil((box.hi.y() - y0_) / cell_)) + 1);
  if (static_cast<double>(nx_) * ny_ > 4e6) {  // huge face, tiny tool: coarser buckets
    cell_ = std::max(box.hi.x() - x0_, box.hi.y() - y0_) / 1000.0;
    nx_ = static_cast<int>(std::ceil((box.hi.x() - x0_) / cell_)) + 1;
    ny_ = static_cast<int>(std::ceil((box.hi.y() - y0_) / cell_)) + 1;
  }
  std::vector<int> bucket(pts_.size());
  start_.assign(static_cast<std::size_t>(nx_ * ny_ + 1), 0);
  for (std::size_t s = 0; s < pts_.size(); ++s) {
    const int i = std::clamp(static_cast<int>((pts_[s].x() - x0_) / cell_), 0, nx_ - 1);
    const int j = std::clamp(static_cast<int>((pts_[s].y() - y0_) / cell_), 0, ny_ - 1);
    bucket[s] = j * nx_ + i;
    ++start_[static_cast<std::size_t>(bucket[s] + 1)];
  }
  for (std::size_t b = 1; b < start_.size(); ++b) start_[b] += start_[b - 1];
  order_.resize(pts_.size());
  std::vector<int> fill(start_.begin(), start_.end() - 1);
  for (std::size_t s = 0; s < pts_.size(); ++s) order_[static_cast<std::size_t>(fill[bucket[s]]++)] = static_cast<int>(s);
}

// ---------------------------------------------------------------------------------------------------------
// Local minimisation over the parameter box (Newton with a Levenberg shift, projected, backtracking).

namespace {

struct Local {
  double f = kInf;
  Vector2d g = Vector2d::Zero();
  Matrix2d H = Matrix2d::Zero();
};

template <class Fn>
Local minimize_box(Fn&& fn, Vector2d& x, const Vector2d& lo, const Vector2d& hi, int maxit, int* evals) {
  x = x.cwiseMax(lo).cwiseMin(hi);
  Local L = fn(x);
  if (evals) ++*evals;
  const Vector2d span = hi - lo;
  for (int it = 0; it < maxit; ++it) {
    bool fixed[2];
    for (int k = 0; k < 2; ++k)
      fixed[k] = (x[k] <= lo[k] && L.g[k] > 0.0) || (x[k] >= hi[k] && L.g[k] < 0.0);
    if (fixed[0] && fixed[1]) break;
    Matrix2d H = L.H;
    Vector2d g = L.g;
    for (int k = 0; k < 2; ++k) {
      if (fixed[k]) {
        g[k] = 0.0;
        H.row(k).setZero();
        H.col(k).setZero();
        H(k, k) = 1.0;
      }
    }
    // Shift to positive definite: lambda above -min eigenvalue.
    const double a = H(0, 0), b = H(0, 1), c = H(1, 1);
    const double mean = 0.5 * (a + c), dev = std::sqrt(0.25 * (a - c) * (a - c) + b * b);
    const double emin = mean - dev, emax = mean + dev;
    double lambda = 0.0;
    if (emin <= 1e-12 * std::max(1.0, std::abs(emax))) lambda = -emin + 1e-6 * std::max(1.0, std::abs(emax));
    const Matrix2d A = H + lambda * Matrix2d::Identity();
    Vector2d d = -A.ldlt().solve(g);
    for (int k = 0; k < 2; ++k)
      if (fixed[k]) d[k] = 0.0;
    if (!d.allFinite()) break;
    // Limit a step to a quarter of the domain: Newton from far away can jump across the face.
    const double lim = 0.25 * span.maxCoeff();
    if (d.cwiseAbs().maxCoeff() > lim) d *= lim / d.cwiseAbs().maxCoeff();
    double step = 1.0;
    bool moved = false;
    for (int ls = 0; ls < 40; ++ls) {
      Vector2d xn = (x + step * d).cwiseMax(lo).cwiseMin(hi);
      const Local Ln = fn(xn);
      if (evals) ++*evals;
      const double pred = L.g.dot(xn - x);
      if (Ln.f <= L.f + 1e-4 * std::min(pred, 0.0) && std::isfinite(Ln.f)) {
        const double dx = (xn - x).cwiseAbs().maxCoeff();
        const double df = L.f - Ln.f;
        x = xn;
        L = Ln;
        moved = dx > 1e-15 * (1.0 + x.cwiseAbs().maxCoeff()) && (df > 0.0 || dx > 1e-13);
        break;
      }
      step *= 0.5;
    }
    if (!moved) break;
  }
  return L;
}

}  // namespace

// ---------------------------------------------------------------------------------------------------------
// Positioner

namespace {

std::shared_ptr<const PatchSurface> extended_or_same(const std::shared_ptr<const PatchSurface>& s, double d) {
  if (!s) throw std::invalid_argument("no surface");
  if (!(d >= 0.0) || !std::isfinite(d)) throw std::invalid_argument("extension distance must be >= 0");
  if (d == 0.0) return s;
  return std::make_shared<const PatchSurface>(s->extended(d));
}

}  // namespace

MultipointPositioner::MultipointPositioner(std::shared_ptr<const PatchSurface> surface, TorusTool tool,
                                           MultipointOptions options)
    : real_(surface),
      surface_(extended_or_same(surface, options.extend)),
      tool_((tool.validate(), tool)),
      opt_(options),
      samples_(*surface_,
               options.sample_spacing > 0.0 ? options.sample_spacing : (tool.Ro + tool.Ri) / 8.0,
               std::max((tool.Ro + tool.Ri) * 0.5, 1e-3)) {
  if (!(opt_.beta_max > 0.0 && opt_.beta_max < kPi / 2)) throw std::invalid_argument("beta_max must be in (0, pi/2)");
  if (!(opt_.tol > 0.0)) throw std::invalid_argument("tolerance must be > 0");
  if (opt_.divisions < 1 || opt_.refinements < 0 || opt_.drd_divisions < 2 || opt_.drd_refinements < 1 ||
      opt_.drd_bisections < 1 || opt_.anchor_iterations < 1)
    throw std::invalid_argument("grid divisions / refinements / bisections / anchor iterations out of range");
  if (opt_.extend > 0.0) {
    real_samples_ = std::make_unique<SurfaceSamples>(*real_, samples_.spacing(), std::max((tool.Ro + tool.Ri) * 0.5, 1e-3));
  }
}

namespace {

// -(tip height of the vertical tool at (x, y) touching S(U, V)), as a function of (U, V) for Newton:
// f = -(S_z - h(rho)), rho = |S_xy - (x, y)|.
Local drop_objective(const PatchSurface& s, const TorusTool& tool, double x, double y, const Vector2d& uv) {
  const SurfacePoint sp = s.eval(uv.x(), uv.y(), 2);
  const double dx = sp.S.x() - x, dy = sp.S.y() - y;
  const double rho = std::hypot(dx, dy);
  Local L;
  const double Ro = tool.Ro, Ri = tool.Ri;
  if (rho > Ro + Ri) {
    L.f = kInf;
    return L;
  }
  double H = 0.0, H1 = 0.0, H2 = 0.0;
  const bool flat = (tool.shape == ToolShape::BullNose && rho <= Ro);
  const bool body = (tool.shape == ToolShape::RoundInsert && rho < Ro - Ri);
  if (body) {
    H = Ri;
  } else if (!flat) {
    const double t = rho - Ro;
    const double q = std::max(Ri * Ri - t * t, 1e-300);
    const double sq = std::sqrt(q);
    H = Ri - sq;
    H1 = t / sq;
    H2 = Ri * Ri / (q * sq);
  }
  L.f = -(sp.S.z() - H);
  Vector2d ru = Vector2d::Zero();
  Matrix2d rr = Matrix2d::Zero();
  if (rho > 1e-12 && (H1 != 0.0 || H2 != 0.0)) {
    const Eigen::Vector2d e(dx / rho, dy / rho);
    const Eigen::Vector2d su = sp.Su.head<2>(), sv = sp.Sv.head<2>();
    ru << e.dot(su), e.dot(sv);
    rr(0, 0) = (su.squaredNorm() - ru[0] * ru[0]) / rho + e.dot(sp.Suu.head<2>());
    rr(0, 1) = rr(1, 0) = (su.dot(sv) - ru[0] * ru[1]) / rho + e.dot(sp.Suv.head<2>());
    rr(1, 1) = (sv.squaredNorm() - ru[1] * ru[1]) / rho + e.dot(sp.Svv.head<2>());
  }
  L.g << -(sp.Su.z() - H1 * ru[0]), -(sp.Sv.z() - H1 * ru[1]);
  L.H(0, 0) = -(sp.Suu.z() - H2 * ru[0] * ru[0] - H1 * rr(0, 0));
  L.H(0, 1) = L.H(1, 0) = -(sp.Suv.z() - H2 * ru[0] * ru[1] - H1 * rr(0, 1));
  L.H(1, 1) = -(sp.Svv.z() - H2 * ru[1] * ru[1] - H1 * rr(1, 1));
  return L;
}

// Tool distance of S(U, V) for the tool at (tip, axis), with derivatives in (U, V).
Local distance_objective(const PatchSurface& s, const TorusTool& tool, const Vector3d& tip,
                         const Vector3d& axis, const Vector2d& uv) {
  const SurfacePoint sp = s.eval(uv.x(), uv.y(), 2);
  Vector3d g;
  Matrix3d H;
  Local L;
  L.f = tool_distance(tool, tip, axis, sp.S, &g, &H);
  L.g << g.dot(sp.Su), g.dot(sp.Sv);
  L.H(0, 0) = sp.Su.dot(H * sp.Su) + g.dot(sp.Suu);
  L.H(0, 1) = L.H(1, 0) = sp.Su.dot(H * sp.Sv) + g.dot(sp.Suv);
  L.H(1, 1) = sp.Sv.dot(H * sp.Sv) + g.dot(sp.Svv);
  return L;
}

// Seed-style zoom: (d+1)^2 grid over a window around `best`, keep the best, shrink, repeat; score(uv)
// returns a value to minimise (+inf: no ray hit).
template <class Score>
void zoom_grid(const PatchSurface& s, Vector2d& best, double& best_score, Vector2d half, int divisions,
               int refinements, Score&& score, int* evals) {
  for (int r = 0; r < refinements; ++r) {
    const Vector2d c = best;
    for (int a = 0; a <= divisions; ++a) {
      for (int b = 0; b <= divisions; ++b) {
        Vector2d uv(c.x() - half.x() + 2.0 * half.x() * a / divisions,
                    c.y() - half.y() + 2.0 * half.y() * b / divisions);
        uv = uv.cwiseMax(s.lo()).cwiseMin(s.hi());
        const double v = score(uv);
        if (evals) ++*evals;
        if (v < best_score) {
          best_score = v;
          best = uv;
        }
      }
    }
    half *= 2.0 / divisions;
  }
}

// Rotation of the tool by -beta about u1 through O1 (the exact tilt).
void tilt_pose(const Vector3d& O1, const Vector3d& u1, double beta, const Vector3d& tip0, Vector3d* tip,
               Vector3d* axis) {
  const Matrix3d R = Eigen::AngleAxisd(-beta, u1).toRotationMatrix();
  *tip = O1 + R * (tip0 - O1);
  *axis = R * Vector3d::UnitZ();
}

}  // namespace

MultipointPositioner::Drop MultipointPositioner::drop_vcrf(double x, double y, int* evals) const {
  // Vertical rays fired up from the samples to the lower tool surface: tip = S_z - h(rho), highest wins.
  // The best few samples, kept apart, are refined (the zoom grid, then Newton): near the tool's rim h is
  // steep, so the highest sample need not lie next to the highest point.
  const PatchSurface& s = *surface_;
  const double Rt = tool_.radius();
  constexpr int K = 3;
  std::pair<double, std::size_t> top[K];
  int ntop = 0;
  const double sep2 = std::pow(2.0 * samples_.spacing(), 2);
  const auto& pts = samples_.points();
  samples_.within(x, y, Rt, [&](std::size_t k) {
    const double rho = std::hypot(pts[k].x() - x, pts[k].y() - y);
    const double f = -(pts[k].z() - tool_.profile(rho));
    for (int i = 0; i < ntop; ++i) {
      if ((pts[top[i].second] - pts[k]).squaredNorm() < sep2) {
        if (f < top[i].first) top[i] = {f, k};
        return;
      }
    }
    if (ntop < K) {
      top[ntop++] = {f, k};
      return;
    }
    int worst = 0;
    for (int i = 1; i < K; ++i)
      if (top[i].first > top[worst].first) worst = i;
    if (f < top[worst].first) top[worst] = {f, k};
  });
  Drop d;
  auto score = [&](const Vector2d& p) {
    const Vector3d S = s.point(p.x(), p.y());
    const double rho = std::hypot(S.x() - x, S.y() - y);
    return rho > Rt ? kInf : -(S.z() - tool_.profile(rho));
  };
  auto objective = [&](const Vector2d& p) { return drop_objective(s, tool_, x, y, p); };
  double best = kInf;
  if (ntop == 0) {
    // No sample under the tool: the face may still reach under it between samples (narrow faces).
    Vector2d uv = 0.5 * (s.lo() + s.hi());
    const Local L = minimize_box(objective, uv, s.lo(), s.hi(), 50, evals);
    if (!std::isfinite(L.f)) return d;
    d.ok = true;
    d.tip_z = -L.f;
    d.uv = uv;
    return d;
  }
  // Insertion sort of the K candidates (std::sort's unrolled small-array path warns on a fixed K array).
  for (int i = 1; i < ntop; ++i)
    for (int j = i; j > 0 && top[j] < top[j - 1]; --j) std::swap(top[j], top[j - 1]);
  // Candidates far below the best cannot win: a sample misses its local maximum by at most the rise of
  // the tool's profile over one sample spacing, taken here as Ri / 2 (the final check is the safety net).
  while (ntop > 1 && top[ntop - 1].first > top[0].first + 0.5 * tool_.Ri) --ntop;
  for (int i = 0; i < ntop; ++i) {
    Vector2d uv = samples_.params()[top[i].second];
    double f = top[i].first;
    if (i == 0) zoom_grid(s, uv, f, samples_.step(top[i].second), opt_.divisions, opt_.refinements, score, evals);
    const Local L = minimize_box(objective, uv, s.lo(), s.hi(), 50, evals);
    const double fi = std::min(L.f, f);
    if (fi < best) {
      best = fi;
      d.uv = L.f <= f ? uv : samples_.params()[top[i].second];
    }
  }
  d.ok = std::isfinite(best);
  d.tip_z = -best;
  return d;
}

MultipointPositioner::Drop MultipointPositioner::drop_drd(const PatchSurface& s, double x, double y,
                                                          int* evals) const {
  // Rays fired down from the tool's lower surface (seed figure 3.6), on a (rho, phi) grid that zooms in on
  // the shortest ray; the tool starts above the face's bounding box.
  const double Rt = tool_.radius();
  const double z_ref = s.bounds().hi.z() + 1.0;
  const double rho_lo = tool_.shape == ToolShape::RoundInsert ? std::max(0.0, tool_.Ro - tool_.Ri) : 0.0;
  double r0 = rho_lo, r1 = Rt, p0 = 0.0, p1 = 2.0 * kPi;
  const int n = opt_.drd_divisions;
  double best = kInf;  // shortest ray
  double best_r = 0.0, best_p = 0.0;
  Vector2d best_uv = 0.5 * (s.lo() + s.hi());
  Vector2d guess = best_uv;
  bool have_guess = false;
  const Vector3d down(0.0, 0.0, -1.0);
  struct Coarse {
    double s;
    Vector2d uv;
    Vector3d point;
  };
  std::vector<Coarse> coarse;
  const double sep2 = std::pow(2.0 * samples_.spacing(), 2);
  for (int level = 0; level < opt_.drd_refinements; ++level) {
    for (int a = 0; a <= n; ++a) {
      const double rho = std::clamp(r0 + (r1 - r0) * a / n, rho_lo, Rt);
      const double hz = tool_.profile(rho);
      for (int b = 0; b <= n; ++b) {
        const double phi = p0 + (p1 - p0) * b / n;
        const Vector3d o(x + rho * std::cos(phi), y + rho * std::sin(phi), z_ref + hz);
        std::optional<RayHit> hit;
        if (have_guess) hit = s.ray_hit_newton(o, down, guess);
        if (!hit) hit = s.ray_hit(o, down);
        if (evals) *evals += 4;
        if (!hit) continue;
        guess = hit->uv;
        have_guess = true;
        if (level == 0) {  // the best few coarse rays, apart, are polished too (a far local maximum)
          const Vector3d hp = o + hit->s * down;
          bool merged = false;
          for (auto& c : coarse) {
            if ((c.point - hp).squaredNorm() < sep2) {
              if (hit->s < c.s) c = {hit->s, hit->uv, hp};
              merged = true;
              break;
            }
          }
          if (!merged) {
            if (coarse.size() < 3) {
              coarse.push_back({hit->s, hit->uv, hp});
            } else {
              auto worst = std::max_element(coarse.begin(), coarse.end(),
                                            [](const Coarse& a, const Coarse& b) { return a.s < b.s; });
              if (hit->s < worst->s) *worst = {hit->s, hit->uv, hp};
            }
          }
        }
        if (hit->s < best) {
          best = hit->s;
          best_r = rho;
          best_p = phi;
          best_uv = hit->uv;
        }
      }
    }
    const double dr = (r1 - r0) / n, dp = (p1 - p0) / n;
    r0 = std::max(rho_lo, best_r - dr);
    r1 = std::min(Rt, best_r + dr);
    p0 = best_p - dp;
    p1 = best_p + dp;
  }
  Drop d;
  if (!std::isfinite(best)) return d;
  // Newton polish of the contact (the seed stops at the grid's resolution), from the zoomed ray and from
  // the other coarse candidates.
  d.ok = true;
  d.tip_z = z_ref - best;
  d.uv = best_uv;
  auto polish = [&](Vector2d uv) {  // every candidate is a true contact height: the highest wins
    const Local L = minimize_box([&](const Vector2d& p) { return drop_objective(s, tool_, x, y, p); }, uv, s.lo(),
                                 s.hi(), 50, evals);
    if (std::isfinite(L.f) && -L.f > d.tip_z) {
      d.tip_z = -L.f;
      d.uv = uv;
    }
  };
  polish(best_uv);
  for (const auto& c : coarse) polish(c.uv);
  return d;
}

double MultipointPositioner::penetration(const Vector3d& tip, const Vector3d& axis, Vector2d* where,
                                         int* evals) const {
  return penetration_on(*surface_, samples_, tip, axis, where, evals);
}

double MultipointPositioner::penetration_real(const Vector3d& tip, const Vector3d& axis, Vector2d* where,
                                              int* evals) const {
  if (!real_samples_) return penetration_on(*surface_, samples_, tip, axis, where, evals);
  return penetration_on(*real_, *real_samples_, tip, axis, where, evals);
}

double MultipointPositioner::penetration_on(const PatchSurface& s, const SurfaceSamples& samples,
                                            const Vector3d& tip, const Vector3d& axis, Vector2d* where,
                                            int* evals) const {
  const Vector3d C = tip + tool_.Ri * axis;
  // The tilted tool's torus lies within Ro + Ri of C; the margin covers the shank's foot.
  const double r = tool_.radius() + 0.5 * tool_.Ri;
  const auto& pts = samples.points();
  // The lowest few samples, kept apart from each other, are polished by Newton.
  constexpr int K = 6;
  std::pair<double, std::size_t> low[K];
  int nlow = 0;
  const double sep2 = std::pow(2.0 * samples.spacing(), 2);
  samples.within(C.x(), C.y(), r, [&](std::size_t k) {
    const double d = tool_distance(tool_, tip, axis, pts[k]);
    if (evals) ++*evals;
    if (d > tool_.Ri) return;
    // Replace a close candidate if lower, else insert among the K lowest.
    for (int i = 0; i < nlow; ++i) {
      if ((pts[low[i].second] - pts[k]).squaredNorm() < sep2) {
        if (d < low[i].first) low[i] = {d, k};
        return;
      }
    }
    if (nlow < K) {
      low[nlow++] = {d, k};
      return;
    }
    int worst = 0;
    for (int i = 1; i < K; ++i)
      if (low[i].first > low[worst].first) worst = i;
    if (d < low[worst].first) low[worst] = {d, k};
  });
  double best = kInf;
  Vector2d at = Vector2d::Zero();
  for (int i = 0; i < nlow; ++i) {
    Vector2d uv = samples.params()[low[i].second];
    const Local L = minimize_box([&](const Vector2d& p) { return distance_objective(s, tool_, tip, axis, p); }, uv,
                                 s.lo(), s.hi(), 30, evals);
    const double d = std::min(L.f, low[i].first);
    if (d < best) {
      best = d;
      at = L.f <= low[i].first ? uv : samples.params()[low[i].second];
    }
  }
  if (where) *where = at;
  return std::isfinite(best) ? std::max(0.0, -best) : 0.0;
}

namespace {

// VCRF circular ray (seed 4.3): the smallest beta in (0, 2 pi) at which the surface point, turned by beta
// about the pseudo-insert axis (u1 through O1, counter-clockwise in (v1, w1)), enters the tool. Local
// coordinates (su, sv, sw) in the frame {u1, v1, w1} at O1; the tool axis is the line u = 0, v = Ro.
// The circle of radius R in the plane u = su meets the torus (seed eq. 29) where
//   sqrt(su^2 + (v - Ro)^2) = K - v,  K = (su^2 + 2 Ro^2 - Ri^2 + R^2) / (2 Ro),
// which is linear in v after squaring: one v, two points w = +-sqrt(R^2 - v^2) (only the lower one is on
// the tool's boundary). The other boundary pieces (flat bottom or hollow ceiling, shank) are planes and a
// cylinder: closed forms as well. The first crossing along the circle is where the point enters.
// Returns a pseudo-angle, monotonic in the angle (1 - cos on (0, pi], 3 + cos on (pi, 2 pi)): comparisons
// need no atan2; pseudo_to_angle() converts the winner.
double circular_ray(const TorusTool& tool, double su, double sv, double sw) {
  const double Ro = tool.Ro, Ri = tool.Ri, Rt = Ro + Ri;
  const double R2 = sv * sv + sw * sw;
  double best = kInf;
  if (R2 <= 0.0) return kInf;
  auto cross = [&](double v, double w) {  // pseudo-angle from (sv, sw) to (v, w), counter-clockwise
    const double c = (sv * v + sw * w) / R2, sn = sv * w - sw * v;
    double a = sn > 0.0 ? 1.0 - c : 3.0 + c;
    if (a <= 0.0) a = 4.0;  // the start point itself: a full turn
    best = std::min(best, a);
  };
  // Torus, lower half.
  if (Ro > 0.0) {
    const double K = (su * su + 2.0 * Ro * Ro - Ri * Ri + R2) / (2.0 * Ro);
    if (std::abs(K - Ro) > 1e-14 * (1.0 + K)) {
      const double v = (K * K - Ro * Ro - su * su) / (2.0 * (K - Ro));
      const double rho = K - v;
      const double w2 = R2 - v * v;
      if (rho >= 0.0 && w2 >= 0.0) {
        const bool on_tool = tool.shape == ToolShape::RoundInsert || rho >= Ro;
        if (on_tool) cross(v, -std::sqrt(w2));
      }
    }
  }
  // Flat bottom w = -Ri, rho <= Ro (bull-nose) or hollow ceiling w = 0, rho <= Ro - Ri (round insert).
  {
    const double w = tool.shape == ToolShape::BullNose ? -Ri : 0.0;
    const double rmax = tool.shape == ToolShape::BullNose ? Ro : Ro - Ri;
    if (rmax > 0.0 && R2 >= w * w) {
      const double v = std::sqrt(R2 - w * w);
      for (double vv : {v, -v})
        if (su * su + (vv - Ro) * (vv - Ro) <= rmax * rmax) cross(vv, w);
    }
  }
  // Shank rho = Rt, w >= 0.
  if (std::abs(su) <= Rt) {
    const double c = std::sqrt(Rt * Rt - su * su);
    for (double v : {Ro + c, Ro - c}) {
      if (R2 >= v * v) cross(v, std::sqrt(R2 - v * v));
    }
  }
  return best;
}

double pseudo_to_angle(double p) {
  if (!std::isfinite(p)) return kInf;
  return p <= 2.0 ? std::acos(std::clamp(1.0 - p, -1.0, 1.0)) : 2.0 * kPi - std::acos(std::clamp(p - 3.0, -1.0, 1.0));
}

}  // namespace

MultipointResult MultipointPositioner::position_core(double x, double y) const {
  MultipointResult res;
  const PatchSurface& s = *surface_;
  int evals = 0;
  const Vector3d Z = Vector3d::UnitZ();
  const double Ro = tool_.Ro, Ri = tool_.Ri;
  const bool drd = opt_.method == MultipointMethod::DRD;

  const Drop drop = drd ? drop_drd(s, x, y, &evals) : drop_vcrf(x, y, &evals);
  if (!drop.ok) {
    res.status = ContactStatus::Failed;
    res.reason = ContactReason::NoSurface;
    res.tip = Vector3d(x, y, s.bounds().hi.z());
    res.centre = res.tip + Ri * Z;
    res.evaluations = evals;
    return res;
  }
  const Vector3d tip0(x, y, drop.tip_z);
  const Vector3d C0 = tip0 + Ri * Z;
  res.drop_z = drop.tip_z;
  res.uvP = drop.uv;
  {
    const SurfacePoint sp = s.eval(drop.uv.x(), drop.uv.y(), 1);
    res.P = sp.S;
    res.nP = sp.normal();
    if (res.nP.z() < 0.0) res.nP = -res.nP;
  }
  // known_penetration >= 0: the caller has already checked this pose.
  auto finish_single = [&](ContactReason reason, const Vector3d& tip, const Vector3d& axis, double beta,
                           double known_penetration = -1.0) {
    res.status = ContactStatus::OneContact;
    res.reason = reason;
    res.tip = tip;
    res.axis = axis;
    res.beta = beta;
    res.centre = tip + Ri * axis;
    res.Q = res.P;
    res.nQ = res.nP;
    res.uvQ = res.uvP;
    res.gap_P = res.gap_Q = tool_distance(tool_, tip, axis, res.P);
    res.penetration = known_penetration >= 0.0 ? known_penetration : penetration(tip, axis, nullptr, &evals);
    if (res.penetration > opt_.tol) {
      res.status = ContactStatus::Failed;
      res.reason = ContactReason::Gouge;
    }
    res.evaluations = evals;
    return res;
  };

  const Vector3d dP = res.P - C0;
  const Vector3d q = dP - dP.dot(Z) * Z;
  const double rhoP = q.norm();
  if (Ro == 0.0) return finish_single(ContactReason::Ball, tip0, Z, 0.0);
  const double eps = 1e-9 * (1.0 + Ro + Ri);
  if (tool_.shape == ToolShape::BullNose && rhoP <= Ro + eps) return finish_single(ContactReason::FlatBottom, tip0, Z, 0.0);
  if (tool_.shape == ToolShape::RoundInsert && rhoP < Ro - Ri + eps) return finish_single(ContactReason::Hollow, tip0, Z, 0.0);

  // Pseudo-insert frame (seed eqs. 24-27): e from the axis to P, u1 = w1 x e, v1 = -e, O1 on the major circle.
  const Vector3d e = q / rhoP;
  const Vector3d u1 = Z.cross(e);
  const Vector3d v1 = -e;
  const Vector3d O1 = C0 + Ro * e;

  // --- First guess of the tilt beta0 and of Q.
  double beta0 = kInf;
  Vector2d uvQ = res.uvP;
  std::vector<std::pair<double, std::size_t>> hits;  // VCRF: (pseudo-angle of the circular ray, sample)
  if (!drd) {
    // Circular rays from the samples around the tool.
    const auto& pts = samples_.points();
    std::size_t kbest = 0;
    const double limit = 1.0 - std::cos(std::min(2.0 * opt_.beta_max, kPi));  // pseudo-angle
    samples_.within(x, y, tool_.radius() + 0.5 * Ri, [&](std::size_t k) {
      const Vector3d d = pts[k] - O1;
      const double b = circular_ray(tool_, d.dot(u1), d.dot(v1), d.dot(Z));
      ++evals;
      if (b > limit || tool_distance(tool_, tip0, Z, pts[k]) <= 1e-7) return;
      hits.emplace_back(b, k);
      if (b < beta0) {
        beta0 = b;
        kbest = k;
      }
    });
    std::sort(hits.begin(), hits.end());
    if (std::isfinite(beta0)) {
      uvQ = samples_.params()[kbest];
      auto score = [&](const Vector2d& p) {
        const Vector3d S = s.point(p.x(), p.y());
        if (tool_distance(tool_, tip0, Z, S) <= 1e-7) return kInf;
        const Vector3d d = S - O1;
        return circular_ray(tool_, d.dot(u1), d.dot(v1), d.dot(Z));
      };
      zoom_grid(s, uvQ, beta0, samples_.step(kbest), opt_.divisions, opt_.refinements, score, &evals);
      beta0 = pseudo_to_angle(beta0);
    }
  } else {
    // Drop, rotate the surface about the pseudo-insert axis, drop again; bisect on beta (seed figure 3.5).
    auto gouges = [&](double beta, Vector2d* contact) {
      const Matrix3d R = Eigen::AngleAxisd(beta, u1).toRotationMatrix();
      const PatchSurface rotated = s.transformed(R, O1 - R * O1);
      const Drop d2 = drop_drd(rotated, x, y, &evals);
      if (d2.ok && contact) *contact = d2.uv;
      return d2.ok && d2.tip_z > drop.tip_z + 1e-7;
    };
    Vector2d c;
    if (gouges(opt_.beta_max, &c)) {
      double lo = 0.0, hi = opt_.beta_max;
      uvQ = c;
      for (int k = 0; k < opt_.drd_bisections; ++k) {
        const double mid = 0.5 * (lo + hi);
        if (gouges(mid, &c)) {
          hi = mid;
          uvQ = c;
        } else {
          lo = mid;
        }
      }
      beta0 = hi;
    }
  }
  if (!(beta0 <= opt_.beta_max)) {
    Vector3d tip, axis;
    tilt_pose(O1, u1, opt_.beta_max, tip0, &tip, &axis);
    return finish_single(ContactReason::TiltLimit, tip, axis, opt_.beta_max);
  }

  // --- Refinement: beta such that the tool distance, minimised over Q's neighbourhood, is 0 (Newton on
  // beta, safeguarded by a bracket; inner Newton on (U, V)). Returns false if it does not converge.
  Vector3d tip, axis;
  const double near = std::max(0.1 * Ri, 2.0 * samples_.spacing());
  const double allowed = std::min(1e-6, 0.25 * opt_.tol);  // osculation, not a tolerated gouge
  auto refine = [&](double& beta, Vector2d& uv, double hi) {
    double lo = 0.0;
    for (int it = 0; it < 60; ++it) {
      tilt_pose(O1, u1, beta, tip0, &tip, &axis);
      const Local L = minimize_box([&](const Vector2d& p) { return distance_objective(s, tool_, tip, axis, p); },
                                   uv, s.lo(), s.hi(), 40, &evals);
      const double m = L.f;
      if (std::abs(m) < 1e-10) return true;
      if ((s.point(uv.x(), uv.y()) - res.P).norm() < near) return true;  // slid into P: the caller decides
      if (m > 0.0) lo = std::max(lo, beta);
      else hi = std::min(hi, beta);
      Vector3d g;
      const Vector3d X = s.point(uv.x(), uv.y());
      tool_distance(tool_, tip, axis, X, &g);
      const double dm = g.dot(u1.cross(X - O1));  // d(distance)/d(beta): the point turns about u1
      double next = (dm < 0.0) ? beta - m / dm : kInf;
      if (!(next > lo && next < hi)) next = std::isfinite(hi) ? 0.5 * (lo + hi) : std::max(2.0 * beta, beta + 1e-3);
      if (!std::isfinite(hi) && next > 1.5 * opt_.beta_max) return false;
      if (std::isfinite(hi) && hi - lo < 1e-14) return std::abs(m) < 1e-3 * opt_.tol;
      beta = next;
    }
    return false;
  };
  // Local gouge next to P: Newton from two points beside P along the pseudo-insert axis (where a tilted ring
  // first dips below a curved surface) finds a negative minimum if the tool cuts in around P.
  Vector2d side(0.0, 0.0);
  {
    const SurfacePoint sp = s.eval(res.uvP.x(), res.uvP.y(), 1);
    Eigen::Matrix<double, 3, 2> J;
    J << sp.Su, sp.Sv;
    side = (J.transpose() * J).ldlt().solve(J.transpose() * u1);
    side *= std::max(0.05 * Ri, samples_.spacing()) ;
  }
  // Warm starts: where the last gouge was found on each side (the minimum moves little with beta).
  Vector2d start[2] = {res.uvP + side, res.uvP - side};
  // Depth of the deepest local minimum of the tool distance beside P (0 if none below zero).
  int gouge_side = -1;  // once known, only that side is searched
  auto local_depth = [&](double beta) {
    tilt_pose(O1, u1, beta, tip0, &tip, &axis);
    double depth = 0.0;
    for (int k = 0; k < 2; ++k) {
      if (gouge_side >= 0 && k != gouge_side) continue;
      Vector2d uv = start[k];
      const Local L = minimize_box([&](const Vector2d& p) { return distance_objective(s, tool_, tip, axis, p); },
                                   uv, s.lo(), s.hi(), 10, &evals);
      if (L.f < depth) depth = L.f;
      if (L.f < -0.5 * allowed && (uv - res.uvP).norm() > 1e-9) {
        start[k] = uv;
        gouge_side = k;
      }
    }
    return depth;
  };
  auto safe_tilt = [&](double b, ContactReason why) {
    // Keep what is safe: the largest tilt the full check accepts below b.
    double a = 0.0;
    for (int k = 0; k < 20; ++k) {
      const double mid = 0.5 * (a + b);
      tilt_pose(O1, u1, mid, tip0, &tip, &axis);
      if (penetration(tip, axis, nullptr, &evals) <= allowed) a = mid;
      else b = mid;
    }
    tilt_pose(O1, u1, a, tip0, &tip, &axis);
    return finish_single(why, tip, axis, a);
  };

  // The gouge check of a tilt, VCRF: a sample is inside the tool tilted by beta exactly when its circular
  // ray arrives before beta, so the samples nearest to arriving (lowest ray angles, kept apart) are the
  // candidates that Newton polishes; no second scan of the samples. DRD scans (its own, independent check).
  auto check = [&](double beta, Vector2d* where) {
    if (drd) return penetration(tip, axis, where, &evals);
    const double sep2 = std::pow(2.0 * samples_.spacing(), 2);
    const auto& pts = samples_.points();
    std::size_t chosen[6];
    int n = 0;
    for (const auto& h : hits) {
      bool apart = true;
      for (int i = 0; i < n && apart; ++i) apart = (pts[chosen[i]] - pts[h.second]).squaredNorm() >= sep2;
      if (apart) chosen[n++] = h.second;
      if (n == 6) break;
    }
    double best = kInf;
    for (int i = 0; i < n; ++i) {
      Vector2d uv = samples_.params()[chosen[i]];
      const double d0 = tool_distance(tool_, tip, axis, pts[chosen[i]]);
      const Local L = minimize_box([&](const Vector2d& p) { return distance_objective(s, tool_, tip, axis, p); }, uv,
                                   s.lo(), s.hi(), 30, &evals);
      const double d = std::min(L.f, d0);
      if (d < best) {
        best = d;
        if (where) *where = L.f <= d0 ? uv : samples_.params()[chosen[i]];
      }
    }
    // Next to P (its own samples were left out: they touch): the local search beside P.
    Vector3d keep_tip = tip, keep_axis = axis;
    const double around_P = local_depth(beta);
    tip = keep_tip;
    axis = keep_axis;
    if (around_P < best) {
      best = around_P;
      if (where) *where = start[gouge_side >= 0 ? gouge_side : 0];
    }
    return std::isfinite(best) ? std::max(0.0, -best) : 0.0;
  };

  double beta = beta0, hi = kInf;
  bool two = false;
  for (int attempt = 0; attempt < 6 && !two; ++attempt) {
    if ((s.point(uvQ.x(), uvQ.y()) - res.P).norm() < near) {
      // The second contact runs into P: tilt until the tool osculates the surface at P, where the Hessian
      // of the tool distance over (U, V) at P stops being positive semidefinite (P stays a contact, so
      // the second-order term decides). Regula falsi (Illinois) on its smallest eigenvalue; the local
      // gouge search by Newton beside P backs it up. If the full check then finds a contact elsewhere,
      // that one is refined.
      double a = 0.0, b = std::min({beta, hi, opt_.beta_max});
      auto lam = [&](double t) {
        tilt_pose(O1, u1, t, tip0, &tip, &axis);
        const Local L = distance_objective(s, tool_, tip, axis, res.uvP);
        ++evals;
        const double h0 = L.H(0, 0), h1 = L.H(0, 1), h2 = L.H(1, 1);
        return 0.5 * (h0 + h2) - std::sqrt(0.25 * (h0 - h2) * (h0 - h2) + h1 * h1);
      };
      double fa = lam(a), fb = lam(b);
      if (fa >= 0.0 && fb < 0.0) {
        int side = 0;
        for (int k = 0; k < 60 && b - a > 1e-11; ++k) {
          const double c = (a * fb - b * fa) / (fb - fa);
          const double m = (c > a && c < b) ? c : 0.5 * (a + b);
          const double fm = lam(m);
          if (fm >= 0.0) {
            a = m;
            fa = fm;
            if (side == -1) fb *= 0.5;
            side = -1;
          } else {
            b = m;
            fb = fm;
            if (side == 1) fa *= 0.5;
            side = 1;
          }
        }
      } else {
        a = b;  // no sign change: the local depth search below decides over [0, b]
      }
      // Third-order terms put the limit a little below the second-order one: regula falsi on the local
      // depth beside P reaching -allowed / 2 (it is 0 below the limit and falls smoothly past it).
      const double target = -0.5 * allowed;
      double fu = local_depth(a) - target;
      if (fu < 0.0) {
        double lo = 0.0, up = a, fl = -target;
        int side = 0;
        for (int k = 0; k < 24 && up - lo > 1e-8; ++k) {
          const double c = (lo * fu - up * fl) / (fu - fl);
          const double m = (c > lo && c < up) ? c : 0.5 * (lo + up);
          const double fm = local_depth(m) - target;
          if (fm >= 0.0) {
            lo = m;
            fl = fm;
            if (side == -1) fu *= 0.5;
            side = -1;
          } else {
            up = m;
            fu = fm;
            if (side == 1) fl *= 0.5;
            side = 1;
          }
        }
        a = lo;
      }
      tilt_pose(O1, u1, a, tip0, &tip, &axis);
      Vector2d where;
      const double pen = check(a, &where);
      tilt_pose(O1, u1, a, tip0, &tip, &axis);
      if (pen <= allowed) return finish_single(ContactReason::CurvatureLimit, tip, axis, a, pen);
      if ((s.point(where.x(), where.y()) - res.P).norm() < near) return safe_tilt(a, ContactReason::CurvatureLimit);
      hi = a;
      beta = a;
      uvQ = where;
      continue;
    }
    if (!refine(beta, uvQ, hi)) return safe_tilt(std::min({beta0, hi, opt_.beta_max}), ContactReason::NotConverged);
    if ((s.point(uvQ.x(), uvQ.y()) - res.P).norm() < near) continue;
    if (beta > opt_.beta_max) {
      tilt_pose(O1, u1, opt_.beta_max, tip0, &tip, &axis);
      return finish_single(ContactReason::TiltLimit, tip, axis, opt_.beta_max);
    }
    tilt_pose(O1, u1, beta, tip0, &tip, &axis);
    Vector2d where;
    res.penetration = check(beta, &where);
    if (res.penetration <= allowed) {
      two = true;
      break;
    }
    // Another point touches first (the guess was a later contact): go on from the deepest point.
    hi = beta;
    uvQ = where;
  }
  if (!two) return safe_tilt(std::min({beta0, hi, opt_.beta_max}), ContactReason::NotConverged);

  // --- Two contacts.
  res.beta = beta;
  res.uvQ = uvQ;
  {
    const SurfacePoint sq = s.eval(uvQ.x(), uvQ.y(), 1);
    res.Q = sq.S;
    res.nQ = sq.normal();
    if (res.nQ.z() < 0.0) res.nQ = -res.nQ;
  }
  // The seed's axis: Z turned about global X by beta, the sign that leans the same way in Y.
  const Vector3d sx1 = Eigen::AngleAxisd(beta, Vector3d::UnitX()) * Z;
  const Vector3d sx2 = Eigen::AngleAxisd(-beta, Vector3d::UnitX()) * Z;
  const double sign = sx1.dot(axis) >= sx2.dot(axis) ? 1.0 : -1.0;
  res.seed_axis = sign > 0 ? sx1 : sx2;
  res.seed_axis_angle = std::acos(std::clamp(res.seed_axis.dot(axis), -1.0, 1.0));
  res.status = ContactStatus::TwoContacts;
  res.reason = ContactReason::Ok;
  if (opt_.rotation == TiltRotation::GlobalX) {
    const Matrix3d Rx = Eigen::AngleAxisd(sign * beta, Vector3d::UnitX()).toRotationMatrix();
    tip = O1 + Rx * (tip0 - O1);
    axis = res.seed_axis;
    res.reason = ContactReason::SeedRotation;
    res.penetration = penetration(tip, axis, nullptr, &evals);
  }
  res.tip = tip;
  res.axis = axis;
  res.centre = tip + Ri * axis;
  res.gap_P = tool_distance(tool_, tip, axis, res.P);
  res.gap_Q = tool_distance(tool_, tip, axis, res.Q);
  if (opt_.rotation == TiltRotation::PseudoInsert &&
      (res.penetration > opt_.tol || std::abs(res.gap_P) > opt_.tol || std::abs(res.gap_Q) > opt_.tol)) {
    res.status = ContactStatus::Failed;
    res.reason = res.penetration > opt_.tol ? ContactReason::Gouge : ContactReason::NotConverged;
  }
  if (opt_.rotation == TiltRotation::GlobalX && res.penetration > opt_.tol) res.status = ContactStatus::Failed;
  res.evaluations = evals;
  return res;
}

MultipointResult MultipointPositioner::position_axis(double x, double y) const {
  MultipointResult r = position_core(x, y);
  r.axis_xy = Vector2d(x, y);
  r.penetration_real = r.penetration;
  if (real_samples_ && r.status != ContactStatus::Failed) {
    // Positioned against the extended face, which holds the real one: the real face is checked on its own
    // (its samples and Newton), a position that enters it beyond tolerance fails.
    int evals = 0;
    r.penetration_real = penetration_real(r.tip, r.axis, nullptr, &evals);
    r.evaluations += evals;
    if (r.penetration_real > opt_.tol) {
      r.status = ContactStatus::Failed;
      r.reason = ContactReason::Gouge;
    }
  }
  if (real_samples_) {
    const Vector2d lo = real_->lo(), hi = real_->hi();
    auto outside = [&](const Vector2d& uv) {
      return uv.x() < lo.x() || uv.x() > hi.x() || uv.y() < lo.y() || uv.y() > hi.y();
    };
    r.P_extension = outside(r.uvP);
    r.Q_extension = outside(r.uvQ);
  }
  return r;
}

MultipointResult MultipointPositioner::position(double x, double y) const {
  if (opt_.anchor == FootprintAnchor::Axis) return position_axis(x, y);
  // Tip anchor: find the pre-tilt axis point q whose tilted tip lands on (x, y). The tip moves with q almost
  // by translation (the tilt changes slowly along the face), so q += (target - tip_xy) converges in a few
  // steps; where the position switches between one and two contacts the map jumps and the iteration may
  // cycle: the iterate nearest the target is kept (anchor_error says how near). Failed iterates are not
  // kept; the step is halved back from them.
  const Vector2d target(x, y);
  Vector2d q = target, last_step = Vector2d::Zero();
  MultipointResult best;
  bool have = false;
  double best_err = kInf;
  int evals = 0;
  const double goal = std::min(opt_.tol, 1e-3);
  for (int k = 0; k < opt_.anchor_iterations; ++k) {
    MultipointResult r = position_axis(q.x(), q.y());
    evals += r.evaluations;
    if (r.status == ContactStatus::Failed) {
      if (!have && k == 0) best = r;
      if (last_step.norm() < 1e-9) break;
      last_step *= 0.5;
      q -= last_step;
      continue;
    }
    const Vector2d err = target - r.tip.head<2>();
    const double e = err.norm();
    if (e < best_err) {
      best_err = e;
      best = r;
      have = true;
    }
    if (e <= goal) break;
    last_step = err;
    q += err;
  }
  best.anchor_error = have ? best_err : 0.0;
  best.evaluations = evals;
  return best;
}

void MultipointPositioner::position_batch(const double* xy, std::size_t n, MultipointResult* out,
                                          const BatchOptions& options) const {
  const std::size_t chunk = opt_.method == MultipointMethod::DRD ? 1 : 16;  // DRD points are slow: balance
  parallel_chunks(n, chunk, options, [&](std::size_t begin, std::size_t end) {
    for (std::size_t i = begin; i < end; ++i) out[i] = position(xy[2 * i], xy[2 * i + 1]);
  });
}

}  // namespace tmm
