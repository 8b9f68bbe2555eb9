// Lean passes' kernel fit (algo/lean_profile.hpp) against independent references:
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
#include "tmm/algo/lean_profile.hpp"

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

// The largest |move - exact| over every move of `res` (an arc: the circle about its centre through its start), the
// exact drop sampled every `h` mm.
double worst_deviation(const MeshIndex& index, const Cutter& c, const LeanRuns& runs, const LeanResult& res,
                       double floor_z, double h) {
  double worst = 0;
  for (std::size_t k = 0; k + 1 < res.offsets.size(); ++k) {
    const double ox = runs.origin[2 * k], oy = runs.origin[2 * k + 1], ux = runs.dir[2 * k], uy = runs.dir[2 * k + 1];
    for (std::size_t v = res.offsets[k]; v + 1 < res.offsets[k + 1]; ++v) {
      const double sa = res.s[v], sb = res.s[v + 1], za = res.z[v], zb = res.z[v + 1];
      const bool arc = !res.arc_s.empty() && std::isfinite(res.arc_s[v + 1]);
      const double cs = arc ? res.arc_s[v + 1] : 0, cz = arc ? res.arc_z[v + 1] : 0;
      const double r = std::hypot(sa - cs, za - cz), side = za > cz ? 1.0 : -1.0;
      const int n = std::max(1, static_cast<int>(std::ceil((sb - sa) / h)));
      for (int i = 0; i <= n; ++i) {
        const double s = sa + (sb - sa) * i / n;
        const double z = arc ? cz + side * std::sqrt(std::max(r * r - (s - cs) * (s - cs), 0.0))
                             : za + (zb - za) * i / n;
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

// Runs marked for arcs over a cylinder fine enough to be a circle to a controller: the arcs (G-code valid: both ends
// on the circle, radius within the limits) hold the band, cut the moves several times, and a run not marked for
// arcs is fitted exactly as without them.
LeanResult expect_arcs_within_band(const MeshIndex& mesh, const Cutter& c, double tol, double fewer) {
  LeanRuns runs = runs_over(mesh, c, {0.7, 6.0}, -13.0, 13.0, 0.25, -50);
  LeanOptions o;
  o.tol = tol;
  o.drop.drop_floor = -50;
  const LeanResult lines = tmm::lean_profiles(mesh, c, runs, o);
  runs.arcs = {1, 1, 0};  // the 30 deg run lies in no principal plane
  const LeanResult r = tmm::lean_profiles(mesh, c, runs, o);
  EXPECT_LE(worst_deviation(mesh, c, runs, r, -50, 0.002), tol * (1 + 1e-6));
  EXPECT_GT(r.arcs, 0u);
  const auto moves = [](const LeanResult& x, std::size_t k) { return x.offsets[k + 1] - x.offsets[k] - 1; };
  for (std::size_t k = 0; k < 2; ++k)
    EXPECT_LE(moves(r, k) * fewer, moves(lines, k)) << "run " << k << ": " << moves(r, k) << " with arcs, "
                                                    << moves(lines, k) << " lines";
  EXPECT_TRUE(std::equal(r.s.begin() + r.offsets[2], r.s.end(), lines.s.begin() + lines.offsets[2],
                         lines.s.end()));
  EXPECT_TRUE(std::equal(r.z.begin() + r.offsets[2], r.z.end(), lines.z.begin() + lines.offsets[2],
                         lines.z.end()));
  for (std::size_t k = 0; k + 1 < r.offsets.size(); ++k) {
    EXPECT_TRUE(std::isnan(r.arc_s[r.offsets[k]])) << "a run starts with a vertex, not a move";
    for (std::size_t v = r.offsets[k] + 1; v < r.offsets[k + 1]; ++v) {
      if (std::isnan(r.arc_s[v])) continue;
      EXPECT_LT(k, 2u) << "an arc in the run not marked for arcs";
      const double ra = std::hypot(r.s[v - 1] - r.arc_s[v], r.z[v - 1] - r.arc_z[v]);
      const double rb = std::hypot(r.s[v] - r.arc_s[v], r.z[v] - r.arc_z[v]);
      EXPECT_NEAR(ra, rb, 1e-9 * ra);
      EXPECT_GE(ra, o.arc_min_radius);
      EXPECT_LE(ra, o.arc_max_radius);
    }
  }
  tmm::BatchOptions one;
  one.threads = 1;
  const LeanResult r1 = tmm::lean_profiles(mesh, c, runs, o, one);
  EXPECT_EQ(r1.s, r.s);
  EXPECT_EQ(r1.arc_z.size(), r.arc_z.size());
  for (std::size_t v = 0; v < std::min(r.arc_z.size(), r1.arc_z.size()); ++v)
    EXPECT_TRUE(r1.arc_z[v] == r.arc_z[v] || (std::isnan(r1.arc_z[v]) && std::isnan(r.arc_z[v]))) << v;
  std::cout << "arcs " << r.arcs << ", moves " << r.s.size() - 3 << " (lines alone " << lines.s.size() - 3 << ")\n";
  return r;
}

TEST(LeanProfile, ArcsOverAFinelyFacetedCylinder) {
  // radius 15 along Y, 0.047 mm facets (1.8e-5 mm from the circle): ball r 1 and bull-nose D4 r1
  const MeshIndex cyl = grid_mesh([](double x, double) { return std::sqrt(std::max(0.0, 225.0 - x * x)) - 5.0; }, -14,
                             -20, 14, 20, 600, 8);
  expect_arcs_within_band(cyl, Cutter(1.0, 1.0), 0.001, 4.0);
  expect_arcs_within_band(cyl, Cutter(2.0, 1.0), 0.001, 4.0);
}

TEST(LeanProfile, ArcsOverAFacetedSphereStayInTheBand) {
  // 2.5 mm facets: an arc takes a roll over an edge, no more (docs/history/results-log.md, "The least number of moves")
  const MeshIndex cap = grid_mesh(sphere_cap, -25, -25, 25, 25, 20, 20);
  expect_arcs_within_band(cap, Cutter(3.0, 3.0), 0.001, 1.0);
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
