// Candidate selection alone: SpreadLowest (the drop's and the gouge check's streaming choice) against its
// definition checked by brute force, and pick_apart (VCRF's second-contact candidates).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <random>
#include <utility>
#include <vector>

#include "tmm/position/candidates.hpp"

namespace {

using Eigen::Vector3d;

std::vector<Vector3d> random_points(int n, unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> u(0.0, 10.0);
  std::vector<Vector3d> p;
  for (int i = 0; i < n; ++i) p.emplace_back(u(rng), u(rng), u(rng));
  return p;
}

TEST(Candidates, SpreadLowestWithoutNeighboursKeepsTheKLowest) {
  // Points far apart (separation 0): exactly the K lowest scores survive, whatever the order.
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  for (int trial = 0; trial < 50; ++trial) {
    std::vector<double> score(40);
    for (auto& s : score) s = u(rng);
    tmm::SpreadLowest<std::size_t, 4> best(0.0);
    for (std::size_t i = 0; i < score.size(); ++i) best.offer(score[i], i, Vector3d(double(i), 0, 0));
    std::vector<double> sorted = score;
    std::sort(sorted.begin(), sorted.end());
    std::vector<double> kept;
    for (const auto& e : best) kept.push_back(e.score);
    std::sort(kept.begin(), kept.end());
    ASSERT_EQ(kept.size(), 4u);
    for (int k = 0; k < 4; ++k) EXPECT_EQ(kept[k], sorted[k]);
  }
}

TEST(Candidates, SpreadLowestKeepsOnePerNeighbourhood) {
  // Clusters of points around 3 centres far apart: one per cluster, the cluster's lowest.
  const Vector3d centre[3] = {Vector3d(0, 0, 0), Vector3d(100, 0, 0), Vector3d(0, 100, 0)};
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> u(-0.4, 0.4), s(0.0, 1.0);
  tmm::SpreadLowest<int, 6> best(1.0);  // separation 1 > any in-cluster distance (< 0.4 sqrt 3)
  double lowest[3] = {INFINITY, INFINITY, INFINITY};
  for (int i = 0; i < 300; ++i) {
    const int c = i % 3;
    const Vector3d p = centre[c] + 0.5 * Vector3d(u(rng), u(rng), u(rng));
    const double score = s(rng);
    lowest[c] = std::min(lowest[c], score);
    best.offer(score, c, p);
  }
  ASSERT_EQ(best.size(), 3);
  for (const auto& e : best) EXPECT_EQ(e.score, lowest[e.item]);
}

TEST(Candidates, SpreadLowestAlwaysKeepsTheLowest) {
  // Whatever the neighbourhoods, the overall lowest item survives: nothing lower replaces it and it is
  // never the highest kept.
  for (unsigned seed = 0; seed < 20; ++seed) {
    const auto pts = random_points(200, seed);
    std::mt19937 rng(seed + 100);
    std::uniform_real_distribution<double> u(0.0, 1.0);
    const double sep2 = 4.0;
    tmm::SpreadLowest<std::size_t, 5> best(sep2);
    std::vector<double> score(pts.size());
    for (std::size_t i = 0; i < pts.size(); ++i) {
      score[i] = u(rng);
      best.offer(score[i], i, pts[i]);
    }
    ASSERT_EQ(best.size(), 5);
    for (int i = 0; i < best.size(); ++i) {
      EXPECT_EQ(best[i].point, pts[best[i].item]);
      EXPECT_EQ(best[i].score, score[best[i].item]);
    }
    const std::size_t argmin = std::min_element(score.begin(), score.end()) - score.begin();
    bool found = false;
    for (const auto& e : best) found |= e.item == argmin;
    EXPECT_TRUE(found);
  }
}

TEST(Candidates, PickApartIsTheGreedyChoiceInRankOrder) {
  for (unsigned seed = 0; seed < 20; ++seed) {
    const auto pts = random_points(150, seed);
    std::vector<std::pair<double, std::size_t>> ranked;
    std::mt19937 rng(seed);
    std::uniform_real_distribution<double> u(0.0, 1.0);
    for (std::size_t i = 0; i < pts.size(); ++i) ranked.emplace_back(u(rng), i);
    std::sort(ranked.begin(), ranked.end());
    const double sep2 = 9.0;
    const auto chosen = tmm::pick_apart(ranked, pts, sep2, 6);
    // Brute force: walk the ranking, take an entry iff it is apart from all taken so far, stop at 6.
    std::vector<std::size_t> expect;
    for (const auto& r : ranked) {
      bool ok = true;
      for (std::size_t c : expect) ok = ok && (pts[c] - pts[r.second]).squaredNorm() >= sep2;
      if (ok && expect.size() < 6) expect.push_back(r.second);
    }
    EXPECT_EQ(chosen, expect);
    EXPECT_EQ(chosen.front(), ranked.front().second);  // the best is always a candidate
  }
}

TEST(Candidates, PickApartOfFewerThanK) {
  const std::vector<Vector3d> pts = {Vector3d(0, 0, 0), Vector3d(0.1, 0, 0), Vector3d(5, 0, 0)};
  const std::vector<std::pair<double, std::size_t>> ranked = {{0.1, 1}, {0.2, 0}, {0.3, 2}};
  EXPECT_EQ(tmm::pick_apart(ranked, pts, 1.0, 6), (std::vector<std::size_t>{1, 2}));
  EXPECT_TRUE(tmm::pick_apart({}, pts, 1.0, 6).empty());
}

}  // namespace
