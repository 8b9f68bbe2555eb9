// Checks that a long kernel phase reports progress and honours cancel, without timing anything.
#pragma once

#include <gtest/gtest.h>

#include <algorithm>
#include <functional>
#include <vector>

#include "tmm/util/parallel.hpp"

namespace tmm_test {

using ProgressFn = std::function<bool(double)>;

// Runs phase(progress) with a callback that always goes on, and again with one that cancels at its first
// report: the first reports more than once, never backwards, within [0, 1] and ends at 1; the second
// throws tmm::Cancelled after that one report. Returns the first run's result (to compare with a run
// without a callback: going on must not change it).
template <class Phase>
auto run_reported(Phase&& phase) {
  std::vector<double> seen;
  auto result = phase([&seen](double f) {
    seen.push_back(f);
    return true;
  });
  EXPECT_GE(seen.size(), 2u);
  EXPECT_TRUE(std::is_sorted(seen.begin(), seen.end()));
  if (!seen.empty()) {
    EXPECT_GE(seen.front(), 0.0);
    EXPECT_EQ(seen.back(), 1.0);
  }
  int calls = 0;
  EXPECT_THROW(phase([&calls](double) {
                 ++calls;
                 return false;
               }),
               tmm::Cancelled);
  EXPECT_EQ(calls, 1);
  return result;
}

}  // namespace tmm_test
