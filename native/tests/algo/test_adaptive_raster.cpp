// Adaptive raster pass placement (algo/adaptive_raster.hpp) against closed forms:
//  - a level plane: every gap is the ball's planar step for 0.95 x the tolerance, R - sqrt(R^2 - (s/2)^2);
//  - a convex cylinder along the passes: the cusp between two ball passes is where the two balls' circles
//    cross, nearer the axis: D cos(d/2) - sqrt(R^2 - D^2 sin^2(d/2)) - Rc (D = Rc + R, d the angle between
//    the centres); every gap's exact cusp within the tolerance and not much under it;
//  - the same offsets for any thread count; progress sees the width placed, also within a pass, where cancel
//    throws Cancelled too;
//  - bad options and a too large section grid refused by name.
// The numpy reference (core/footprint/adaptive_raster.py) is compared in tests/core/test_adaptive_raster.py.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>
#include <vector>

#include "support/test_meshes.hpp"
#include "tmm/algo/adaptive_raster.hpp"

namespace {

using tmm::AdaptiveRasterOptions;
using tmm::Cutter;
using tmm::MeshIndex;

using tmm_test::grid_mesh;

AdaptiveRasterOptions options(double cusp) {
  AdaptiveRasterOptions o;
  o.xmin = 0, o.ymin = 0, o.xmax = 20, o.ymax = 12;
  o.cusp = cusp;
  o.sample_step = 0.5;
  o.floor_z = -50;
  o.max_slope = 75.0 * M_PI / 180.0;
  o.step_min = 0.05;
  o.step_max = 2 * std::sqrt(2 * 3.0 * cusp - cusp * cusp);  // the ball's planar step: the widest useful
  return o;
}

double ball_plane_step(double R, double cusp) { return 2 * std::sqrt(2 * R * cusp - cusp * cusp); }

TEST(AdaptiveRaster, LevelPlaneGivesThePlanarStep) {
  const MeshIndex plane = grid_mesh([](double, double) { return 0.0; }, -20, -20, 40, 40, 4, 4);
  const Cutter ball(3.0, 3.0);
  const AdaptiveRasterOptions o = options(0.01);
  const auto r = tmm::adaptive_raster(plane, ball, ball, o, {});
  ASSERT_GE(r.offsets.size(), 3u);
  EXPECT_DOUBLE_EQ(r.offsets.front(), 0.0);
  EXPECT_NEAR(r.offsets.back(), 12.0, 1e-12);
  const double expected = ball_plane_step(3.0, 0.95 * 0.01);
  for (std::size_t k = 0; k + 2 < r.offsets.size(); ++k) {  // the last gap closes on the boundary
    const double gap = r.offsets[k + 1] - r.offsets[k];
    EXPECT_LE(gap, expected * 1.001) << k;
    EXPECT_GE(gap, expected * 0.97) << k;
  }
  for (double c : r.cusps) EXPECT_LE(c, 0.01);
  EXPECT_EQ(r.limited, 0u);
  EXPECT_EQ(r.unreachable, 0u);
}

TEST(AdaptiveRaster, ConvexCylinderKeepsTheExactCusp) {
  const double Rc = 20.0, R = 3.0, D = Rc + R, tol = 0.01;
  // the cylinder y^2 + z^2 = Rc^2 along X, vertices on it every 0.24 deg (sagitta 4e-5 mm)
  const int n = 480;
  tmm::Vertices V(2 * (n + 1), 3);
  for (int j = 0; j <= n; ++j) {
    const double t = -1.0 + 2.0 * j / n;  // radians: the cylinder from -57 to +57 deg
    V.row(2 * j) << -10, Rc * std::sin(t), Rc * std::cos(t);
    V.row(2 * j + 1) << 30, Rc * std::sin(t), Rc * std::cos(t);
  }
  tmm::Triangles T(2 * n, 3);
  for (int j = 0; j < n; ++j) {
    T.row(2 * j) << 2 * j, 2 * j + 1, 2 * j + 3;
    T.row(2 * j + 1) << 2 * j, 2 * j + 3, 2 * j + 2;
  }
  const MeshIndex mesh(V, T);
  const Cutter ball(R, R);
  AdaptiveRasterOptions o = options(tol);
  o.ymin = -10, o.ymax = 10;
  const auto r = tmm::adaptive_raster(mesh, ball, ball, o, {});
  ASSERT_GE(r.offsets.size(), 10u);
  EXPECT_EQ(r.limited, 0u);
  double smallest = 1e9, largest = 0;
  for (std::size_t k = 0; k + 2 < r.offsets.size(); ++k) {
    // the ball centres on the circle of radius D, at the passes' y
    const double a1 = std::asin(r.offsets[k] / D), a2 = std::asin(r.offsets[k + 1] / D), d = a2 - a1;
    const double ridge = D * std::cos(d / 2) - std::sqrt(R * R - D * D * std::sin(d / 2) * std::sin(d / 2));
    const double exact = ridge - Rc;
    EXPECT_LE(exact, tol) << "gap " << k;
    smallest = std::min(smallest, exact);
    largest = std::max(largest, exact);
    // the measured cusp is the exact one less the dense envelope's own (about 1/64) and the facets'
    EXPECT_NEAR(r.cusps[k], exact, 0.05 * tol) << "gap " << k;
  }
  EXPECT_GE(smallest, 0.85 * tol);  // aimed at 0.95 x the tolerance within a 2 % bracket
  EXPECT_LE(largest, 0.97 * tol);
  // steeper towards the sides: the horizontal gaps shrink away from the top (cos of the slope)
  const double top_gap = r.offsets[r.offsets.size() / 2 + 1] - r.offsets[r.offsets.size() / 2];
  EXPECT_GT(top_gap, (r.offsets[2] - r.offsets[1]) * 1.05);
}

TEST(AdaptiveRaster, SameForAnyThreadCountProgressAndCancel) {
  const MeshIndex bump = grid_mesh([](double x, double y) { return 2.0 * std::exp(-((x - 10) * (x - 10) + (y - 6) * (y - 6)) / 18.0); },
                              -10, -9, 30, 21, 80, 60);
  const Cutter bull(4.0, 2.0);
  AdaptiveRasterOptions o = options(0.01);
  o.sample_step = 0.25;
  o.floor_z = 0;
  o.step_max = 1.0;
  tmm::BatchOptions one, two;
  one.threads = 1;
  two.threads = 2;
  std::vector<double> seen;
  two.progress = [&](double f) {
    seen.push_back(f);
    return true;
  };
  const auto a = tmm::adaptive_raster(bump, bull, bull, o, one);
  const auto b = tmm::adaptive_raster(bump, bull, bull, o, two);
  EXPECT_EQ(a.offsets, b.offsets);
  EXPECT_EQ(a.cusps, b.cusps);
  // before each pass after the first the width placed, then within the pass that same fraction: never back,
  // and as many values as passes placed
  for (std::size_t k = 1; k < seen.size(); ++k) EXPECT_GE(seen[k], seen[k - 1]);
  EXPECT_EQ(seen.front(), 0.0);
  std::vector<double> starts = seen;
  starts.erase(std::unique(starts.begin(), starts.end()), starts.end());
  EXPECT_EQ(starts.size(), a.offsets.size() - 1);
  EXPECT_GT(seen.size(), starts.size());  // reports within the passes
  // cancelled within a pass: stopped at the report after the first with some width placed, which comes from
  // within that pass (the same fraction), not from the next pass's start
  tmm::BatchOptions stop;
  std::vector<double> asked;
  stop.progress = [&](double f) {
    asked.push_back(f);
    return !(asked.size() >= 2 && asked[asked.size() - 2] > 0.0);
  };
  EXPECT_THROW(tmm::adaptive_raster(bump, bull, bull, o, stop), tmm::Cancelled);
  ASSERT_GE(asked.size(), 2u);
  EXPECT_GT(asked.back(), 0.0);
  EXPECT_EQ(asked.back(), asked[asked.size() - 2]);
}

TEST(AdaptiveRaster, BadOptionsAreRefusedByName) {
  const MeshIndex plane = grid_mesh([](double, double) { return 0.0; }, -20, -20, 40, 40, 2, 2);
  const Cutter ball(3.0, 3.0);
  auto refused = [&](AdaptiveRasterOptions o, const std::string& words) {
    try {
      tmm::adaptive_raster(plane, ball, ball, o, {});
      ADD_FAILURE() << "accepted, expected: " << words;
    } catch (const std::invalid_argument& e) {
      EXPECT_NE(std::string(e.what()).find(words), std::string::npos) << e.what();
    }
  };
  AdaptiveRasterOptions o = options(0.01);
  o.cusp = 0;
  refused(o, "cusp height must be > 0 mm, got 0");
  o = options(0.01);
  o.sample_step = -1;
  refused(o, "sample step must be > 0 mm, got -1");
  o = options(0.01);
  o.step_min = 1.0;
  refused(o, "step_min <= step_max");
  o = options(0.01);
  o.step_max = 6.0;
  refused(o, "< 6 mm (the tool's width)");
  o = options(0.01);
  o.xmax = o.xmin;
  refused(o, "boundary must be finite and non-empty");
  o = options(0.01);
  o.max_slope = M_PI / 2;
  refused(o, "slope limit must be in (0, pi/2)");
  o = options(0.01);
  o.xmax = 1e6;
  o.sample_step = 0.01;
  refused(o, "section samples per pass, more than the kernel's");
}

}  // namespace
