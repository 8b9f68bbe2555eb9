// Lean passes' kernel fit (query/lean_profile.hpp) against independent references:
//  - a run over a tilted plane is one line: 2 vertices, the ends exact;
//  - a ball over a faceted sphere cap (2.5 mm facets, as sphere_on_plate.stl) and over a faceted cylinder across
//    its axis: every move within +-tol of the exact drop height sampled every 0.002 mm (drop_point), far fewer
//    vertices than samples, never fewer than the lower bound, the same for 1 and 2 threads;
//  - air beside the model: the moves across it stay as sampled;
//  - cancel throws Cancelled; a bad tolerance and malformed runs are refused by name.
// The Python fit (core/strategies/raster_lean.py) is compared in tests/core/test_lean_kernel.py.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <iostream>
#include <stdexcept>
#include <string>
#include <vector>

#include "support/test_meshes.hpp"
#include "tmm/query/drop_cutter.hpp"
#include "tmm/query/lean_profile.hpp"

namespace {

using tmm::Cutter;
using tmm::LeanOptions;
using tmm::LeanResult;
using tmm::LeanRuns;
using tmm::MeshIndex;

using tmm_test::grid_mesh;

double sphere_cap(double x, double y) { return std::sqrt(std::max(0.0, 30.0 * 30.0 - x * x - y * y)) - 20.0; }

// Runs along +X at the given y values (and one at 30 deg), samples every `step` from x0 to x1, exact heights.
LeanRuns runs_over(const MeshIndex& index, const Cutter& c, const std::vector<double>& ys, double x0, double x1,
                   double step, double floor_z) {
  LeanRuns r;
  r.offsets.push_back(0);
  auto add = [&](double ox, double oy, double ux, double uy, double length) {
    r.origin.insert(r.origin.end(), {ox, oy});
    r.dir.insert(r.dir.end(), {ux, uy});
    const int n = static_cast<int>(std::ceil(length / step));
    for (int i = 0; i <= n; ++i) {
      const double s = length * i / n;
      r.s.push_back(s);
      r.z.push_back(tmm::drop_point(index, c, ox + s * ux, oy + s * uy, floor_z));
      r.flags.push_back(i == 0 || i == n ? tmm::kLeanFixed : 0);
    }
    r.offsets.push_back(r.s.size());
  };
  for (double y : ys) add(x0, y, 1.0, 0.0, x1 - x0);
  add(x0, ys.front(), std::cos(M_PI / 6), std::sin(M_PI / 6), 0.8 * (x1 - x0));
  return r;
}

// The largest |move - exact| over every move of `res`, the exact drop sampled every `h` mm.
double worst_deviation(const MeshIndex& index, const Cutter& c, const LeanRuns& runs, const LeanResult& res,
                       double floor_z, double h) {
  double worst = 0;
  for (std::size_t k = 0; k + 1 < res.offsets.size(); ++k) {
    const double ox = runs.origin[2 * k], oy = runs.origin[2 * k + 1], ux = runs.dir[2 * k], uy = runs.dir[2 * k + 1];
    for (std::size_t v = res.offsets[k]; v + 1 < res.offsets[k + 1]; ++v) {
      const double sa = res.s[v], sb = res.s[v + 1], za = res.z[v], zb = res.z[v + 1];
      const int n = std::max(1, static_cast<int>(std::ceil((sb - sa) / h)));
      for (int i = 0; i <= n; ++i) {
        const double s = sa + (sb - sa) * i / n;
        const double z = za + (zb - za) * i / n;
        worst = std::max(worst, std::fabs(z - tmm::drop_point(index, c, ox + s * ux, oy + s * uy, floor_z)));
      }
    }
  }
  return worst;
}

TEST(LeanProfile, LineOverAPlaneIsOneMove) {
  const MeshIndex plane = grid_mesh([](double x, double y) { return 0.1 * x + 0.05 * y; }, -10, -10, 40, 20, 20, 12);
  const Cutter ball(3.0, 3.0);
  const LeanRuns runs = runs_over(plane, ball, {0.0, 3.3}, 0.0, 30.0, 0.25, -50);
  LeanOptions o;
  o.tol = 0.001;
  o.drop.drop_floor = -50;
  const LeanResult r = tmm::lean_profiles(plane, ball, runs, o);
  ASSERT_EQ(r.offsets.size(), 4u);
  for (std::size_t k = 0; k < 3; ++k) {
    EXPECT_EQ(r.offsets[k + 1] - r.offsets[k], 2u) << "run " << k;
    EXPECT_DOUBLE_EQ(r.z[r.offsets[k]], runs.z[runs.offsets[k]]);
    EXPECT_DOUBLE_EQ(r.z[r.offsets[k + 1] - 1], runs.z[runs.offsets[k + 1] - 1]);
  }
}

void expect_within_band(const MeshIndex& mesh, const Cutter& c, const std::vector<double>& ys, double tol,
                        double fewer) {
  const LeanRuns runs = runs_over(mesh, c, ys, -18.0, 18.0, 0.25, -50);
  LeanOptions o;
  o.tol = tol;
  o.drop.drop_floor = -50;
  o.lower_bound = true;
  const LeanResult r = tmm::lean_profiles(mesh, c, runs, o);
  EXPECT_LE(worst_deviation(mesh, c, runs, r, -50, 0.002), tol * (1 + 1e-6));
  const std::size_t moves = r.s.size() - (r.offsets.size() - 1);
  EXPECT_LT(moves * fewer, runs.s.size()) << "moves " << moves << " of " << runs.s.size() << " samples";
  std::cout << "moves " << moves << ", samples " << runs.s.size() << ", lower bound " << r.lower_bound << "\n";
  EXPECT_GE(moves, r.lower_bound);
  EXPECT_GT(r.breakpoints, 0u);
  tmm::BatchOptions one;
  one.threads = 1;
  const LeanResult r1 = tmm::lean_profiles(mesh, c, runs, o, one);
  EXPECT_EQ(r1.s, r.s);
  EXPECT_EQ(r1.z, r.z);
}

TEST(LeanProfile, BallOverAFacetedSphereStaysInTheBand) {
  const MeshIndex cap = grid_mesh(sphere_cap, -25, -25, 25, 25, 20, 20);  // 2.5 mm facets
  expect_within_band(cap, Cutter(3.0, 3.0), {-7.3, 0.0, 4.1}, 0.001, 3.0);
  expect_within_band(cap, Cutter(3.0, 3.0), {2.2}, 0.01, 6.0);
}

TEST(LeanProfile, BullOverAFacetedCylinderStaysInTheBand) {
  // a cylinder of radius 15 along Y (crossed by the runs), 1.25 mm facets, and a bull-nose D4 r1
  const MeshIndex cyl = grid_mesh([](double x, double) { return std::sqrt(std::max(0.0, 225.0 - x * x)) - 5.0; }, -14,
                             -20, 14, 20, 24, 8);
  expect_within_band(cyl, Cutter(2.0, 1.0), {0.7, 6.0}, 0.001, 2.0);
}

TEST(LeanProfile, NeverBelowTheFloor) {
  // the sphere cap clamped at z 5 (a final depth): the moves stay within the band and never go below it
  const MeshIndex cap = grid_mesh(sphere_cap, -25, -25, 25, 25, 20, 20);
  const Cutter ball(3.0, 3.0);
  LeanRuns runs = runs_over(cap, ball, {0.0, 6.3}, -18.0, 18.0, 0.25, -50);
  for (double& z : runs.z) z = std::max(z, 5.0);
  LeanOptions o;
  o.drop.drop_floor = -50;
  o.drop.clamp_floor = 5.0;
  const LeanResult r = tmm::lean_profiles(cap, ball, runs, o);
  for (double z : r.z) EXPECT_GE(z, 5.0);  // the moves are straight: their vertices bound them
  std::size_t on_floor = 0;
  for (double z : runs.z) on_floor += z == 5.0;
  EXPECT_GT(on_floor, 10u);
}

TEST(LeanProfile, AirKeepsTheSampledMoves) {
  // a plate over [0, 10] x [0, 10] only: a run from -5 to 15 crosses air at both ends
  const MeshIndex plate = grid_mesh([](double, double) { return 1.0; }, 0, 0, 10, 10, 4, 4);
  const Cutter ball(1.0, 1.0);
  LeanRuns runs = runs_over(plate, ball, {5.0}, -5.0, 15.0, 0.5, -100);
  runs.offsets.resize(2);  // the +X run only
  runs.origin.resize(2), runs.dir.resize(2);
  runs.s.resize(runs.offsets[1]), runs.z.resize(runs.offsets[1]), runs.flags.resize(runs.offsets[1]);
  LeanOptions o;
  o.drop.drop_floor = -100;
  o.drop.air_below = -99;
  const LeanResult r = tmm::lean_profiles(plate, ball, runs, o);
  // every sample in the air stays (as sampled), the plate (x 0 .. 10: s 5 .. 15) is one line
  for (std::size_t i = 0; i < runs.s.size(); ++i)
    if (runs.z[i] <= -99) {
      EXPECT_NE(std::find(r.s.begin(), r.s.end(), runs.s[i]), r.s.end()) << "air sample at s " << runs.s[i];
    }
  bool one_line = false;
  for (std::size_t i = 0; i + 1 < r.s.size(); ++i) one_line |= r.s[i] <= 5.0 + 1e-9 && r.s[i + 1] >= 15.0 - 1e-9;
  EXPECT_TRUE(one_line);
}

TEST(LeanProfile, CancelThrows) {
  const MeshIndex cap = grid_mesh(sphere_cap, -25, -25, 25, 25, 20, 20);
  const Cutter ball(3.0, 3.0);
  const LeanRuns runs = runs_over(cap, ball, {-8, -6, -4, -2, 0, 2, 4, 6, 8, 10, 12, 14}, -18, 18, 0.25, -50);
  LeanOptions o;
  o.drop.drop_floor = -50;
  tmm::BatchOptions batch;
  batch.threads = 2;
  batch.progress = [](double) { return false; };
  EXPECT_THROW(tmm::lean_profiles(cap, ball, runs, o, batch), tmm::Cancelled);
}

TEST(LeanProfile, BadInputRefusedByName) {
  const MeshIndex plane = grid_mesh([](double, double) { return 0.0; }, 0, 0, 10, 10, 2, 2);
  const Cutter ball(1.0, 1.0);
  const LeanRuns runs = runs_over(plane, ball, {5.0}, 0, 10, 0.5, -50);
  for (double tol : {0.0, -0.001, std::nan(""), 2.0}) {
    LeanOptions o;
    o.tol = tol;
    try {
      tmm::lean_profiles(plane, ball, runs, o);
      ADD_FAILURE() << "tol " << tol << " accepted";
    } catch (const std::invalid_argument& e) {
      EXPECT_NE(std::string(e.what()).find("lean tolerance"), std::string::npos) << e.what();
    }
  }
  LeanRuns bad = runs;
  bad.offsets.back() += 1;
  EXPECT_THROW(tmm::lean_profiles(plane, ball, bad, LeanOptions()), std::invalid_argument);
  bad = runs;
  bad.dir[0] = 2.0;
  EXPECT_THROW(tmm::lean_profiles(plane, ball, bad, LeanOptions()), std::invalid_argument);
  LeanOptions huge;
  huge.max_step = 1e-9, huge.min_step = 1e-9;
  try {
    tmm::lean_profiles(plane, ball, runs, huge);
    ADD_FAILURE() << "work above the limit accepted";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("lean work"), std::string::npos) << e.what();
  }
}

}  // namespace
