// Local minimisation of a smooth function of two variables over a box: Newton with a Levenberg shift,
// projected onto the box, with a backtracking line search. fn(x) returns the value, gradient and Hessian.
#pragma once

#include <Eigen/Core>
#include <Eigen/Dense>

#include <algorithm>
#include <cmath>

#include "tmm/util/constants.hpp"

namespace tmm {

// Value, gradient and Hessian of a function of two variables at one point (f = +inf: undefined there).
struct LocalModel {
  double f = kInf;
  Eigen::Vector2d g = Eigen::Vector2d::Zero();
  Eigen::Matrix2d H = Eigen::Matrix2d::Zero();
};

// Minimises fn from x (clamped to [lo, hi]) in at most maxit Newton steps; x receives the minimiser, the
// model there is returned. A coordinate on a bound whose gradient pushes outwards is held fixed. Each call
// of fn adds one to *evals (if given).
template <class Fn>
LocalModel minimize_box(Fn&& fn, Eigen::Vector2d& x, const Eigen::Vector2d& lo, const Eigen::Vector2d& hi,
                        int maxit, int* evals) {
  using Eigen::Matrix2d;
  using Eigen::Vector2d;
  x = x.cwiseMax(lo).cwiseMin(hi);
  LocalModel L = fn(x);
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
      const Vector2d xn = (x + step * d).cwiseMax(lo).cwiseMin(hi);
      const LocalModel Ln = fn(xn);
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

}  // namespace tmm
