// The lean profile's refinement stops where no double lies between two drops: two triangles meeting between
// adjacent doubles (possible at any scale once min_step is below the spacing of doubles there) used to make
// the recursive bisection split the same interval forever and overflow the stack.
#include <gtest/gtest.h>

#include <cmath>
#include <vector>

#include "tmm/query/drop_cutter.hpp"
#include "tmm/algo/lean_profile.hpp"

namespace {

TEST(LeanRefine, StopsBetweenAdjacentDoubles) {
  const double X = 1e8, D = 10.0;  // the crease at X: flat on the left, rising on the right
  tmm::Vertices V(6, 3);
  V << X - D, 0, 0, X, 0, 0, X, 10, 0, X - D, 10, 0, X + D, 0, 5, X + D, 10, 5;
  tmm::Triangles F(4, 3);
  F << 0, 1, 2, 0, 2, 3, 1, 4, 5, 1, 5, 2;
  const tmm::MeshIndex index(V, F);
  const tmm::Cutter flat(1.0, 0.0);
  tmm::LeanRuns runs;
  runs.offsets = {0, 2};
  runs.origin = {0.0, 5.0};
  runs.dir = {1.0, 0.0};
  // Two samples a few doubles apart around the crease's contact change (the flat end's rim at X - 1).
  const double at = X - 1.0, ulp = std::nextafter(at, 2 * at) - at;
  runs.s = {at - 4 * ulp, at + 4 * ulp};
  for (double s : runs.s) runs.z.push_back(tmm::drop_point(index, flat, s, 5.0, -10.0));
  runs.flags = {tmm::kLeanFixed, tmm::kLeanFixed};
  tmm::LeanOptions o;
  o.min_step = 1e-12;  // far below the 1.5e-8 mm between doubles at 1e8 mm
  o.max_step = 1.0;
  o.drop.drop_floor = -10.0;
  const tmm::LeanResult r = tmm::lean_profiles(index, flat, runs, o);
  ASSERT_EQ(r.offsets.size(), 2u);
  EXPECT_GE(r.s.size(), 2u);
  EXPECT_LE(r.drops, 200u);  // a handful of bisections, each of a different interval
  EXPECT_EQ(r.s.front(), runs.s[0]);
  EXPECT_EQ(r.s.back(), runs.s[1]);
}

}  // namespace
