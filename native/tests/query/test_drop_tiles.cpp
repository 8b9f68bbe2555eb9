// DropTiles (drop_cutter.hpp): drops at scattered points through lists gathered once per tile, as a
// waterline level asks them; and drop_batch_capped, a waterline's grid. Checked against the maximum over all triangles (every cutter kind, floors,
// ceilings, hints, points outside the tiles), a triangle just above the lists' floor beside the tile (the
// lists' pruning rule: within the cutter's radius of the tile, top above the floor), and threads sharing
// the tiles.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <random>
#include <stdexcept>
#include <thread>
#include <vector>

#include "support/test_meshes.hpp"
#include "tmm/mesh/mesh_index.hpp"
#include "tmm/query/drop_cutter.hpp"

namespace {

using tmm::Cutter;

double brute_drop(const tmm::MeshIndex& index, const Cutter& c, double x, double y, double floor_z) {
  double best = floor_z;
  for (const auto& t : index.triangles()) best = std::max(best, tmm::drop_on_triangle(c, x, y, t));
  return best;
}

TEST(DropTiles, EqualsTheMaximumOverAllTriangles) {
  const int n = 24;
  std::mt19937_64 rng(5);
  const auto [V, F] = tmm_test::bumpy_grid(n, 4, 5, rng);
  const tmm::MeshIndex index(V, F);
  const int count = static_cast<int>(index.triangle_count());
  std::uniform_real_distribution<double> pos(-4, n + 4), u(0, 1);
  for (const Cutter& cut : {Cutter(2, 2), Cutter(2, 0), Cutter(3, 1), Cutter::apt(2, 0.5, 6, 0, 0.1)}) {
    // Tiles over part of the mesh only, their lists above z = -1: points outside and lower floors take
    // drop_point.
    const double tiles_floor = -1.0;
    const tmm::DropTiles tiles(index, cut, 0, 0, 16, 20, 0.5 * cut.max_radius(), tiles_floor);
    int32_t hint = -1;
    for (int k = 0; k < 1500; ++k) {
      const double x = pos(rng), y = pos(rng);
      const double floor_z = u(rng) < 0.2 ? -3.0 : tiles_floor + 3.0 * u(rng);
      const double exact = brute_drop(index, cut, x, y, floor_z);
      if (u(rng) < 0.3) hint = static_cast<int32_t>(u(rng) * count);  // any triangle, or the last winner
      const double h = tiles.drop(x, y, floor_z, &hint);
      ASSERT_NEAR(h, exact, 1e-12) << "(" << x << ", " << y << ") floor " << floor_z;
      if (h > floor_z) {
        ASSERT_GE(hint, 0);
        EXPECT_NEAR(tmm::drop_on_triangle(cut, x, y, index.triangles()[hint]), h, 1e-12);  // the winner
      } else {
        EXPECT_EQ(hint, -1);
      }
      // With a ceiling: the height where it is below, else some contact above the ceiling.
      const double ceiling = exact + (u(rng) - 0.5);
      const double capped = tiles.drop(x, y, floor_z, &hint, ceiling);
      if (exact <= ceiling) EXPECT_NEAR(capped, exact, 1e-12);
      else EXPECT_GT(capped, ceiling);
    }
  }
}

// The lists keep every triangle within the cutter's radius of the tile whose top is above the floor, not
// only those over the tile: a small triangle 1e-6 above the floor, in the next tile but within the flat's
// radius of a point at this tile's corner, lifts the flat to its height; one 1e-6 below the floor does not.
TEST(DropTiles, KeepsATriangleJustAboveTheFloorBesideTheTile) {
  const double floor_z = 2.0, top = floor_z + 1e-6;
  tmm::Vertices V(6, 3);
  V << 3.0005, 0.2, top, 3.3, 0.2, top, 3.2, 0.4, top,  // above the floor, in the tile from x = 3
      -3.3, 0.2, floor_z - 1e-6, -3.1, 0.2, floor_z - 1e-6, -3.2, 0.4, floor_z - 1e-6;  // below it
  tmm::Triangles F(2, 3);
  F << 0, 1, 2, 3, 4, 5;
  const tmm::MeshIndex index(V, F);
  const Cutter flat(3, 0), ball(3, 3);
  const tmm::DropTiles flat_tiles(index, flat, -10, -10, 10, 10, 1.0, floor_z);
  int32_t hint = -1;
  // (0.5, 0.5) lies in tile [0, 1] x [0, 1]; the triangle's nearest corner is 2.52 mm away.
  EXPECT_EQ(flat_tiles.drop(0.5, 0.5, floor_z, &hint), top);
  EXPECT_EQ(hint, static_cast<int32_t>(std::find_if(index.triangles().begin(), index.triangles().end(),
                                                    [](const auto& t) { return t.zmax > 2.0; }) -
                                       index.triangles().begin()));
  hint = -1;
  EXPECT_EQ(flat_tiles.drop(-0.5, 0.5, floor_z, &hint), floor_z);  // only the triangle below the floor
  EXPECT_EQ(hint, -1);
  // The ball 0.001 mm beside its corner, in the tile before, rests on it 1.7e-7 mm lower.
  const tmm::DropTiles ball_tiles(index, ball, -10, -10, 10, 10, 1.0, floor_z);
  hint = -1;
  const double h = ball_tiles.drop(2.9995, 0.2, floor_z, &hint);
  EXPECT_GT(h, floor_z);
  EXPECT_EQ(h, brute_drop(index, ball, 2.9995, 0.2, floor_z));
}

TEST(DropTiles, ThreadsSharingTheTilesGetTheSameHeights) {
  const int n = 30;
  std::mt19937_64 rng(9);
  const auto [V, F] = tmm_test::bumpy_grid(n, 5, 3, rng);
  const tmm::MeshIndex index(V, F);
  const Cutter cut(3, 1);
  std::uniform_real_distribution<double> pos(0, n);
  std::vector<double> xy(2 * 4000);
  for (double& v : xy) v = pos(rng);
  std::vector<double> single(xy.size() / 2);
  for (std::size_t i = 0; i < single.size(); ++i)
    single[i] = tmm::drop_point(index, cut, xy[2 * i], xy[2 * i + 1], -10);
  const tmm::DropTiles tiles(index, cut, 0, 0, n, n, 1.5, -10);
  std::vector<std::vector<double>> got(4, std::vector<double>(single.size(), NAN));
  std::vector<std::vector<std::size_t>> order(4, std::vector<std::size_t>(single.size()));
  for (auto& o : order) {  // each thread its own order: the tiles gathered by whichever comes first
    for (std::size_t i = 0; i < o.size(); ++i) o[i] = i;
    std::shuffle(o.begin(), o.end(), rng);
  }
  std::vector<std::thread> threads;
  for (int t = 0; t < 4; ++t)
    threads.emplace_back([&, t] {
      int32_t hint = -1;
      for (std::size_t i : order[t]) got[t][i] = tiles.drop(xy[2 * i], xy[2 * i + 1], -10, &hint);
    });
  for (auto& th : threads) th.join();
  for (int t = 0; t < 4; ++t)
    for (std::size_t i = 0; i < single.size(); ++i) ASSERT_NEAR(got[t][i], single[i], 1e-12) << t << " " << i;
}

// drop_batch_capped (a waterline's grid) solves the points of a tile standing above the ceiling without the
// tile's list (the last winner, else a walk stopping above the ceiling) and gathers the list at the first
// point below it: every height is min(h, ceiling), whichever way, and the same bits on 1 and 2 threads.
TEST(DropBatch, CappedHeightsAreTheHeightOrTheCeiling) {
  const int n = 30;
  std::mt19937_64 rng(13);
  const auto [V, F] = tmm_test::bumpy_grid(n, 4, 6, rng);
  const tmm::MeshIndex index(V, F);
  std::vector<double> xy;
  for (int i = 0; i <= 60; ++i)
    for (int j = 0; j <= 60; ++j) {
      xy.push_back(-2 + 0.56 * j);
      xy.push_back(-2 + 0.56 * i);
    }
  const std::size_t m = xy.size() / 2;
  for (const Cutter& cut : {Cutter(2, 2), Cutter(2, 0), Cutter(3, 1)}) {
    std::vector<double> exact(m);
    for (std::size_t i = 0; i < m; ++i) exact[i] = brute_drop(index, cut, xy[2 * i], xy[2 * i + 1], -10);
    for (double ceiling : {-2.0, 0.0, 1.5, 2.5}) {  // most points above it .. a few
      std::vector<double> z1(m), z2(m);
      tmm::BatchOptions one, two;
      one.threads = 1;
      two.threads = 2;
      tmm::drop_batch_capped(index, cut, xy.data(), m, -10, ceiling, z1.data(), one);
      tmm::drop_batch_capped(index, cut, xy.data(), m, -10, ceiling, z2.data(), two);
      int above = 0;
      for (std::size_t i = 0; i < m; ++i) {
        ASSERT_EQ(z1[i], z2[i]);
        above += exact[i] > ceiling;
        ASSERT_NEAR(z1[i], std::min(exact[i], ceiling), 1e-12) << "point " << i << " ceiling " << ceiling;
      }
      EXPECT_GT(above, 0);
      EXPECT_LT(above, static_cast<int>(m));
    }
  }
}

TEST(DropTiles, RefusesNonFiniteOrEmptyBounds) {
  const tmm::MeshIndex index = tmm_test::one_triangle({0, 0, 0}, {1, 0, 0}, {0, 1, 0});
  const Cutter ball(1, 1);
  EXPECT_THROW(tmm::DropTiles(index, ball, 0, 0, NAN, 1, 0.5, 0), std::invalid_argument);
  EXPECT_THROW(tmm::DropTiles(index, ball, 0, 0, 1, 1, INFINITY, 0), std::invalid_argument);
  EXPECT_THROW(tmm::DropTiles(index, ball, 2, 0, 1, 1, 0.5, 0), std::invalid_argument);
}

}  // namespace
