// The seed's zoom search alone: each level is the brute-force minimum over its grid.
#include <gtest/gtest.h>

#include <cmath>
#include <memory>
#include <vector>

#include "tmm/position/zoom_grid.hpp"

namespace {

using Eigen::Vector2d;

tmm::PatchSurface unit_square() {
  std::vector<Eigen::Vector3d> net;
  for (int i = 0; i < 2; ++i)
    for (int j = 0; j < 2; ++j) net.emplace_back(i, j, 0);
  return tmm::PatchSurface(tmm::BezierPatch(1, 1, net));
}

TEST(ZoomGrid, OneLevelIsTheBruteForceGridMinimum) {
  const tmm::PatchSurface s = unit_square();
  auto f = [](const Vector2d& p) { return std::sin(7 * p.x()) * std::cos(5 * p.y()) + p.x(); };
  Vector2d best(0.5, 0.5);
  double score = f(best);
  int evals = 0;
  tmm::zoom_grid(s, best, score, Vector2d(0.5, 0.5), 8, 1, f, &evals);
  EXPECT_EQ(evals, 81);
  double brute = f(Vector2d(0.5, 0.5));
  for (int a = 0; a <= 8; ++a)
    for (int b = 0; b <= 8; ++b) brute = std::min(brute, f(Vector2d(a / 8.0, b / 8.0)));
  EXPECT_EQ(score, brute);
  EXPECT_EQ(f(best), score);
}

TEST(ZoomGrid, LevelsConvergeOnASmoothMinimum) {
  const tmm::PatchSurface s = unit_square();
  auto f = [](const Vector2d& p) { return (p - Vector2d(0.3141, 0.2718)).squaredNorm(); };
  Vector2d best(0.5, 0.5);
  double score = f(best);
  tmm::zoom_grid(s, best, score, Vector2d(0.5, 0.5), 6, 8, f, nullptr);
  // The window after 8 levels: 0.5 (2/6)^8 ~ 7.6e-5; the best grid point lies within a grid step of it.
  EXPECT_LT((best - Vector2d(0.3141, 0.2718)).norm(), 1e-4);
}

TEST(ZoomGrid, ClampsToTheDomainAndKeepsAStrictlyBetterStart) {
  const tmm::PatchSurface s = unit_square();
  Vector2d best(0.0, 0.0);
  double score = -1.0;  // better than anything the grid finds
  tmm::zoom_grid(s, best, score, Vector2d(2.0, 2.0), 4, 2, [](const Vector2d& p) {
    EXPECT_TRUE(p.x() >= 0 && p.x() <= 1 && p.y() >= 0 && p.y() <= 1);
    return 0.0;
  }, nullptr);
  EXPECT_EQ(score, -1.0);
  EXPECT_EQ(best, Vector2d(0.0, 0.0));
}

}  // namespace
