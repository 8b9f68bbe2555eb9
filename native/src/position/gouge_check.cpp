#include "tmm/position/gouge_check.hpp"

#include <algorithm>
#include <cmath>
#include <utility>
#include <vector>

#include "tmm/position/objectives.hpp"
#include "tmm/util/constants.hpp"
#include "tmm/util/minimize_box.hpp"

namespace tmm {

using Eigen::Vector2d;
using Eigen::Vector3d;

namespace {

// At most this many candidates are polished (the lowest first); the discrete minima under a tool are a
// handful (P, Q, an edge or two), more only on a nearly flat patch of the tool distance.
constexpr std::size_t kMaxPolished = 16;

}  // namespace

double clearance(const PatchSurface& s, const SurfaceSamples& samples, const TorusTool& tool,
                 const ToolPose& pose, Vector2d* where, int* evals) {
  const Vector3d C = pose.tip + tool.Ri * pose.axis;
  // The tilted tool's torus lies within Ro + Ri of C; the margin covers the shank's foot.
  const double r = tool.radius() + 0.5 * tool.Ri;
  const auto& pts = samples.points();
  auto dist = [&](std::size_t k) { return tool_distance(tool, pose.tip, pose.axis, pts[k]); };
  // The candidates Newton polishes: every discrete local minimum of the tool distance over the samples,
  // in its patch's grid (no lower grid neighbour) and along the face's boundary (no lower neighbour on the
  // edge: a minimum on an edge curve need not be one in 2D). Minima are not thinned by distance: a second
  // contact 2 mm from P has its own basin, however close (a thinning radius of two sample
  // spacings kept only P's sample and missed a 1.8 um gouge on the edge beside it).
  std::vector<std::pair<double, std::size_t>> cand;
  double nearest = kInf;
  std::size_t nearest_k = 0;
  samples.within(C.x(), C.y(), r, [&](std::size_t k) {
    const double d = dist(k);
    if (evals) ++*evals;
    if (d < nearest) {
      nearest = d;
      nearest_k = k;
    }
    if (!(d <= tool.Ri)) return;
    bool grid_min = true, edge_min = samples.on_boundary(k);
    samples.grid_neighbours(k, [&](std::size_t n) { grid_min = grid_min && !(dist(n) < d); });
    if (!grid_min && edge_min)
      samples.boundary_neighbours(k, [&](std::size_t n) { edge_min = edge_min && !(dist(n) < d); });
    if (grid_min || edge_min) cand.emplace_back(d, k);
  });
  if (cand.size() > kMaxPolished) {
    std::nth_element(cand.begin(), cand.begin() + kMaxPolished, cand.end());
    cand.resize(kMaxPolished);
  }
  double best = kInf;
  Vector2d at = Vector2d::Zero();
  for (const auto& [d0, k] : cand) {
    Vector2d uv = samples.params()[k];
    const LocalModel L = minimize_box([&](const Vector2d& p) { return distance_objective(s, tool, pose, p); }, uv,
                                      s.lo(), s.hi(), 30, evals);
    const double d = std::min(L.f, d0);
    if (d < best) {
      best = d;
      at = L.f <= d0 ? uv : samples.params()[k];
    }
  }
  if (!std::isfinite(best) && std::isfinite(nearest)) {
    best = nearest;
    at = samples.params()[nearest_k];
  }
  if (where) *where = at;
  return best;
}

double penetration(const PatchSurface& s, const SurfaceSamples& samples, const TorusTool& tool,
                   const ToolPose& pose, Vector2d* where, int* evals) {
  const double c = clearance(s, samples, tool, pose, where, evals);
  return std::isfinite(c) ? std::max(0.0, -c) : 0.0;
}

}  // namespace tmm
