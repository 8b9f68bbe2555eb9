// Bisection and Illinois regula falsi alone, against known boundaries.
#include <gtest/gtest.h>

#include <cmath>

#include "tmm/util/bracket_1d.hpp"

namespace {

TEST(Bracket1d, BisectionHalvesTowardsTheBoundary) {
  int calls = 0;
  const tmm::Bracket b = tmm::bisect(0.0, 2.0, 40, [&](double t) {
    ++calls;
    return t * t <= 2.0;
  });
  EXPECT_EQ(calls, 40);
  EXPECT_LE(b.good * b.good, 2.0);
  EXPECT_GT(b.bad * b.bad, 2.0);
  EXPECT_NEAR(b.good, std::sqrt(2.0), 2.0 / (1ull << 40) * 1.01);
  EXPECT_NEAR(b.bad - b.good, 2.0 / (1ull << 40), 1e-20);
}

TEST(Bracket1d, BisectionWithEverythingGoodEndsAtTheEnd) {
  const tmm::Bracket b = tmm::bisect(0.0, 1.0, 10, [](double) { return true; });
  EXPECT_EQ(b.bad, 1.0);
  EXPECT_NEAR(b.good, 1.0 - 1.0 / 1024, 1e-15);
}

TEST(Bracket1d, IllinoisFindsTheSignChange) {
  // f(t) = cos(t) - t: good (>= 0) below the root 0.739085133215161.
  auto f = [](double t) { return std::cos(t) - t; };
  const tmm::Bracket b = tmm::illinois(0.0, 1.0, f(0.0), f(1.0), 60, 1e-13, f);
  EXPECT_GE(f(b.good), 0.0);
  EXPECT_LT(f(b.bad), 0.0);
  EXPECT_NEAR(b.good, 0.739085133215161, 1e-12);
}

TEST(Bracket1d, IllinoisIsFastWhereRegulaFalsiStalls) {
  // A convex f: plain regula falsi keeps one end fixed and converges linearly; Illinois halves it.
  int calls = 0;
  auto f = [&](double t) {
    ++calls;
    return 1.0 - std::exp(8.0 * t) / std::exp(4.0);  // root at t = 0.5
  };
  const tmm::Bracket b = tmm::illinois(0.0, 1.0, f(0.0), f(1.0), 100, 1e-12, f);
  EXPECT_NEAR(b.good, 0.5, 1e-12);
  EXPECT_LE(calls, 2 + 40);  // plain regula falsi needs hundreds here
}

TEST(Bracket1d, IllinoisStopsAtTheIterationCap) {
  int calls = 0;
  auto f = [&](double t) {
    ++calls;
    return 0.3 - t;
  };
  tmm::illinois(0.0, 1.0, 0.3, -0.7, 3, 0.0, f);
  EXPECT_EQ(calls, 3);
}

}  // namespace
