// The 3D offset's arrival-time field (algo/arrival_field.hpp) against closed forms:
//  - a level plane, a straight start line at any angle: T is the distance over the flat step (exact to
//    rounding: first-order fast marching is exact for a plane wave);
//  - a level plane, a point start: T within the first-order error of the distance;
//  - a plane rising at 30 deg along +Y: a front moving across the slope takes the table's 30 deg step, one
//    moving along the level lines the flat step (the speed follows the front's direction);
//  - inactive nodes stay unreached; bad input is refused by name.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <stdexcept>
#include <vector>

#include "tmm/algo/arrival_field.hpp"

namespace {

constexpr double kPi = 3.14159265358979323846;
constexpr double kNan = std::numeric_limits<double>::quiet_NaN();

tmm::StepRuleTable table(double flat, double at30) {
  tmm::StepRuleTable r;
  r.steps = {flat, at30, at30};  // 0, 30, 60 deg
  r.dslope = kPi / 6;
  r.radius = 3;
  r.probe = 0.25;
  r.min_step = 0.01;
  return r;
}

TEST(ArrivalField, PlaneWaveOnALevelPlaneIsExact) {
  tmm::ArrivalGrid g{81, 61, 0.1};
  const std::vector<double> z(81 * 61, 0.0);
  const std::vector<std::uint8_t> active(z.size(), 1);
  for (double deg : {0.0, 17.0, 45.0, 71.0}) {
    const double a = deg * kPi / 180, nx = std::cos(a), ny = std::sin(a), flat = 0.5;
    std::vector<double> start(z.size(), kNan);
    for (int j = 0; j < g.ny; ++j)
      for (int i = 0; i < g.nx; ++i) {
        const double d = i * g.cell * nx + j * g.cell * ny;  // signed distance to the line through node 0
        // the start band, and the grid's inflow edges (there the scheme has one upwind neighbour only)
        if (d <= 0.15 || i == 0 || j == 0) start[j * g.nx + i] = d / flat;
      }
    const std::vector<double> T = tmm::arrival_field(g, z, active, start, table(flat, 0.3));
    for (int j = 0; j < g.ny; ++j)
      for (int i = 0; i < g.nx; ++i)
        ASSERT_NEAR(T[j * g.nx + i], (i * g.cell * nx + j * g.cell * ny) / flat, 1e-9) << deg << " " << i << " " << j;
  }
}

TEST(ArrivalField, PointSourceWithinFirstOrder) {
  tmm::ArrivalGrid g{101, 101, 0.1};
  const std::vector<double> z(101 * 101, 0.0);
  const std::vector<std::uint8_t> active(z.size(), 1);
  std::vector<double> start(z.size(), kNan);
  start[50 * 101 + 50] = 0;
  const std::vector<double> T = tmm::arrival_field(g, z, active, start, table(1.0, 0.5));
  double worst = 0;
  for (int j = 0; j < g.ny; ++j)
    for (int i = 0; i < g.nx; ++i) {
      const double d = std::hypot(i - 50, j - 50) * g.cell;
      worst = std::max(worst, std::abs(T[j * g.nx + i] - d) / std::max(d, g.cell));
    }
  EXPECT_LT(worst, 0.3);                               // first order near the source
  EXPECT_NEAR(T[50 * 101 + 100], 5.0, 1e-9);           // along an axis: exact
  EXPECT_NEAR(T[100 * 101 + 100], 5.0 * std::sqrt(2.0), 0.05 * 5.0 * std::sqrt(2.0));
}

TEST(ArrivalField, TheSpeedFollowsTheFrontsDirectionOnASlope) {
  tmm::ArrivalGrid g{61, 61, 0.1};
  const double t30 = std::tan(kPi / 6);
  std::vector<double> z(61 * 61);
  for (int j = 0; j < g.ny; ++j)
    for (int i = 0; i < g.nx; ++i) z[j * g.nx + i] = j * g.cell * t30;
  const std::vector<std::uint8_t> active(z.size(), 1);
  const double flat = 0.5, at30 = 0.4;
  // across the slope: a start line y = 1 (the probes stay on the grid), the front moves up the slope
  std::vector<double> start(z.size(), kNan);
  for (int i = 0; i < g.nx; ++i) start[10 * g.nx + i] = 0;
  std::vector<double> T = tmm::arrival_field(g, z, active, start, table(flat, at30));
  EXPECT_NEAR(T[50 * g.nx + 30], 4.0 / at30, 1e-6);
  // along the level lines: a start line x = 1
  std::fill(start.begin(), start.end(), kNan);
  for (int j = 0; j < g.ny; ++j) start[j * g.nx + 10] = 0;
  T = tmm::arrival_field(g, z, active, start, table(flat, at30));
  EXPECT_NEAR(T[30 * g.nx + 50], 4.0 / flat, 1e-6);
  EXPECT_NEAR(tmm::arrival_step(g, z, table(flat, at30), 3.0, 3.0, 0.0, 1.0), at30, 1e-9);
  EXPECT_NEAR(tmm::arrival_step(g, z, table(flat, at30), 3.0, 3.0, 1.0, 0.0), flat, 1e-9);
}

TEST(ArrivalField, InactiveNodesAndBadInput) {
  tmm::ArrivalGrid g{10, 10, 0.1};
  const std::vector<double> z(100, 0.0);
  std::vector<std::uint8_t> active(100, 1);
  for (int j = 0; j < 10; ++j) active[j * 10 + 5] = 0;  // a wall at i = 5
  std::vector<double> start(100, kNan);
  start[0] = 0;
  const std::vector<double> T = tmm::arrival_field(g, z, active, start, table(1, 1));
  EXPECT_TRUE(std::isinf(T[9]));
  EXPECT_TRUE(std::isfinite(T[4]));
  EXPECT_THROW(tmm::arrival_field(g, z, active, std::vector<double>(100, kNan), table(1, 1)), std::invalid_argument);
  tmm::StepRuleTable bad = table(1, 1);
  bad.steps = {};
  EXPECT_THROW(tmm::arrival_field(g, z, active, start, bad), std::invalid_argument);
  EXPECT_THROW(tmm::arrival_field(g, std::vector<double>(99, 0.0), active, start, table(1, 1)), std::invalid_argument);
}

}  // namespace
