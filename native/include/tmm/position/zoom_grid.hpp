// The seed's zoom search over the surface parameters.
#pragma once

#include <Eigen/Core>

#include "tmm/surface/bezier.hpp"

namespace tmm {

// (d+1)^2 grid over the window best +- half (clamped to the face's domain), keep the best point, shrink
// the window by 2 / d around it, repeat `refinements` times. score(uv) returns a value to minimise (+inf:
// no ray hit); best and best_score are updated only by a strictly lower score. Adds one to *evals per
// score.
template <class Score>
void zoom_grid(const PatchSurface& s, Eigen::Vector2d& best, double& best_score, Eigen::Vector2d half,
               int divisions, int refinements, Score&& score, int* evals) {
  for (int r = 0; r < refinements; ++r) {
    const Eigen::Vector2d c = best;
    for (int a = 0; a <= divisions; ++a) {
      for (int b = 0; b <= divisions; ++b) {
        Eigen::Vector2d uv(c.x() - half.x() + 2.0 * half.x() * a / divisions,
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

}  // namespace tmm
