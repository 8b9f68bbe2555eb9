// The tilted tool alone: tilting about the pseudo-insert axis keeps the first contact on the tool, and
// VCRF's circular ray agrees with turning the point step by step.
#include <gtest/gtest.h>

#include <Eigen/Geometry>

#include <cmath>

#include "tmm/position/pose.hpp"
#include "tmm/position/tilt_guess.hpp"

namespace {

using Eigen::Vector3d;

TEST(Pose, TiltingAboutThePseudoInsertKeepsTheContact) {
  for (const auto shape : {tmm::ToolShape::RoundInsert, tmm::ToolShape::BullNose}) {
    tmm::TorusTool tool{6.7, 6.0, shape};
    const Vector3d tip0(1, 2, 3), e = Vector3d(0.6, 0.8, 0);
    const tmm::PseudoInsert f(tip0, e, tool);
    EXPECT_NEAR((f.O1 - (tip0 + Vector3d(0, 0, 6.0) + 6.7 * e)).norm(), 0.0, 1e-15);
    // A point on the pseudo-insert, 1 rad outwards from its bottom: on the outer torus for tilts below 1 rad
    // (the tool turns so that P moves towards the bottom of the insert).
    const Vector3d P = f.O1 + 6.0 * (e * std::sin(1.0) - Vector3d::UnitZ() * std::cos(1.0));
    for (double beta : {0.0, 0.1, 0.4, 0.78}) {
      const tmm::ToolPose pose = f.tilted(beta);
      EXPECT_NEAR(pose.axis.norm(), 1.0, 1e-15);
      EXPECT_NEAR(std::acos(pose.axis.z()), beta, 1e-12);
      EXPECT_NEAR(tmm::tool_distance(tool, pose.tip, pose.axis, P), 0.0, 1e-12) << beta;
      // The axis leans away from P.
      if (beta > 0) {
        EXPECT_LT(pose.axis.dot(e), 0.0);
      }
    }
  }
}

TEST(Pose, CircularRayIsWhereTheTurningPointEnters) {
  // Brute force: turn the point about u1 through O1 in small steps until the tool distance turns negative.
  const tmm::TorusTool tool{6.7, 6.0, tmm::ToolShape::RoundInsert};
  const tmm::PseudoInsert f(Vector3d(0, 0, 0), Vector3d::UnitX(), tool);
  const tmm::ToolPose vertical{Vector3d(0, 0, 0), Vector3d::UnitZ()};
  int checked = 0;
  for (int i = 0; i < 40; ++i) {
    const Vector3d p(-14.0 + 0.7 * i, 0.37 * (i % 7) - 1.0, -2.0 + 0.1 * (i % 5));
    if (tmm::tool_distance(tool, vertical.tip, vertical.axis, p) <= 0.0) continue;
    const Vector3d l = f.local(p);
    const double angle = tmm::pseudo_to_angle(tmm::circular_ray(tool, l.x(), l.y(), l.z()));
    // The surface point turns by +beta about u1 (as the tool turns by -beta).
    double first = INFINITY;
    for (int k = 1; k <= 200000; ++k) {
      const double b = 2.0 * M_PI * k / 200000;
      const Vector3d q = f.O1 + Eigen::AngleAxisd(b, f.u1) * (p - f.O1);
      if (tmm::tool_distance(tool, vertical.tip, vertical.axis, q) < 0.0) {
        first = b;
        break;
      }
    }
    if (std::isfinite(first)) {
      EXPECT_NEAR(angle, first, 2.0 * M_PI / 200000 * 1.5) << i;
      ++checked;
    } else {
      EXPECT_FALSE(std::isfinite(angle)) << i;
    }
  }
  EXPECT_GT(checked, 10);
}

}  // namespace
