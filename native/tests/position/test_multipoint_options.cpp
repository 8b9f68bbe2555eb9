// Options the positioner refuses, each with a message naming the option, and the sample spacing it cannot
// honour (a tiny spacing once overflowed an int cast: undefined behaviour, then a footprint that mostly
// failed without a word).
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <memory>
#include <stdexcept>
#include <string>
#include <vector>

#include "tmm/position/multipoint.hpp"

namespace {

using Eigen::Vector3d;

std::shared_ptr<tmm::PatchSurface> seed_convex() {
  const double cz[16] = {80, 90, 90, 80, 90, 105, 105, 90, 90, 105, 105, 90, 80, 90, 90, 80};
  std::vector<Vector3d> net;
  for (int i = 0; i < 4; ++i)
    for (int j = 0; j < 4; ++j) net.emplace_back(50.0 * i, 50.0 * j, cz[i * 4 + j]);
  return std::make_shared<tmm::PatchSurface>(tmm::BezierPatch(3, 3, net));
}

const tmm::TorusTool kTool{6.7, 6.0, tmm::ToolShape::RoundInsert};

// The message of the std::invalid_argument the positioner throws ("" and a failure when none).
std::string refusal(const tmm::MultipointOptions& o, const tmm::TorusTool& tool = kTool) {
  try {
    tmm::MultipointPositioner mp(seed_convex(), tool, o);
  } catch (const std::invalid_argument& e) {
    return e.what();
  }
  ADD_FAILURE() << "accepted";
  return "";
}

#define EXPECT_CONTAINS(text, part) EXPECT_NE(std::string(text).find(part), std::string::npos) << (text)

TEST(MultipointOptions, NonFiniteOptionsAreRefusedByName) {
  const double nan = std::numeric_limits<double>::quiet_NaN(), inf = std::numeric_limits<double>::infinity();
  for (const double bad : {nan, inf, -inf}) {
    tmm::MultipointOptions o;
    o.beta_max = bad;
    EXPECT_CONTAINS(refusal(o), "beta_max must be");
    o = {};
    o.tol = bad;
    EXPECT_CONTAINS(refusal(o), "tol must be");
    o = {};
    o.sample_spacing = bad;
    EXPECT_CONTAINS(refusal(o), "sample_spacing must be");
    o = {};
    o.extend = bad;
    EXPECT_CONTAINS(refusal(o), "extend must be");
    tmm::TorusTool t = kTool;
    t.Ro = bad;
    EXPECT_CONTAINS(refusal({}, t), "Ro must be");
    t = kTool;
    t.Ri = bad;
    EXPECT_CONTAINS(refusal({}, t), "Ri must be");
  }
  tmm::MultipointOptions o;
  o.tol = std::numeric_limits<double>::quiet_NaN();
  EXPECT_CONTAINS(refusal(o), "got nan");
  o = {};
  o.sample_spacing = -1.0;  // once silently taken as "auto"
  EXPECT_CONTAINS(refusal(o), "sample_spacing must be 0 (auto");
  o = {};
  o.divisions = 1 << 30;  // the zoom grid's (d + 1)^2 loop counters would overflow
  EXPECT_CONTAINS(refusal(o), "divisions must be a whole number in [1, 1000], got 1073741824");
}

TEST(MultipointOptions, ASampleSpacingTooFineForTheFaceIsRefusedWithTheFinestItCanTake) {
  for (const double tiny : {1e-300, 1e-9, 1e-3}) {
    tmm::MultipointOptions o;
    o.sample_spacing = tiny;
    const std::string msg = refusal(o);
    EXPECT_CONTAINS(msg, "sample_spacing");
    EXPECT_CONTAINS(msg, "is finer than this face can be sampled at");
    EXPECT_CONTAINS(msg, "must be 0 (auto: (Ro + Ri) / 8 = 1.5875 mm) or >= ");
  }
  // The finest spacing it names is honoured exactly (no widening, no capped side).
  const auto s = seed_convex();
  const double finest = tmm::SurfaceSamples::finest_spacing(*s, 1e-300);
  bool capped = true;
  EXPECT_EQ(tmm::SurfaceSamples::planned_spacing(*s, finest, &capped), finest);
  EXPECT_FALSE(capped);
  EXPECT_LT(finest, 0.2);  // ~0.1 mm on this 150 mm face: 4 million samples
  // A fine spacing the face can take is kept as asked.
  tmm::MultipointOptions o;
  o.sample_spacing = 0.5;
  const tmm::MultipointPositioner mp(s, kTool, o);
  EXPECT_EQ(mp.samples().spacing(), 0.5);
}

TEST(MultipointOptions, SamplesNearANonFinitePointAreNone) {
  // The bucket range is clamped before the int conversion: NaN and huge coordinates visit nothing.
  const auto s = seed_convex();
  const tmm::SurfaceSamples samples(*s, 2.0, 5.0);
  int visited = 0;
  for (const double x : {std::numeric_limits<double>::quiet_NaN(), 1e300, -1e300})
    samples.within(x, 75.0, 10.0, [&](std::size_t) { ++visited; });
  samples.within(75.0, 75.0, 1e300, [&](std::size_t) { ++visited; });  // everything, no overflow
  EXPECT_EQ(visited, static_cast<int>(samples.points().size()));
}

}  // namespace
