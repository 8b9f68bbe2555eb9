// Multipoint positioning (seed 001) on the seed's convex and concave bicubic patches, checked independently
// of the positioning code:
//  - P and Q on the surface (explicit Bernstein sum at their parameters) and on the tool (distance to the
//    torus, written out here from the torus' definition),
//  - no penetration: dense sampling (0.05 mm) of the surface under the tool, distance to the tool solid,
//  - VCRF and DRD agree; the exact tilt keeps both contacts, the seed's global-X rotation does not.
#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <atomic>
#include <cmath>
#include <memory>

#include "tmm/position/multipoint.hpp"

namespace {

using Eigen::Vector3d;
using tmm::ContactStatus;
using tmm::MultipointOptions;
using tmm::MultipointPositioner;
using tmm::MultipointResult;
using tmm::TorusTool;

constexpr double kRo = 6.7, kRi = 6.0;

std::shared_ptr<tmm::PatchSurface> seed_surface(bool convex) {
  const double cz[16] = {80, 90, 90, 80, 90, 105, 105, 90, 90, 105, 105, 90, 80, 90, 90, 80};
  const double vz[16] = {80, 70, 70, 80, 70, 55, 55, 70, 70, 55, 55, 70, 80, 70, 70, 80};
  std::vector<Vector3d> net;
  for (int i = 0; i < 4; ++i)
    for (int j = 0; j < 4; ++j) net.emplace_back(50.0 * i, 50.0 * j, (convex ? cz : vz)[i * 4 + j]);
  return std::make_shared<tmm::PatchSurface>(tmm::BezierPatch(3, 3, net));
}

// Explicit bicubic Bernstein sum (independent of BezierPatch's evaluation).
Vector3d bicubic(const tmm::BezierPatch& b, double u, double v) {
  const double bu[4] = {std::pow(1 - u, 3), 3 * u * (1 - u) * (1 - u), 3 * u * u * (1 - u), u * u * u};
  const double bv[4] = {std::pow(1 - v, 3), 3 * v * (1 - v) * (1 - v), 3 * v * v * (1 - v), v * v * v};
  Vector3d s = Vector3d::Zero();
  for (int i = 0; i < 4; ++i)
    for (int j = 0; j < 4; ++j) s += bu[i] * bv[j] * b.pole(i, j);
  return s;
}

// Signed distance to the round-insert tool: the torus (distance to the major circle minus Ri), and the body
// above the centre plane out to Ro + Ri (the torus' definition, written independently of tool_distance).
double torus_distance(const Vector3d& tip, const Vector3d& axis, const Vector3d& x) {
  const Vector3d c = tip + kRi * axis;
  const Vector3d d = x - c;
  const double h = d.dot(axis);
  const double rho = (d - h * axis).norm();
  const double torus = std::sqrt((rho - kRo) * (rho - kRo) + h * h) - kRi;
  if (h >= 0 && rho <= kRo + kRi) return std::min(torus, -std::min(h, kRo + kRi - rho));
  return torus;
}

// Deepest penetration of the surface into the tool by dense sampling of the surface under the tool
// (x = 150 u, y = 150 v on these patches).
double sampled_penetration(const tmm::BezierPatch& b, const MultipointResult& r, double step) {
  const Vector3d c = r.centre;
  const double R = kRo + kRi + 1.0;
  double worst = 0.0;
  for (double x = std::max(0.0, c.x() - R); x <= std::min(150.0, c.x() + R); x += step)
    for (double y = std::max(0.0, c.y() - R); y <= std::min(150.0, c.y() + R); y += step) {
      const Vector3d p = bicubic(b, x / 150.0, y / 150.0);
      worst = std::max(worst, -torus_distance(r.tip, r.axis, p));
    }
  return worst;
}

std::vector<double> footprint() {
  std::vector<double> xy;
  for (double x = 20; x <= 130; x += 22)
    for (double y = 15; y <= 135; y += 30) {
      xy.push_back(x);
      xy.push_back(y);
    }
  return xy;
}

void check_positions(bool convex, tmm::MultipointMethod method, double* max_seed_angle = nullptr) {
  const auto surface = seed_surface(convex);
  MultipointOptions o;
  o.method = method;
  const MultipointPositioner mp(surface, TorusTool{kRo, kRi, tmm::ToolShape::RoundInsert}, o);
  const auto xy = footprint();
  const std::size_t n = xy.size() / 2;
  std::vector<MultipointResult> res(n);
  mp.position_batch(xy.data(), n, res.data(), tmm::BatchOptions{});
  int two = 0;
  for (std::size_t i = 0; i < n; ++i) {
    const auto& r = res[i];
    SCOPED_TRACE(testing::Message() << (convex ? "convex" : "concave") << " at " << xy[2 * i] << ", " << xy[2 * i + 1]
                                    << " status " << static_cast<int>(r.status) << " reason "
                                    << tmm::multipoint_reason_text()[static_cast<int>(r.reason)]);
    ASSERT_NE(r.status, ContactStatus::Failed);
    EXPECT_NEAR(r.axis.norm(), 1.0, 1e-12);
    EXPECT_LT((r.centre - (r.tip + kRi * r.axis)).norm(), 1e-9);
    const auto& patch = surface->patch(0, 0);
    EXPECT_LT((bicubic(patch, r.uvP.x(), r.uvP.y()) - r.P).norm(), 1e-9);
    EXPECT_LT(std::abs(torus_distance(r.tip, r.axis, r.P)), 1e-3);
    if (r.status == ContactStatus::TwoContacts) {
      ++two;
      EXPECT_LT((bicubic(patch, r.uvQ.x(), r.uvQ.y()) - r.Q).norm(), 1e-9);
      EXPECT_LT(std::abs(torus_distance(r.tip, r.axis, r.Q)), 1e-3);
      // Q is not P: apart (at (42, 45) on the concave patch Q lies 0.98 mm from P, parted from it by a
      // 25 um ridge of the tool distance: a contact of its own, which finer samples find too).
      EXPECT_GT((r.Q - r.P).norm(), 0.5);
      EXPECT_GT(r.beta, 0.0);
      EXPECT_LE(r.beta, o.beta_max);
      if (max_seed_angle) *max_seed_angle = std::max(*max_seed_angle, r.seed_axis_angle);
    }
    EXPECT_LT(sampled_penetration(patch, r, 0.05), 1e-3);
  }
  EXPECT_GE(two, static_cast<int>(n) * 3 / 4) << "two-contact positions";
}

TEST(Multipoint, VcrfConvexBothContactsTouchNothingPenetrates) {
  double angle = 0.0;
  check_positions(true, tmm::MultipointMethod::VCRF, &angle);
  std::printf("convex VCRF: largest angle between the exact axis and the seed's global-X axis %.3f deg\n",
              angle * 180 / M_PI);
}

TEST(Multipoint, VcrfConcaveBothContactsTouchNothingPenetrates) {
  double angle = 0.0;
  check_positions(false, tmm::MultipointMethod::VCRF, &angle);
  std::printf("concave VCRF: largest angle between the exact axis and the seed's global-X axis %.3f deg\n",
              angle * 180 / M_PI);
}

TEST(Multipoint, DrdConvexAndConcave) {
  check_positions(true, tmm::MultipointMethod::DRD);
  check_positions(false, tmm::MultipointMethod::DRD);
}

TEST(Multipoint, DrdAndVcrfFindTheSamePosition) {
  for (bool convex : {true, false}) {
    const auto surface = seed_surface(convex);
    MultipointOptions v, d;
    d.method = tmm::MultipointMethod::DRD;
    const TorusTool tool{kRo, kRi, tmm::ToolShape::RoundInsert};
    const MultipointPositioner a(surface, tool, v), b(surface, tool, d);
    for (auto [x, y] : {std::pair{40.0, 60.0}, {75.0, 75.0}, {110.0, 30.0}, {60.0, 120.0}}) {
      const auto ra = a.position(x, y), rb = b.position(x, y);
      ASSERT_EQ(ra.status, rb.status) << x << "," << y;
      EXPECT_NEAR(ra.drop_z, rb.drop_z, 1e-6);
      // Two contacts: the same solution. One contact (curvature limit): both stop within the bisection's
      // resolution of the osculating tilt.
      const double tol = ra.status == ContactStatus::TwoContacts ? 1e-7 : 1e-5;
      EXPECT_NEAR(ra.beta, rb.beta, tol) << x << "," << y;
      EXPECT_LT((ra.tip - rb.tip).norm(), 1e3 * tol);
    }
  }
}

TEST(Multipoint, SeedGlobalXRotationLosesTheContacts) {
  // Where P is not in the YZ plane of the axis, turning about global X is not the pseudo-insert rotation.
  const auto surface = seed_surface(false);
  MultipointOptions exact, seed;
  seed.rotation = tmm::TiltRotation::GlobalX;
  const TorusTool tool{kRo, kRi, tmm::ToolShape::RoundInsert};
  const MultipointPositioner a(surface, tool, exact), b(surface, tool, seed);
  double worst_gap = 0.0, worst_angle = 0.0;
  for (double x = 20; x <= 130; x += 10) {
    const auto ra = a.position(x, 40.0), rb = b.position(x, 40.0);
    if (ra.status != ContactStatus::TwoContacts) continue;
    EXPECT_NEAR(ra.beta, rb.beta, 1e-12);
    worst_angle = std::max(worst_angle, ra.seed_axis_angle);
    worst_gap = std::max({worst_gap, std::abs(rb.gap_Q), rb.penetration});
  }
  std::printf("seed global-X rotation (concave, y = 40): axis off by up to %.3f deg, contact off by %.3f mm\n",
              worst_angle * 180 / M_PI, worst_gap);
  EXPECT_GT(worst_angle, 1e-3);
}

// Surface extension: on the concave patch the rim x = 0 is the highest line of the section; a tool centred
// on it rests on the boundary curve (P and Q at u = 0) and leaves a wedge of material beside the rim. Against
// the face continued past the rim the tool lies on the continued bowl, leans into the patch and cuts the
// wedge down; it penetrates neither the extended nor the real face.
TEST(Multipoint, ExtensionRestsOnTheContinuedSurfaceNotOnTheRim) {
  const auto surface = seed_surface(false);
  const auto& patch = surface->patch(0, 0);
  const TorusTool tool{kRo, kRi, tmm::ToolShape::RoundInsert};
  MultipointOptions o;
  const MultipointPositioner plain(surface, tool, o);
  o.extend = kRo + kRi;
  const MultipointPositioner ext(surface, tool, o);
  EXPECT_LT(ext.surface().umin(), -0.08);
  EXPECT_EQ(ext.real_surface().umin(), 0.0);
  const Vector3d wedge = bicubic(patch, 6.44 / 150.0, 27.0 / 150.0);  // the uncut wedge at the section
  for (double x : {0.0, 150.0}) {
    SCOPED_TRACE(testing::Message() << "x = " << x);
    const MultipointResult a = plain.position(x, 28.0), b = ext.position(x, 28.0);
    ASSERT_EQ(a.status, ContactStatus::TwoContacts);
    ASSERT_EQ(b.status, ContactStatus::TwoContacts);
    EXPECT_NEAR(a.uvP.x(), x / 150.0, 1e-12);  // on the rim
    EXPECT_NEAR(a.uvQ.x(), x / 150.0, 1e-12);
    EXPECT_FALSE(a.P_extension || a.Q_extension);
    EXPECT_TRUE(b.P_extension && b.Q_extension);  // both on the continued bowl
    EXPECT_LT(std::abs(torus_distance(b.tip, b.axis, b.P)), 1e-3);
    EXPECT_LT(std::abs(torus_distance(b.tip, b.axis, b.Q)), 1e-3);
    EXPECT_GT(std::abs(b.axis.x()), 0.15);  // leans into the patch
    const Vector3d w = x == 0.0 ? wedge : bicubic(patch, 1.0 - 6.44 / 150.0, 27.0 / 150.0);
    EXPECT_GT(torus_distance(a.tip, a.axis, w), 1.4);  // the wedge left by the tool on the rim
    EXPECT_LT(torus_distance(b.tip, b.axis, w), 0.5);  // cut down by the tool on the extension
    EXPECT_LE(b.penetration_real, 1e-3);
    EXPECT_LT(sampled_penetration(patch, b, 0.05), 1e-3);  // the real patch, sampled independently
  }
  // Away from the edges the extension changes nothing.
  const MultipointResult a = plain.position(72.0, 60.0), b = ext.position(72.0, 60.0);
  EXPECT_LT((a.tip - b.tip).norm(), 1e-6);
  EXPECT_LT((a.axis - b.axis).norm(), 1e-6);
  EXPECT_FALSE(b.P_extension || b.Q_extension);
}

// Footprint anchor: with Axis the tilt about the pseudo-insert axis moves the tip off the footprint point
// (about 0.8 mm on the concave patch); with Tip the tilted tip lands on it, and the position is exactly the
// Axis position of the pre-tilt point it reports.
TEST(Multipoint, TipAnchorPutsTheTiltedTipOnTheFootprintPoint) {
  const auto surface = seed_surface(false);
  const TorusTool tool{kRo, kRi, tmm::ToolShape::RoundInsert};
  MultipointOptions o;
  const MultipointPositioner axis(surface, tool, o);
  o.anchor = tmm::FootprintAnchor::Tip;
  const MultipointPositioner tip(surface, tool, o);
  double moved = 0.0;
  for (double x : {18.0, 36.0, 90.0, 126.0}) {
    for (double y : {28.0, 60.0}) {
      SCOPED_TRACE(testing::Message() << "at " << x << ", " << y);
      const MultipointResult a = axis.position(x, y), t = tip.position(x, y);
      ASSERT_NE(a.status, ContactStatus::Failed);
      ASSERT_NE(t.status, ContactStatus::Failed);
      moved = std::max(moved, (a.tip.head<2>() - Eigen::Vector2d(x, y)).norm());
      EXPECT_EQ(a.axis_xy, Eigen::Vector2d(x, y));
      EXPECT_LT((t.tip.head<2>() - Eigen::Vector2d(x, y)).norm(), 1e-3);
      EXPECT_NEAR(t.anchor_error, (t.tip.head<2>() - Eigen::Vector2d(x, y)).norm(), 1e-12);
      const MultipointResult again = axis.position(t.axis_xy.x(), t.axis_xy.y());
      EXPECT_LT((again.tip - t.tip).norm(), 1e-9);
      EXPECT_LT((again.axis - t.axis).norm(), 1e-9);
      EXPECT_LT(sampled_penetration(surface->patch(0, 0), t, 0.05), 1e-3);
    }
  }
  EXPECT_GT(moved, 0.5);
}

TEST(Multipoint, BallIsOneContactFlatIsRefused) {
  const auto surface = seed_surface(true);
  const MultipointPositioner ball(surface, TorusTool{0.0, 5.0, tmm::ToolShape::RoundInsert}, MultipointOptions{});
  const auto r = ball.position(60.0, 70.0);
  EXPECT_EQ(r.status, ContactStatus::OneContact);
  EXPECT_EQ(r.reason, tmm::ContactReason::Ball);
  // Ball centre at exactly the radius from the surface.
  EXPECT_NEAR((r.centre - r.P).norm(), 5.0, 1e-6);
  EXPECT_THROW(MultipointPositioner(surface, TorusTool{6.0, 0.0, tmm::ToolShape::BullNose}, MultipointOptions{}),
               std::invalid_argument);
  EXPECT_THROW(MultipointPositioner(surface, TorusTool{-1.0, 2.0, tmm::ToolShape::BullNose}, MultipointOptions{}),
               std::invalid_argument);
}

TEST(Multipoint, BullNoseOnConvexIsOneContactWithoutGouge) {
  const auto surface = seed_surface(true);
  const MultipointPositioner mp(surface, TorusTool{kRo, kRi, tmm::ToolShape::BullNose}, MultipointOptions{});
  for (auto [x, y] : {std::pair{75.0, 75.0}, {40.0, 60.0}}) {
    const auto r = mp.position(x, y);
    EXPECT_NE(r.status, ContactStatus::Failed) << tmm::multipoint_reason_text()[static_cast<int>(r.reason)];
    EXPECT_LT(r.penetration, 1e-3);
  }
}

TEST(Multipoint, NoSurfaceUnderTheToolFails) {
  const MultipointPositioner mp(seed_surface(true), TorusTool{kRo, kRi}, MultipointOptions{});
  const auto r = mp.position(500.0, 500.0);
  EXPECT_EQ(r.status, ContactStatus::Failed);
  EXPECT_EQ(r.reason, tmm::ContactReason::NoSurface);
}

TEST(Multipoint, BatchThreadsMatchAndCancel) {
  const MultipointPositioner mp(seed_surface(false), TorusTool{kRo, kRi}, MultipointOptions{});
  const auto xy = footprint();
  const std::size_t n = xy.size() / 2;
  std::vector<MultipointResult> a(n), b(n);
  tmm::BatchOptions one, two;
  one.threads = 1;
  two.threads = 2;
  mp.position_batch(xy.data(), n, a.data(), one);
  mp.position_batch(xy.data(), n, b.data(), two);
  for (std::size_t i = 0; i < n; ++i) EXPECT_EQ(a[i].tip, b[i].tip);
  tmm::BatchOptions cancel;
  cancel.progress = [](double) { return false; };
  std::vector<double> many;
  for (int k = 0; k < 2000; ++k) {
    many.push_back(20 + (k % 100));
    many.push_back(20 + k / 20);
  }
  std::vector<MultipointResult> c(many.size() / 2);
  EXPECT_THROW(mp.position_batch(many.data(), c.size(), c.data(), cancel), tmm::Cancelled);
}

TEST(Multipoint, ToolDistanceGradientAndHessianMatchFiniteDifferences) {
  const Vector3d tip(1, 2, 3), axis = Vector3d(0.2, -0.1, 1).normalized();
  for (auto shape : {tmm::ToolShape::RoundInsert, tmm::ToolShape::BullNose}) {
    const TorusTool tool{kRo, kRi, shape};
    for (const Vector3d& x : {Vector3d(12, 2, 1), Vector3d(-8, 9, 0.5), Vector3d(3, -7, -2), Vector3d(1.2, 2.1, 3.5),
                              Vector3d(20, 3, 9), Vector3d(4, 4, 20)}) {
      Vector3d g;
      Eigen::Matrix3d H;
      const double full = tmm::tool_distance(tool, tip, axis, x, &g, &H);
      EXPECT_NEAR(full, tmm::tool_distance(tool, tip, axis, x), 1e-12);  // value-only path agrees
      const double h = 1e-5;
      for (int k = 0; k < 3; ++k) {
        const Vector3d dx = h * Vector3d::Unit(k);
        Vector3d g1, g0;
        const double f1 = tmm::tool_distance(tool, tip, axis, x + dx, &g1);
        const double f0 = tmm::tool_distance(tool, tip, axis, x - dx, &g0);
        EXPECT_NEAR(g[k], (f1 - f0) / (2 * h), 1e-6);
        EXPECT_LT((H.col(k) - (g1 - g0) / (2 * h)).norm(), 1e-5);
      }
    }
  }
}

}  // namespace
