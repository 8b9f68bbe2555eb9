#include "tmm/position/gouge_check.hpp"

#include <cmath>

#include "tmm/position/candidates.hpp"
#include "tmm/position/objectives.hpp"
#include "tmm/util/constants.hpp"
#include "tmm/util/minimize_box.hpp"

namespace tmm {

using Eigen::Vector2d;
using Eigen::Vector3d;

double penetration(const PatchSurface& s, const SurfaceSamples& samples, const TorusTool& tool,
                   const ToolPose& pose, Vector2d* where, int* evals) {
  const Vector3d C = pose.tip + tool.Ri * pose.axis;
  // The tilted tool's torus lies within Ro + Ri of C; the margin covers the shank's foot.
  const double r = tool.radius() + 0.5 * tool.Ri;
  const auto& pts = samples.points();
  // The lowest few samples, kept apart from each other, are polished by Newton.
  SpreadLowest<std::size_t, 6> low(std::pow(2.0 * samples.spacing(), 2));
  samples.within(C.x(), C.y(), r, [&](std::size_t k) {
    const double d = tool_distance(tool, pose.tip, pose.axis, pts[k]);
    if (evals) ++*evals;
    if (d <= tool.Ri) low.offer(d, k, pts[k]);
  });
  double best = kInf;
  Vector2d at = Vector2d::Zero();
  for (const auto& c : low) {
    Vector2d uv = samples.params()[c.item];
    const LocalModel L = minimize_box([&](const Vector2d& p) { return distance_objective(s, tool, pose, p); }, uv,
                                      s.lo(), s.hi(), 30, evals);
    const double d = std::min(L.f, c.score);
    if (d < best) {
      best = d;
      at = L.f <= c.score ? uv : samples.params()[c.item];
    }
  }
  if (where) *where = at;
  return std::isfinite(best) ? std::max(0.0, -best) : 0.0;
}

}  // namespace tmm
