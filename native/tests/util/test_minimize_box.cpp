// The 2-D box minimiser alone, against known minima and a brute-force grid.
#include <gtest/gtest.h>

#include <cmath>

#include "tmm/util/minimize_box.hpp"

namespace {

using Eigen::Vector2d;
using tmm::LocalModel;

// f = (x - a)^T A (x - a) / 2 + c x0 y0 ... a general quadratic with its exact derivatives.
struct Quadratic {
  Eigen::Matrix2d A;
  Vector2d a;
  LocalModel operator()(const Vector2d& x) const {
    LocalModel L;
    const Vector2d d = x - a;
    L.f = 0.5 * d.dot(A * d);
    L.g = A * d;
    L.H = A;
    return L;
  }
};

// Rosenbrock's valley, scaled down: an ill-conditioned, non-convex function.
LocalModel rosenbrock(const Vector2d& p) {
  const double x = p.x(), y = p.y();
  LocalModel L;
  L.f = (1 - x) * (1 - x) + 10 * (y - x * x) * (y - x * x);
  L.g << -2 * (1 - x) - 40 * x * (y - x * x), 20 * (y - x * x);
  L.H << 2 - 40 * (y - x * x) + 80 * x * x, -40 * x, -40 * x, 20;
  return L;
}

TEST(MinimizeBox, InteriorMinimumOfAQuadratic) {
  Quadratic q{(Eigen::Matrix2d() << 3, 1, 1, 2).finished(), Vector2d(0.3, -0.2)};
  Vector2d x(0.9, 0.9);
  int evals = 0;
  const LocalModel L = tmm::minimize_box(q, x, Vector2d(-1, -1), Vector2d(1, 1), 20, &evals);
  EXPECT_NEAR(x.x(), 0.3, 1e-12);
  EXPECT_NEAR(x.y(), -0.2, 1e-12);
  EXPECT_NEAR(L.f, 0.0, 1e-20);
  EXPECT_GT(evals, 1);
}

TEST(MinimizeBox, MinimumOnTheBoxIsTheConstrainedOne) {
  // The free minimum (2, 0.5) lies outside x <= 1: the box minimum is on x = 1, at y minimising the
  // quadratic there (y = 0.5 - A01 / A11 (1 - 2)).
  Quadratic q{(Eigen::Matrix2d() << 2, 0.5, 0.5, 1).finished(), Vector2d(2, 0.5)};
  Vector2d x(0, 0);
  tmm::minimize_box(q, x, Vector2d(-1, -1), Vector2d(1, 1), 30, nullptr);
  EXPECT_EQ(x.x(), 1.0);
  EXPECT_NEAR(x.y(), 0.5 + 0.5 * 1.0 / 1.0, 1e-12);
}

TEST(MinimizeBox, CornerMinimumFixesBothCoordinates) {
  Quadratic q{Eigen::Matrix2d::Identity(), Vector2d(5, -5)};
  Vector2d x(0, 0);
  tmm::minimize_box(q, x, Vector2d(-1, -1), Vector2d(1, 1), 30, nullptr);
  EXPECT_EQ(x, Vector2d(1, -1));
}

TEST(MinimizeBox, NonConvexValleyAgreesWithBruteForce) {
  // Brute force on a fine grid over the box, then the minimiser from a corner must do at least as well.
  const Vector2d lo(-1.5, -0.5), hi(0.5, 1.5);  // the valley's minimum (1, 1) is outside: x <= 0.5
  double best = INFINITY;
  for (int i = 0; i <= 2000; ++i)
    for (int j = 0; j <= 2000; ++j)
      best = std::min(best, rosenbrock(Vector2d(lo.x() + 2.0 * i / 2000, lo.y() + 2.0 * j / 2000)).f);
  Vector2d x(-1.2, 1.0);
  const LocalModel L = tmm::minimize_box(rosenbrock, x, lo, hi, 200, nullptr);
  EXPECT_LE(L.f, best + 1e-9);
  EXPECT_NEAR(x.x(), 0.5, 1e-9);
  EXPECT_NEAR(x.y(), 0.25, 1e-6);
}

TEST(MinimizeBox, UndefinedPointsAreNeverAccepted) {
  // f = +inf for x > 0.2: the line search backs off; the result stays defined.
  auto f = [](const Vector2d& p) {
    LocalModel L;
    if (p.x() > 0.2) return L;  // f = inf
    L.f = (p.x() - 1) * (p.x() - 1) + p.y() * p.y();
    L.g << 2 * (p.x() - 1), 2 * p.y();
    L.H << 2, 0, 0, 2;
    return L;
  };
  Vector2d x(0, 0.5);
  const LocalModel L = tmm::minimize_box(f, x, Vector2d(-1, -1), Vector2d(1, 1), 50, nullptr);
  EXPECT_TRUE(std::isfinite(L.f));
  EXPECT_LE(x.x(), 0.2);
  EXPECT_LT(L.f, 1.0 + 0.25);  // better than the start
}

}  // namespace
