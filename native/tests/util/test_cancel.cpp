// Progress and cancel within one long chunk (tmm::ChunkContext): a single 5-axis move of a million
// sub-steps reports progress as it goes and stops soon after the callback says false; the one-thread
// loops (SerialProgress: the arrival field) cancel too. Times are generous bounds for a loaded machine.
#include <gtest/gtest.h>

#include <atomic>
#include <chrono>
#include <vector>

#include "tmm/algo/arrival_field.hpp"
#include "tmm/sim/sweep5.hpp"
#include "tmm/util/parallel.hpp"

namespace {

using Clock = std::chrono::steady_clock;

double seconds_since(Clock::time_point t) { return std::chrono::duration<double>(Clock::now() - t).count(); }

TEST(ChunkCancel, OneLongChunkReportsAndStops) {
  tmm::BatchOptions b;
  b.threads = 2;
  std::vector<double> seen;
  Clock::time_point said_no;
  b.progress = [&](double f) {
    seen.push_back(f);
    if (seen.size() < 5) return true;
    said_no = Clock::now();
    return false;
  };
  EXPECT_THROW(tmm::parallel_chunks(1, 1, b,
                                    [](std::size_t, std::size_t, tmm::ChunkContext& ctx) {
                                      const auto start = Clock::now();
                                      while (!ctx.stopping() && seconds_since(start) < 60.0)
                                        ctx.done_within(seconds_since(start) / 60.0);
                                    }),
               tmm::Cancelled);
  EXPECT_LT(seconds_since(said_no), 1.0);
  ASSERT_GE(seen.size(), 5u);
  EXPECT_GT(seen[4], 0.0);  // the chunk's own progress, before it ended
}

TEST(ChunkCancel, ALongFiveAxisMoveStopsWithinItself) {
  tmm::TorusTool tool;
  tool.Ro = 2.0;
  tool.Ri = 1.0;
  // One cut move 400 mm long at 0.0004 mm steps: a million instances, minutes of work.
  const double tips[6] = {-200.0, 0.0, 0.0, 200.0, 0.0, 0.0}, axes[6] = {0, 0, 1, 0.3, 0, 1};
  const tmm::MoveKind kinds[1] = {tmm::MoveKind::Cut};
  tmm::Sweep5Options o;
  o.max_step = 0.0004;
  tmm::ZMap stock(-205.0, -5.0, 0.05, 8200, 200, 1.0);
  tmm::BatchOptions b;
  b.threads = 2;
  std::vector<double> seen;
  const auto start = Clock::now();
  Clock::time_point said_no;
  b.progress = [&](double f) {
    seen.push_back(f);
    if (seconds_since(start) < 1.0) return true;
    said_no = Clock::now();
    return false;
  };
  EXPECT_THROW(tmm::cut_5axis(stock, tool, tips, axes, kinds, 2, o, b), tmm::Cancelled);
  EXPECT_LT(seconds_since(said_no), 3.0);  // within a second, with slack for a loaded machine
  ASSERT_GE(seen.size(), 2u);
  EXPECT_GT(seen[seen.size() - 2], 0.02);  // progress within the move (past the footprint pass)
}

TEST(SerialCancel, TheArrivalFieldStops) {
  tmm::ArrivalGrid g;
  g.nx = g.ny = 400;
  g.cell = 0.1;
  const std::size_t n = 400 * 400;
  std::vector<double> z(n, 0.0), start(n, std::nan(""));
  start[0] = 0.0;
  const std::vector<std::uint8_t> active(n, 1);
  tmm::StepRuleTable r;
  r.steps = {0.5};
  r.dslope = 0.1;
  r.probe = 0.5;
  r.min_step = 0.05;
  tmm::BatchOptions b;
  int calls = 0;
  b.progress = [&](double) { return ++calls < 2; };
  EXPECT_THROW(tmm::arrival_field(g, z, active, start, r, b), tmm::Cancelled);
  EXPECT_EQ(calls, 2);
}

}  // namespace
