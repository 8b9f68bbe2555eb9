// The cutter's profile on its own (no mesh): refused tools, the generalized APT cutter's special cases against
// their closed forms, and reach2 against the profile it inverts.
#include <gtest/gtest.h>

#include <cmath>
#include <stdexcept>
#include <utility>

#include "tmm/cutter/cutter.hpp"

namespace {

using tmm::Cutter;

TEST(Cutter, RejectsImpossibleTools) {
  EXPECT_THROW(Cutter(0.0, 0.0), std::invalid_argument);
  EXPECT_THROW(Cutter(-1.0, 0.0), std::invalid_argument);
  EXPECT_THROW(Cutter(NAN, 0.0), std::invalid_argument);
  EXPECT_THROW(Cutter(3.0, 3.5), std::invalid_argument);
  EXPECT_THROW(Cutter(3.0, -0.1), std::invalid_argument);
  EXPECT_EQ(Cutter(3, 3).kind(), tmm::CutterKind::Ball);
  EXPECT_EQ(Cutter(3, 0).kind(), tmm::CutterKind::Flat);
  EXPECT_EQ(Cutter(5, 2).kind(), tmm::CutterKind::Bull);
}

// Generalized APT cutters: V-bits, chamfers, tapered ball and bull, cone-bottomed bull.
TEST(CutterApt, GeometryOfSpecialCases) {
  const double deg = M_PI / 180;
  // Plain APT parameters reproduce ball, flat and bull profiles.
  for (const auto& [R, r] : {std::pair{3.0, 3.0}, {3.0, 0.0}, {5.0, 2.0}}) {
    const Cutter simple(R, r), apt = Cutter::apt(R, r, 40, 0, 0);
    EXPECT_EQ(apt.kind(), simple.kind());
    for (double rho = 0; rho <= R; rho += R / 97) EXPECT_NEAR(apt.height(rho), simple.height(rho), 1e-12);
  }
  // Sharp 60-degree V-bit (cone 60 degrees from the horizontal up to R = 5 at L_C = 5 tan 60).
  const Cutter v = Cutter::apt(5, 0, 5 * std::tan(60 * deg), 60 * deg, 0);
  EXPECT_NEAR(v.height(2.0), 2.0 * std::tan(60 * deg), 1e-12);
  EXPECT_NEAR(v.max_radius(), 5.0, 1e-12);
  // Flat-tipped chamfer: tip radius 1, side at 45 degrees from the axis, R = 6 at L_C = 5.
  const Cutter ch = Cutter::apt(6, 0, 5, 0, 45 * deg);
  EXPECT_NEAR(ch.flat_radius(), 1.0, 1e-12);
  EXPECT_NEAR(ch.height(0.5), 0.0, 1e-12);
  EXPECT_NEAR(ch.height(3.5), 2.5, 1e-12);
  EXPECT_NEAR(ch.height(6.0), 5.0, 1e-12);
  // Tapered ball: tip radius 1.5, taper 5 degrees, R at L_C = 20.
  const double rt = 1.5, b2 = 5 * deg, L = 20;
  // The side is tangent to the ball: its distance from the ball centre (0, rt) equals rt.
  const double R = rt / std::cos(b2) + (L - rt) * std::tan(b2);
  const Cutter tb = Cutter::apt(R, rt, L, 0, b2);
  EXPECT_NEAR(tb.arc_centre_radius(), 0.0, 1e-9);
  EXPECT_NEAR(tb.arc_centre_height(), rt, 1e-9);
  EXPECT_NEAR(tb.height(tb.max_radius()), L, 1e-9);
  EXPECT_NEAR(tb.height(1.0), rt - std::sqrt(rt * rt - 1.0), 1e-9);
  // Continuity and monotone slope across the piece boundaries of a cone-bottomed tapered bull.
  const Cutter g = Cutter::apt(6, 1.5, 15, 10 * deg, 8 * deg);
  double last_h = -1, last_s = -1;
  for (double rho = 0; rho <= g.max_radius(); rho += g.max_radius() / 5000) {
    const double h = g.height(rho), sl = g.slope(rho);
    EXPECT_GE(h, last_h - 1e-12);
    EXPECT_GE(sl, last_s - 1e-9);
    if (last_h >= 0) {
      EXPECT_LT(h - last_h, 0.02);
    }
    last_h = h;
    last_s = sl;
  }
  EXPECT_NEAR(g.height(g.max_radius()), 15.0, 1e-9);
  // Impossible tools are refused with a clear message.
  EXPECT_THROW(Cutter::apt(3, 1, 10, -1 * deg, 0), std::invalid_argument);
  EXPECT_THROW(Cutter::apt(3, 1, 10, 0, 95 * deg), std::invalid_argument);
  EXPECT_THROW(Cutter::apt(1, 0, 10, 0, 30 * deg), std::invalid_argument);  // side crosses the axis
  EXPECT_THROW(Cutter::apt(3, 5, 10, 0, 0), std::invalid_argument);
}

// reach2 inverts the profile: h(rho) < lift exactly when rho^2 < reach2(lift).
TEST(Cutter, Reach2InvertsTheProfile) {
  const double deg = M_PI / 180;
  for (const Cutter& c : {Cutter(3, 3), Cutter(3, 0), Cutter(5, 2), Cutter::apt(4, 0, 4 * std::tan(60 * deg), 60 * deg, 0),
                          Cutter::apt(5, 0, 4, 0, 45 * deg), Cutter::apt(5, 1.2, 8, 10 * deg, 8 * deg),
                          Cutter::apt(3.5, 1.0, 6, 0, -5 * deg)}) {
    for (int i = 0; i <= 400; ++i) {
      const double rho = c.max_radius() * i / 400.0;
      const double h = c.height(rho);
      for (const double lift : {h + 1e-6, h + 0.3, h - 1e-6}) {
        const bool below = h < lift;
        const double r2 = c.reach2(lift);
        if (std::fabs(rho * rho - r2) > 1e-9 * (1 + r2)) {
          EXPECT_EQ(rho * rho < r2, below) << rho << " " << lift;
        }
      }
    }
    EXPECT_LT(c.reach2(0.0), 0.0);
    EXPECT_EQ(c.reach2(c.height(c.max_radius()) + 1), INFINITY);
  }
}

}  // namespace
