// The signed clearance of the face from a placed tool (gouge_check.hpp): what the moves between multipoint
// positions are checked by, for gouges (negative) and for the gap a move leaves (positive; issue 11 item
// 3). Checked against an independent reference: the face sampled by an explicit Bernstein sum every
// 0.05 mm under the tool and along its edges, against the torus' own formula, the lowest sample polished on
// a 0.0025 mm grid around it.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <random>
#include <string>

#include "support/seed_patches.hpp"
#include "tmm/position/multipoint.hpp"

namespace {

using Eigen::Vector3d;
using tmm::ContactStatus;
using tmm::MultipointOptions;
using tmm::MultipointPositioner;
using tmm::TorusTool;

constexpr double kRo = 6.7, kRi = 6.0, kSize = 150.0;

double reference_clearance(const tmm::BezierPatch& b, const Vector3d& tip, const Vector3d& axis) {
  const Vector3d c = tip + kRi * axis;
  const double R = kRo + kRi + 0.5;
  auto d = [&](double x, double y) {
    x = std::clamp(x, 0.0, kSize), y = std::clamp(y, 0.0, kSize);
    return tmm_test::round_insert_distance(kRo, kRi, tip, axis, tmm_test::bernstein_point(b, x / kSize, y / kSize));
  };
  const double x0 = std::max(0.0, c.x() - R), x1 = std::min(kSize, c.x() + R);
  const double y0 = std::max(0.0, c.y() - R), y1 = std::min(kSize, c.y() + R);
  double best = INFINITY, bx = 0, by = 0;
  auto take = [&](double x, double y) {
    const double v = d(x, y);
    if (v < best) best = v, bx = x, by = y;
  };
  for (double x = x0; x <= x1 + 1e-9; x += 0.05)
    for (double y = y0; y <= y1 + 1e-9; y += 0.05) take(x, y);
  for (double t = 0; t <= 1.0 + 1e-12; t += 0.05 / (2 * R)) {  // the face's edges, where they pass under
    const double x = x0 + t * (x1 - x0), y = y0 + t * (y1 - y0);
    take(x, y0), take(x, y1), take(x0, y), take(x1, y);
  }
  const double cx = bx, cy = by;
  for (int i = -20; i <= 20; ++i)
    for (int j = -20; j <= 20; ++j) take(cx + 0.0025 * i, cy + 0.0025 * j);
  return best;
}

TEST(Clearance, AgreesWithADenseReferenceForGapsAndGougesOnTheSeedPatches) {
  std::mt19937 rng(20261201);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  int gaps = 0, gouges = 0, cases = 0;
  double worst = 0;
  for (const char* kind : {"convex", "concave", "saddle"}) {
    const auto s = tmm_test::seed_patch(kind);
    const MultipointPositioner mp(s, TorusTool{kRo, kRi, tmm::ToolShape::RoundInsert}, MultipointOptions{});
    for (const double fx : {2.0, 40.0, 75.0, 148.0})
      for (const double fy : {1.0, 60.0, 149.0}) {
        const auto r = mp.position(fx, fy);
        if (r.status == ContactStatus::Failed) continue;
        for (int variant = 0; variant < 4; ++variant) {
          // the position itself, lifted along its axis, and tilted by up to 2 deg about a random direction
          Vector3d tip = r.tip, axis = r.axis;
          if (variant == 1) tip += 0.15 * unit(rng) * axis;
          if (variant >= 2) {
            const double phi = 2 * M_PI * unit(rng), t = (variant == 2 ? 0.5 : 2.0) * M_PI / 180.0;
            const Vector3d k = Vector3d(std::cos(phi), std::sin(phi), 0.0).cross(axis).normalized();
            axis = (axis * std::cos(t) + k.cross(axis) * std::sin(t)).normalized();
          }
          SCOPED_TRACE(testing::Message() << kind << " (" << fx << ", " << fy << ") variant " << variant);
          const double truth = reference_clearance(s->patch(0, 0), tip, axis);
          if (!(truth < kRi)) continue;  // beyond Ri only the sampled distance is promised
          const double found = mp.clearance_real(tip, axis, nullptr, nullptr);
          EXPECT_NEAR(found, truth, 2e-4);
          worst = std::max(worst, std::abs(found - truth));
          ++cases;
          gaps += truth > 1e-3;
          gouges += truth < -1e-3;
        }
      }
  }
  RecordProperty("worst_difference_um", std::to_string(worst * 1e3));  // 2.5 um when written
  EXPECT_GT(cases, 100);
  EXPECT_GT(gaps, 10);
  EXPECT_GT(gouges, 10);
}

TEST(Clearance, PenetrationIsTheNegativePart) {
  const auto s = tmm_test::seed_patch("saddle");
  const MultipointPositioner mp(s, TorusTool{kRo, kRi, tmm::ToolShape::RoundInsert}, MultipointOptions{});
  const auto r = mp.position(75.0, 75.0);
  ASSERT_NE(r.status, ContactStatus::Failed);
  for (const double lift : {-0.05, 0.0, 0.05}) {
    const Vector3d tip = r.tip + lift * r.axis;
    const double c = mp.clearance_real(tip, r.axis, nullptr, nullptr);
    EXPECT_NEAR(std::max(0.0, -c), mp.penetration_real(tip, r.axis, nullptr, nullptr), 1e-12);
    EXPECT_NEAR(c, lift, 1e-3);  // near a contact, lifting along the axis opens the gap by about the lift
  }
  EXPECT_TRUE(std::isinf(mp.clearance_real(Vector3d(500, 500, 90), Vector3d::UnitZ(), nullptr, nullptr)));
}

}  // namespace
