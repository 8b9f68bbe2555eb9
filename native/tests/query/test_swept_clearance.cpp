// The clearance certificate of the drop along a direction (swept_clearance.hpp), against the exact first contact
// of the general method (facet, vertices, edges with no cap, itself checked against a brute force in
// test_drop_direction.cpp):
//  - it never clears a triangle that the solid touches before the cap (cap a hair past the contact, or far
//    past it), for every cutter shape and random axes, motions and triangles;
//  - it is not vacuous: with the cap well before the contact (or a triangle never touched) it clears nearly all;
//  - a triangle touched exactly at the cap is not cleared (the plane must clear it by 1e-9 mm);
//  - an endless cutter or an unbounded sweep is never cleared;
//  - the plane a clear answer gives proves the same case again on its own (plane_clears), and proves nothing
//    once the triangle is touched before the cap.
#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <cmath>
#include <limits>
#include <random>
#include <vector>

#include "tmm/query/drop_direction.hpp"
#include "tmm/query/swept_clearance.hpp"

namespace {

using Eigen::Vector3d;
using tmm::Cutter;
using tmm::direction_detail::plane_clears;
using tmm::direction_detail::support;
using tmm::direction_detail::triangle_clear;
using tmm::direction_detail::triangle_travel;

constexpr double kDeg = M_PI / 180.0;
constexpr double kInf = std::numeric_limits<double>::infinity();

std::vector<Cutter> solids() {
  return {
      Cutter::apt(3, 3, 9, 0, 0),                                 // ball
      Cutter::apt(3, 0, 7, 0, 0),                                 // flat
      Cutter::apt(5, 2, 8, 0, 0),                                 // bull
      Cutter::apt(4, 0, 4 * std::tan(60 * kDeg), 60 * kDeg, 0),  // V-bit
      Cutter::apt(5, 1.2, 8, 10 * kDeg, 8 * kDeg),                // cone-bottom tapered bull
      Cutter::apt(3.5, 1.0, 6, 0, -5 * kDeg),                     // inward taper
      Cutter::apt(27, 2, 62, 0, 0),                               // a holder grown by its clearance
      Cutter::apt(27, 2, 2, 0, 0),                                // its rim's disc
  };
}

Vector3d random_unit(std::mt19937_64& rng) {
  std::normal_distribution<double> g;
  return Vector3d(g(rng), g(rng), g(rng)).normalized();
}

// The lower bound of a triangle's travel that the mesh query gives the certificate.
double travel_bound(const Cutter& c, const Vector3d& q0, const Vector3d& q1, const Vector3d& q2, const Vector3d& W) {
  const double t0 = std::min({q0.dot(W), q1.dot(W), q2.dot(W)}) - support(c, W).value;
  return t0 - 1e-9 * (1 + std::fabs(t0));
}

TEST(SweptClearance, NeverClearsATriangleTouchedBeforeTheCap) {
  std::mt19937_64 rng(41);
  std::uniform_real_distribution<double> pos(-1.0, 1.0), size(0.05, 1.0);
  int touched = 0, cleared_early = 0, early = 0, cleared_never = 0, never = 0;
  for (const Cutter& c : solids()) {
    const double reach = c.max_radius() + c.cutting_length();
    for (int k = 0; k < 3000; ++k) {
      const Vector3d W = random_unit(rng);
      // A triangle about a point near the solid, of any size and orientation, ahead of it along W.
      const Vector3d centre = Vector3d(reach * pos(rng), reach * pos(rng), c.cutting_length() * (0.5 + pos(rng))) +
                              reach * (1 + pos(rng)) * W;
      const double s = size(rng) * (k % 4 == 0 ? reach : 3.0);
      const Vector3d q0 = centre + s * random_unit(rng), q1 = centre + s * random_unit(rng),
                     q2 = centre + s * random_unit(rng);
      const double t = triangle_travel(c, q0, q1, q2, W);
      const double t0 = travel_bound(c, q0, q1, q2, W);
      if (t < kInf) {
        ++touched;
        ASSERT_GE(t, t0) << k;
        // Touched before the cap: never cleared.
        for (const double past : {1e-7, 1e-3, 1.0, 100.0})
          ASSERT_FALSE(triangle_clear(c, q0, q1, q2, W, t0, t + past)) << k << " " << past;
        // Touched exactly at the cap: not cleared either.
        ASSERT_FALSE(triangle_clear(c, q0, q1, q2, W, t0, t)) << k;
        // Well before the contact: cleared (a few searches may give up; the caller then solves the triangle).
        if (t - 0.01 > t0) {
          ++early;
          cleared_early += triangle_clear(c, q0, q1, q2, W, t0, t - 0.01);
        }
      } else {
        ++never;
        cleared_never += triangle_clear(c, q0, q1, q2, W, t0, t0 + 2 * reach);
      }
    }
  }
  EXPECT_GT(touched, 3000);
  EXPECT_GT(early, 2000);
  EXPECT_GT(never, 3000);
  EXPECT_GT(cleared_early, 0.95 * early);
  EXPECT_GT(cleared_never, 0.99 * never);
}

TEST(SweptClearance, AMissedTriangleIsClearedAndATouchedOneIsNot) {
  // A flat D6 (cutting length 7) moving along +x in its own frame, a triangle in the plane x = 10 about the
  // axis: the side touches it at travel 10 - 3 = 7.
  const Cutter flat = Cutter::apt(3, 0, 7, 0, 0);
  const Vector3d W = Vector3d::UnitX();
  const Vector3d q0(10, -5, 1), q1(10, 5, 1), q2(10, 0, 6);
  ASSERT_NEAR(triangle_travel(flat, q0, q1, q2, W), 7.0, 1e-9);
  const double t0 = 5.0;  // any lower bound of the travel will do
  EXPECT_TRUE(triangle_clear(flat, q0, q1, q2, W, t0, 6.99));
  EXPECT_FALSE(triangle_clear(flat, q0, q1, q2, W, t0, 7.0));
  EXPECT_FALSE(triangle_clear(flat, q0, q1, q2, W, t0, 7.01));
  // The same triangle lifted above the cutting length is passed by: cleared for any cap.
  const Vector3d up(0, 0, 8);
  EXPECT_TRUE(triangle_clear(flat, q0 + up, q1 + up, q2 + up, W, t0, 1e6));
  // An endless cutter, or no finite cap: nothing is proven.
  EXPECT_FALSE(triangle_clear(Cutter(3, 0), q0, q1, q2, W, t0, 6.0));
  EXPECT_FALSE(triangle_clear(flat, q0, q1, q2, W, t0, kInf));
  EXPECT_FALSE(triangle_clear(flat, q0, q1, q2, W, -kInf, 6.0));
}

TEST(SweptClearance, TheSeparatingPlaneProvesTheCaseAgain) {
  const Cutter flat = Cutter::apt(3, 0, 7, 0, 0);
  const Vector3d W = Vector3d::UnitX();
  const Vector3d q0(10, -5, 1), q1(10, 5, 1), q2(10, 0, 6);  // touched at travel 7 (as above)
  const double t0 = 5.0;
  Vector3d v = Vector3d::Zero();
  ASSERT_TRUE(triangle_clear(flat, q0, q1, q2, W, t0, 6.5, &v));
  ASSERT_GT(v.norm(), 0.0);
  EXPECT_TRUE(plane_clears(flat, q0, q1, q2, W, t0, 6.5, v));
  // A nearby start (the triangle 0.2 mm further, 0.1 mm aside) with the same plane.
  const Vector3d d(0.2, 0.1, 0.0);
  EXPECT_TRUE(plane_clears(flat, q0 + d, q1 + d, q2 + d, W, t0, 6.5, v));
  // Touched before the cap, or no plane: nothing is proven.
  EXPECT_FALSE(plane_clears(flat, q0, q1, q2, W, t0, 7.01, v));
  EXPECT_FALSE(plane_clears(flat, q0, q1, q2, W, t0, 7.0, v));
  EXPECT_FALSE(plane_clears(flat, q0, q1, q2, W, t0, 6.5, Vector3d::Zero()));
  // The search starts from a given plane, a good one or a poor one: the same answers.
  for (const Vector3d& from : {v, Vector3d(-W), Vector3d(0.3, -2.0, 0.7)}) {
    Vector3d u = from;
    EXPECT_TRUE(triangle_clear(flat, q0, q1, q2, W, t0, 6.5, &u));
    EXPECT_TRUE(plane_clears(flat, q0, q1, q2, W, t0, 6.5, u));
    u = from;
    EXPECT_FALSE(triangle_clear(flat, q0, q1, q2, W, t0, 7.0, &u));
    EXPECT_EQ(u, from);  // unchanged when nothing is proven
  }
  EXPECT_FALSE(plane_clears(flat, q0, q1, q2, W, t0, kInf, v));
}

}  // namespace
