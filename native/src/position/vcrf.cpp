// VCRF (seed 001 chapter 4): the vertical and the circular rays fired from the surface samples.
#include <algorithm>
#include <cmath>
#include <utility>

#include "tmm/position/candidates.hpp"
#include "tmm/position/tilt_guess.hpp"
#include "tmm/position/zoom_grid.hpp"
#include "tmm/util/minimize_box.hpp"

namespace tmm {

using Eigen::Vector2d;
using Eigen::Vector3d;

DropContact vcrf_drop(const PatchSurface& s, const SurfaceSamples& samples, const TorusTool& tool,
                      const MultipointOptions& options, double x, double y, int* evals) {
  // Vertical rays fired up from the samples to the lower tool surface: tip = S_z - h(rho), highest wins.
  // The best few samples, kept apart, are refined (the zoom grid, then Newton): near the tool's rim h is
  // steep, so the highest sample need not lie next to the highest point.
  const double Rt = tool.radius();
  const auto& pts = samples.points();
  SpreadLowest<std::size_t, 3> top(std::pow(2.0 * samples.spacing(), 2));
  samples.within(x, y, Rt, [&](std::size_t k) {
    const double rho = std::hypot(pts[k].x() - x, pts[k].y() - y);
    top.offer(-(pts[k].z() - tool.profile(rho)), k, pts[k]);
  });
  DropContact d;
  auto score = [&](const Vector2d& p) {
    const Vector3d S = s.point(p.x(), p.y());
    const double rho = std::hypot(S.x() - x, S.y() - y);
    return rho > Rt ? kInf : -(S.z() - tool.profile(rho));
  };
  auto objective = [&](const Vector2d& p) { return drop_objective(s, tool, x, y, p); };
  if (top.size() == 0) {
    // No sample under the tool: the face may still reach under it between samples (narrow faces).
    Vector2d uv = 0.5 * (s.lo() + s.hi());
    const LocalModel L = minimize_box(objective, uv, s.lo(), s.hi(), 50, evals);
    if (!std::isfinite(L.f)) return d;
    d.ok = true;
    d.tip_z = -L.f;
    d.uv = uv;
    return d;
  }
  // Highest first (ties by sample index). Insertion sort: std::sort's unrolled small-array path warns on
  // a fixed K array.
  std::pair<double, std::size_t> ranked[3];
  int n = top.size();
  for (int i = 0; i < n; ++i) ranked[i] = {top[i].score, top[i].item};
  for (int i = 1; i < n; ++i)
    for (int j = i; j > 0 && ranked[j] < ranked[j - 1]; --j) std::swap(ranked[j], ranked[j - 1]);
  // Candidates far below the best cannot win: a sample misses its local maximum by at most the rise of
  // the tool's profile over one sample spacing, taken here as Ri / 2 (the final check is the safety net).
  while (n > 1 && ranked[n - 1].first > ranked[0].first + 0.5 * tool.Ri) --n;
  double best = kInf;
  for (int i = 0; i < n; ++i) {
    Vector2d uv = samples.params()[ranked[i].second];
    double f = ranked[i].first;
    if (i == 0)
      zoom_grid(s, uv, f, samples.step(ranked[i].second), options.divisions, options.refinements, score, evals);
    const LocalModel L = minimize_box(objective, uv, s.lo(), s.hi(), 50, evals);
    const double fi = std::min(L.f, f);
    if (fi < best) {
      best = fi;
      d.uv = L.f <= f ? uv : samples.params()[ranked[i].second];
    }
  }
  d.ok = std::isfinite(best);
  d.tip_z = -best;
  return d;
}

// The circle of radius R in the plane u = su meets the torus (seed eq. 29) where
//   sqrt(su^2 + (v - Ro)^2) = K - v,  K = (su^2 + 2 Ro^2 - Ri^2 + R^2) / (2 Ro),
// which is linear in v after squaring: one v, two points w = +-sqrt(R^2 - v^2) (only the lower one is on
// the tool's boundary). The other boundary pieces (flat bottom or hollow ceiling, shank) are planes and a
// cylinder: closed forms as well. The first crossing along the circle is where the point enters; pseudo-
// angles spare the comparisons an atan2.
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

TiltGuess vcrf_tilt_guess(const PatchSurface& s, const SurfaceSamples& samples, const TorusTool& tool,
                          const MultipointOptions& options, const PseudoInsert& frame, const Vector2d& uvP,
                          double x, double y, int* evals) {
  // Circular rays from the samples around the tool; samples touching the vertical tool (P's) are left out.
  TiltGuess g;
  g.uvQ = uvP;
  const Vector3d Z = Vector3d::UnitZ();
  const auto& pts = samples.points();
  std::size_t kbest = 0;
  const double limit = 1.0 - std::cos(std::min(2.0 * options.beta_max, kPi));  // pseudo-angle
  samples.within(x, y, tool.radius() + 0.5 * tool.Ri, [&](std::size_t k) {
    const Vector3d l = frame.local(pts[k]);
    const double b = circular_ray(tool, l.x(), l.y(), l.z());
    ++*evals;
    if (b > limit || tool_distance(tool, frame.tip0, Z, pts[k]) <= 1e-7) return;
    g.hits.emplace_back(b, k);
    if (b < g.beta) {
      g.beta = b;
      kbest = k;
    }
  });
  std::sort(g.hits.begin(), g.hits.end());
  if (std::isfinite(g.beta)) {
    g.uvQ = samples.params()[kbest];
    auto score = [&](const Vector2d& p) {
      const Vector3d S = s.point(p.x(), p.y());
      if (tool_distance(tool, frame.tip0, Z, S) <= 1e-7) return kInf;
      const Vector3d l = frame.local(S);
      return circular_ray(tool, l.x(), l.y(), l.z());
    };
    zoom_grid(s, g.uvQ, g.beta, samples.step(kbest), options.divisions, options.refinements, score, evals);
    g.beta = pseudo_to_angle(g.beta);
  }
  return g;
}

}  // namespace tmm
