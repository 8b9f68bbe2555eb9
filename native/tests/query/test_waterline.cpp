// Exact waterline against closed forms and against the drop-cutter itself:
//  - a ball over a sphere mesh: a circle of radius sqrt((Rs + R)^2 - (z + R - zc)^2), within the mesh's
//    faceting error (the mesh is inscribed: loops lie inside the exact circle, never outside);
//  - a flat end mill on a box: the box's rectangle offset by R with round corners (distance R from it);
//  - every loop point is free (drop height <= z) and blocked material lies within 1e-6 mm on its left, or
//    its drop height is z within 1e-6;
//  - loops closed without self-intersections, islands counter-clockwise, pockets clockwise;
//  - identical loops for any thread count, cancel, bad input;
//  - the adaptive grid (min_step): a bump and a thin ridge between the coarse nodes, which the coarse grid
//    alone misses, are found exactly; loops the same in count, orientation and area as a uniform grid at
//    the fine step on the cases above.
#include <gtest/gtest.h>

#include <algorithm>
#include <atomic>
#include <cmath>
#include <string>
#include <vector>

#include "tmm/mesh/mesh_index.hpp"
#include "tmm/query/drop_cutter.hpp"
#include "tmm/query/waterline.hpp"

namespace {

using tmm::Cutter;
using tmm::MeshIndex;
using tmm::WaterlineLoop;
using tmm::WaterlineOptions;

constexpr double kPi = 3.14159265358979323846;

// A UV sphere with its vertices on the sphere (inscribed): `n` bands from pole to pole, 2n sectors.
MeshIndex sphere(double Rs, double zc, int n) {
  const int m = 2 * n;
  tmm::Vertices V((n - 1) * m + 2, 3);
  V.row(0) << 0, 0, zc + Rs;
  for (int i = 1; i < n; ++i)
    for (int j = 0; j < m; ++j) {
      const double th = kPi * i / n, ph = 2 * kPi * j / m;
      V.row(1 + (i - 1) * m + j) << Rs * std::sin(th) * std::cos(ph), Rs * std::sin(th) * std::sin(ph),
          zc + Rs * std::cos(th);
    }
  const int last = static_cast<int>(V.rows()) - 1;
  V.row(last) << 0, 0, zc - Rs;
  auto id = [&](int i, int j) { return 1 + (i - 1) * m + (j % m); };
  std::vector<std::array<int, 3>> F;
  for (int j = 0; j < m; ++j) F.push_back({0, id(1, j), id(1, j + 1)});
  for (int i = 1; i < n - 1; ++i)
    for (int j = 0; j < m; ++j) {
      F.push_back({id(i, j), id(i + 1, j), id(i + 1, j + 1)});
      F.push_back({id(i, j), id(i + 1, j + 1), id(i, j + 1)});
    }
  for (int j = 0; j < m; ++j) F.push_back({id(n - 1, j), last, id(n - 1, j + 1)});
  tmm::Triangles T(static_cast<Eigen::Index>(F.size()), 3);
  for (std::size_t t = 0; t < F.size(); ++t) T.row(static_cast<Eigen::Index>(t)) << F[t][0], F[t][1], F[t][2];
  return MeshIndex(V, T);
}

// Triangles of quads (corners counter-clockwise seen from above), each split along its first diagonal.
MeshIndex quads(const std::vector<std::array<Eigen::Vector3d, 4>>& q) {
  tmm::Vertices V(4 * q.size(), 3);
  tmm::Triangles T(2 * q.size(), 3);
  for (std::size_t k = 0; k < q.size(); ++k) {
    for (int c = 0; c < 4; ++c) V.row(static_cast<Eigen::Index>(4 * k + c)) = q[k][c].transpose();
    const int b = static_cast<int>(4 * k);
    T.row(static_cast<Eigen::Index>(2 * k)) << b, b + 1, b + 2;
    T.row(static_cast<Eigen::Index>(2 * k + 1)) << b, b + 2, b + 3;
  }
  return MeshIndex(V, T);
}

// A closed box [x0, x1] x [y0, y1] x [0, top].
MeshIndex box(double x0, double y0, double x1, double y1, double top) {
  using P = Eigen::Vector3d;
  return quads({{P(x0, y0, top), P(x1, y0, top), P(x1, y1, top), P(x0, y1, top)},
                {P(x0, y0, 0), P(x0, y1, 0), P(x1, y1, 0), P(x1, y0, 0)},
                {P(x0, y0, 0), P(x1, y0, 0), P(x1, y0, top), P(x0, y0, top)},
                {P(x1, y0, 0), P(x1, y1, 0), P(x1, y1, top), P(x1, y0, top)},
                {P(x1, y1, 0), P(x0, y1, 0), P(x0, y1, top), P(x1, y1, top)},
                {P(x0, y1, 0), P(x0, y0, 0), P(x0, y0, top), P(x0, y1, top)}});
}

// The top of a 40 x 40 frame around a 20 x 20 hole, at height 5 (no walls: the drop sees the top's edges).
MeshIndex frame() {
  using P = Eigen::Vector3d;
  const P o[4] = {P(0, 0, 5), P(40, 0, 5), P(40, 40, 5), P(0, 40, 5)};
  const P i[4] = {P(10, 10, 5), P(30, 10, 5), P(30, 30, 5), P(10, 30, 5)};
  std::vector<std::array<P, 4>> q;
  for (int k = 0; k < 4; ++k) q.push_back({o[k], o[(k + 1) % 4], i[(k + 1) % 4], i[k]});
  return quads(q);
}

WaterlineOptions options(double x0, double y0, double x1, double y1, double step, double tol) {
  WaterlineOptions o;
  o.xmin = x0;
  o.ymin = y0;
  o.xmax = x1;
  o.ymax = y1;
  o.sample_step = step;
  o.chord_tol = tol;
  return o;
}

bool blocked(const MeshIndex& index, const Cutter& c, double x, double y, double z) {
  return tmm::drop_point(index, c, x, y, z) > z;
}

// Every point free; blocked material within 1e-6 mm on the left of the loop there (or h = z within 1e-6).
void expect_contacts(const MeshIndex& index, const Cutter& c, const WaterlineLoop& loop) {
  const std::size_t n = loop.size();
  for (std::size_t i = 0; i < n; ++i) {
    if (!loop.contact[i]) continue;
    const double x = loop.xy[2 * i], y = loop.xy[2 * i + 1];
    const double h = tmm::drop_point(index, c, x, y, loop.z - 100.0);
    ASSERT_LE(h, loop.z) << "point " << i << " (" << x << ", " << y << ") gouges";
    if (std::abs(h - loop.z) <= 1e-6) continue;
    const std::size_t a = (i + n - 1) % n, b = (i + 1) % n;
    const double dx = loop.xy[2 * b] - loop.xy[2 * a], dy = loop.xy[2 * b + 1] - loop.xy[2 * a + 1];
    const double len = std::hypot(dx, dy);
    EXPECT_TRUE(blocked(index, c, x - 1e-6 * dy / len, y + 1e-6 * dx / len, loop.z))
        << "point " << i << " (" << x << ", " << y << "): h - z = " << h - loop.z << " and nothing blocked beside it";
  }
}

bool segments_cross(const double* p, const double* q, const double* r, const double* s) {
  auto orient = [](const double* a, const double* b, const double* c) {
    return (b[0] - a[0]) * (c[1] - a[1]) - (b[1] - a[1]) * (c[0] - a[0]);
  };
  const double d1 = orient(r, s, p), d2 = orient(r, s, q), d3 = orient(p, q, r), d4 = orient(p, q, s);
  return ((d1 > 0 && d2 < 0) || (d1 < 0 && d2 > 0)) && ((d3 > 0 && d4 < 0) || (d3 < 0 && d4 > 0));
}

// No two edges of the level's loops cross (neighbouring edges share a point and never count).
void expect_simple(const std::vector<WaterlineLoop>& level) {
  struct Edge {
    const double* p;
    const double* q;
  };
  std::vector<Edge> edges;
  for (const auto& loop : level)
    for (std::size_t i = 0, n = loop.size(); i < n; ++i) edges.push_back({&loop.xy[2 * i], &loop.xy[2 * ((i + 1) % n)]});
  for (std::size_t a = 0; a < edges.size(); ++a)
    for (std::size_t b = a + 1; b < edges.size(); ++b)
      ASSERT_FALSE(segments_cross(edges[a].p, edges[a].q, edges[b].p, edges[b].q))
          << "edges " << a << " and " << b << " cross";
}

TEST(Waterline, BallOverSphereIsTheCircleOfTheOffsetSphere) {
  const double Rs = 10, zc = 2, R = 3;
  const int n = 96;
  const MeshIndex index = sphere(Rs, zc, n);
  const Cutter ball(R, R);
  const std::vector<double> zs = {zc - 2.0, zc, zc + 4.0, zc + 9.0};
  const auto levels = tmm::waterline(index, ball, zs, options(-20, -20, 20, 20, 0.75, 1e-3), {});
  ASSERT_EQ(levels.size(), zs.size());
  // Facets lie inside the sphere by at most Rs (1 - cos(a)), a the angular radius of a facet (< pi / n from
  // a corner); the offset surface (the ball centre) by the same, and the circle's radius r by that times
  // (Rs + R) / r.
  const double facet = Rs * (1.0 - std::cos(kPi / n));
  for (std::size_t k = 0; k < zs.size(); ++k) {
    ASSERT_EQ(levels[k].size(), 1u) << "z " << zs[k];
    const WaterlineLoop& loop = levels[k][0];
    const double dz = zs[k] + R - zc;
    const double r = std::sqrt((Rs + R) * (Rs + R) - dz * dz);
    const double below = facet * (Rs + R) / r + 1e-6;
    EXPECT_GT(loop.area(), 0.0);
    EXPECT_NEAR(loop.area(), kPi * r * r, 2 * kPi * r * (below + 1e-3));
    for (std::size_t i = 0; i < loop.size(); ++i) {
      ASSERT_TRUE(loop.contact[i]);
      const double rho = std::hypot(loop.xy[2 * i], loop.xy[2 * i + 1]);
      ASSERT_LE(rho, r + 1e-6) << "z " << zs[k] << " point " << i;
      ASSERT_GE(rho, r - below) << "z " << zs[k] << " point " << i;
    }
    expect_contacts(index, ball, loop);
    expect_simple(levels[k]);
  }
}

TEST(Waterline, FlatOnABoxIsTheBoxOffsetWithRoundCorners) {
  const double R = 3, x0 = 0, y0 = 0, x1 = 20, y1 = 10;
  const MeshIndex index = box(x0, y0, x1, y1, 5);
  for (const Cutter& c : {Cutter(R, 0), Cutter(R, 1), Cutter(R, R)}) {
    const double z = 2.0;  // below the corner arcs of all three: the tool's side touches the walls
    const auto levels = tmm::waterline(index, c, {z}, options(-10, -10, 30, 20, 0.6, 1e-4), {});
    ASSERT_EQ(levels[0].size(), 1u);
    const WaterlineLoop& loop = levels[0][0];
    for (std::size_t i = 0; i < loop.size(); ++i) {
      const double x = loop.xy[2 * i], y = loop.xy[2 * i + 1];
      const double dx = std::max({x0 - x, x - x1, 0.0}), dy = std::max({y0 - y, y - y1, 0.0});
      ASSERT_NEAR(std::hypot(dx, dy), R, 1e-6) << "point " << i << " (" << x << ", " << y << ")";
    }
    const double area = (x1 - x0) * (y1 - y0) + 2 * R * ((x1 - x0) + (y1 - y0)) + kPi * R * R;
    // inscribed polygon: below the exact area by at most the chord tolerance along the round corners
    EXPECT_LE(loop.area(), area + 1e-4);
    EXPECT_GE(loop.area(), area - 2 * kPi * R * 1e-4 - 1e-4);
    expect_contacts(index, c, loop);
  }
}

TEST(Waterline, PocketRunsClockwiseAndTheIslandCounterClockwise) {
  const MeshIndex index = frame();
  const Cutter flat(3, 0);
  const auto levels = tmm::waterline(index, flat, {2.5}, options(-10, -10, 50, 50, 0.7, 1e-3), {});
  ASSERT_EQ(levels[0].size(), 2u);
  int islands = 0, pockets = 0;
  for (const WaterlineLoop& loop : levels[0]) {
    expect_contacts(index, flat, loop);
    if (loop.area() > 0) {
      ++islands;
      EXPECT_NEAR(loop.area(), 1600 + 4 * 40 * 3 + kPi * 9, 0.1);
    } else {
      ++pockets;
      // the hole shrunk by R: a 14 x 14 square with sharp corners (the tool's edge on two sides at once)
      EXPECT_NEAR(-loop.area(), 14.0 * 14.0, 1e-4);
    }
  }
  EXPECT_EQ(islands, 1);
  EXPECT_EQ(pockets, 1);
  expect_simple(levels[0]);
}

TEST(Waterline, BlockedPastTheBoundsIsFlaggedAndTheLoopStillCloses) {
  const MeshIndex index = box(0, 0, 20, 10, 5);
  const Cutter ball(3, 3);
  // bounds cut through the box: the loop runs along the bounds where the box goes on past them
  const auto levels = tmm::waterline(index, ball, {2.0}, options(10, -10, 30, 20, 0.5, 1e-3), {});
  ASSERT_EQ(levels[0].size(), 1u);
  const WaterlineLoop& loop = levels[0][0];
  std::size_t off = 0;
  for (std::size_t i = 0; i < loop.size(); ++i) {
    if (loop.contact[i]) continue;
    ++off;
    EXPECT_NEAR(loop.xy[2 * i], 10.0, 1e-12);  // on the bound x = 10
  }
  EXPECT_GT(off, 10u);
  EXPECT_GT(loop.area(), 0.0);
  expect_contacts(index, ball, loop);
  expect_simple(levels[0]);
}

TEST(Waterline, ThreadsGiveIdenticalLoops) {
  const MeshIndex index = sphere(10, 0, 48);
  const Cutter bull(3, 1);
  std::vector<double> zs;
  for (int k = 0; k < 12; ++k) zs.push_back(-2.0 + k);
  tmm::BatchOptions one, two;
  one.threads = 1;
  two.threads = 2;
  const auto a = tmm::waterline(index, bull, zs, options(-15, -15, 15, 15, 0.5, 1e-3), one);
  const auto b = tmm::waterline(index, bull, zs, options(-15, -15, 15, 15, 0.5, 1e-3), two);
  ASSERT_EQ(a.size(), b.size());
  for (std::size_t k = 0; k < a.size(); ++k) {
    ASSERT_EQ(a[k].size(), b[k].size());
    for (std::size_t l = 0; l < a[k].size(); ++l) {
      EXPECT_EQ(a[k][l].xy, b[k][l].xy);
      EXPECT_EQ(a[k][l].contact, b[k][l].contact);
    }
  }
}

TEST(Waterline, ProgressFalseCancels) {
  const MeshIndex index = sphere(10, 0, 48);
  const Cutter ball(3, 3);
  std::atomic<int> calls{0};
  tmm::BatchOptions batch;
  batch.progress = [&](double) { return ++calls < 1; };
  EXPECT_THROW(tmm::waterline(index, ball, {0.0, 1.0, 2.0}, options(-15, -15, 15, 15, 0.05, 1e-3), batch),
               tmm::Cancelled);
  EXPECT_GE(calls.load(), 1);
}

TEST(Waterline, BadInputIsRefusedByName) {
  const MeshIndex index = sphere(10, 0, 16);
  const Cutter ball(3, 3);
  auto message = [&](const WaterlineOptions& o, std::vector<double> zs) {
    try {
      tmm::waterline(index, ball, zs, o, {});
    } catch (const std::invalid_argument& e) {
      return std::string(e.what());
    }
    return std::string("no error");
  };
  EXPECT_NE(message(options(0, 0, 0, 10, 1, 0.01), {0}).find("xmax"), std::string::npos);
  EXPECT_NE(message(options(0, 0, 10, 10, 0, 0.01), {0}).find("sample step"), std::string::npos);
  EXPECT_NE(message(options(0, 0, 10, 10, 1, 0), {0}).find("chord tolerance"), std::string::npos);
  EXPECT_NE(message(options(0, 0, 10, 10, 1, 0.01), {std::nan("")}).find("level z"), std::string::npos);
  const std::string big = message(options(0, 0, 1000, 1000, 0.01, 0.01), {0});
  EXPECT_NE(big.find("sample step 0.01 mm"), std::string::npos) << big;
  EXPECT_NE(big.find("limit"), std::string::npos) << big;
}

// ---- adaptive grid (min_step) ----

WaterlineOptions adaptive(WaterlineOptions o, double min_step) {
  o.min_step = min_step;
  return o;
}

double max_x(const WaterlineLoop& loop) {
  double m = -1e300;
  for (std::size_t i = 0; i < loop.size(); ++i) m = std::max(m, loop.xy[2 * i]);
  return m;
}

// A 20 x 20 plane at z 0 and a thin pyramid on it: apex (ax, ay, top), base half-width w.
MeshIndex plane_with_spike(double ax, double ay, double top, double w) {
  tmm::Vertices V(9, 3);
  V << -10, -10, 0, 10, -10, 0, 10, 10, 0, -10, 10, 0,                               // plane
      ax - w, ay - w, 0, ax + w, ay - w, 0, ax + w, ay + w, 0, ax - w, ay + w, 0,  // base
      ax, ay, top;                                                                  // apex
  tmm::Triangles T(6, 3);
  T << 0, 1, 2, 0, 2, 3, 4, 5, 8, 5, 6, 8, 6, 7, 8, 7, 4, 8;
  return MeshIndex(V, T);
}

TEST(WaterlineAdaptive, FindsABumpBetweenTheCoarseNodes) {
  const Cutter ball(3, 3);
  const double ax = 0.5, ay = 0.5;  // the centre of a 1 mm cell: 0.71 mm from its corners
  const MeshIndex index = plane_with_spike(ax, ay, 1.0, 0.05);
  const double rho = 0.3;           // the loop: the ball touching the apex at rho from its axis
  const double z = 1.0 - ball.height(rho);
  const WaterlineOptions coarse = options(-5, -5, 5, 5, 1.0, 1e-4);
  // The corners see the apex 0.71 mm away, below z: the uniform 1 mm grid finds nothing.
  EXPECT_EQ(tmm::waterline(index, ball, {z}, coarse, {})[0].size(), 0u);
  tmm::WaterlineStats stats;
  const auto levels = tmm::waterline(index, ball, {z}, adaptive(coarse, 0.05), {}, &stats);
  EXPECT_GT(stats.refined_cells, 0u);
  ASSERT_EQ(levels[0].size(), 1u);
  const WaterlineLoop& loop = levels[0][0];
  EXPECT_GT(loop.area(), 0.0);  // an island
  EXPECT_NEAR(loop.area(), kPi * rho * rho, 2 * kPi * rho * 1e-4);
  for (std::size_t i = 0; i < loop.size(); ++i)
    ASSERT_NEAR(std::hypot(loop.xy[2 * i] - ax, loop.xy[2 * i + 1] - ay), rho, 1e-6) << "point " << i;
  expect_contacts(index, ball, loop);
  expect_simple(levels[0]);
  // A uniform grid at the fine step sees the same loop.
  const auto fine = tmm::waterline(index, ball, {z}, options(-5, -5, 5, 5, 0.0625, 1e-4), {});
  ASSERT_EQ(fine[0].size(), 1u);
  EXPECT_NEAR(fine[0][0].area(), loop.area(), 2 * kPi * rho * 1e-4);
}

// A box [0, 10] x [-5, 5] x [0, 5] and a thin ridge of height 1 along y = 0.5 from x = 10 to x = 16.
MeshIndex box_with_ridge() {
  using P = Eigen::Vector3d;
  const double y = 0.5, w = 0.02, x0 = 10, x1 = 16;
  std::vector<std::array<P, 4>> q = {{P(0, -5, 5), P(10, -5, 5), P(10, 5, 5), P(0, 5, 5)},
                                     {P(0, -5, 0), P(10, -5, 0), P(10, -5, 5), P(0, -5, 5)},
                                     {P(10, -5, 0), P(10, 5, 0), P(10, 5, 5), P(10, -5, 5)},
                                     {P(10, 5, 0), P(0, 5, 0), P(0, 5, 5), P(10, 5, 5)},
                                     {P(0, 5, 0), P(0, -5, 0), P(0, -5, 5), P(0, 5, 5)},
                                     {P(x0, y - w, 0), P(x1, y - w, 0), P(x1, y, 1), P(x0, y, 1)},
                                     {P(x1, y + w, 0), P(x0, y + w, 0), P(x0, y, 1), P(x1, y, 1)}};
  return quads(q);
}

TEST(WaterlineAdaptive, FindsAThinRidgeBetweenTwoGridLines) {
  const Cutter ball(3, 3);
  const MeshIndex index = box_with_ridge();
  const double z = 0.99;
  const double rho = std::sqrt(6.0 * 0.01 - 0.01 * 0.01);  // the ball on the ridge's crest at z: h(rho) = 0.01
  // The ridge runs between the grid lines y = 0 and y = 1; its 0.49 mm wide strip of blocked positions
  // sticks out 3.2 mm past the box's loop (x = 13).
  const WaterlineOptions coarse = options(-10, -10, 20, 10, 1.0, 1e-4);
  const auto plain = tmm::waterline(index, ball, {z}, coarse, {});
  ASSERT_EQ(plain[0].size(), 1u);
  EXPECT_LT(max_x(plain[0][0]), 13.0 + 1e-6);  // the coarse grid cuts the spike off
  const auto levels = tmm::waterline(index, ball, {z}, adaptive(coarse, 0.05), {});
  ASSERT_EQ(levels[0].size(), 1u);
  const WaterlineLoop& loop = levels[0][0];
  EXPECT_GT(loop.area(), 0.0);
  EXPECT_NEAR(max_x(loop), 16.0 + rho, 1e-4);
  expect_contacts(index, ball, loop);
  expect_simple(levels[0]);
  const auto fine = tmm::waterline(index, ball, {z}, options(-10, -10, 20, 10, 0.0625, 1e-4), {});
  ASSERT_EQ(fine[0].size(), 1u);
  EXPECT_NEAR(max_x(fine[0][0]), max_x(loop), 1e-4);
  EXPECT_NEAR(fine[0][0].area(), loop.area(), 1e-3 * loop.area());
}

// A plateau at height 10 with a conical pit: apex (0, 0, 5), walls at 45 degrees up to radius 5; polar rings
// of 64 sectors out to radius 20.
MeshIndex plateau_with_pit() {
  const int sectors = 64;
  const std::vector<double> radii = {0.625, 1.25, 1.875, 2.5, 3.125, 3.75, 4.375, 5, 8, 12, 20};
  tmm::Vertices V(1 + sectors * static_cast<int>(radii.size()), 3);
  V.row(0) << 0, 0, 5;
  for (std::size_t r = 0; r < radii.size(); ++r)
    for (int j = 0; j < sectors; ++j) {
      const double a = 2 * kPi * j / sectors, rho = radii[r];
      V.row(1 + static_cast<int>(r) * sectors + j) << rho * std::cos(a), rho * std::sin(a), std::min(5 + rho, 10.0);
    }
  auto id = [&](std::size_t r, int j) { return 1 + static_cast<int>(r) * sectors + j % sectors; };
  std::vector<std::array<int, 3>> F;
  for (int j = 0; j < sectors; ++j) F.push_back({0, id(0, j), id(0, j + 1)});
  for (std::size_t r = 0; r + 1 < radii.size(); ++r)
    for (int j = 0; j < sectors; ++j) {
      F.push_back({id(r, j), id(r + 1, j), id(r + 1, j + 1)});
      F.push_back({id(r, j), id(r + 1, j + 1), id(r, j + 1)});
    }
  tmm::Triangles T(static_cast<Eigen::Index>(F.size()), 3);
  for (std::size_t t = 0; t < F.size(); ++t) T.row(static_cast<Eigen::Index>(t)) << F[t][0], F[t][1], F[t][2];
  return MeshIndex(V, T);
}

// A free pocket narrower than the grid whose four corners stand above z by more than the pocket band: only
// the cubic through the 4 x 4 nodes around the cell shows the dip, which it must keep showing where its
// samples are skipped (a bound of the cubic from the nodes' range: 1.5625 half-ranges about the mid-range;
// with 1 half-range, the nodes' own range, this pocket is lost).
TEST(WaterlineAdaptive, FindsADipBetweenTheNodesByTheCubic) {
  const Cutter ball(3, 3);
  const MeshIndex index = plateau_with_pit();
  const double bottom = tmm::drop_point(index, ball, 0, 0, 0);  // the ball in the pit: h rises about 1 per mm
  const double z = bottom + 0.12;
  // The pit's axis at the centre of a 0.5 mm cell: its corners 0.35 mm away, about 0.23 above z, above the
  // pocket band (0.17 for the ball over 2 x 0.5 mm).
  const WaterlineOptions coarse = options(-10.25, -10.25, 10.25, 10.25, 0.5, 1e-4);
  for (double c : {0.25, -0.25})
    ASSERT_GT(tmm::drop_point(index, ball, c, c, 0) - z, ball.max_radius() - std::sqrt(9.0 - 1.0));
  auto pockets = [](const std::vector<WaterlineLoop>& level) {
    std::vector<const WaterlineLoop*> found;
    for (const auto& loop : level)
      if (loop.area() < 0) found.push_back(&loop);
    return found;
  };
  EXPECT_TRUE(pockets(tmm::waterline(index, ball, {z}, coarse, {})[0]).empty());
  const auto level = tmm::waterline(index, ball, {z}, adaptive(coarse, 0.05), {})[0];
  const auto found = pockets(level);
  ASSERT_EQ(found.size(), 1u);
  for (std::size_t i = 0; i < found[0]->size(); ++i)
    ASSERT_LT(std::hypot(found[0]->xy[2 * i], found[0]->xy[2 * i + 1]), 0.2) << "point " << i;
  expect_contacts(index, ball, *found[0]);
  expect_simple(level);
  // A uniform grid at the fine step sees the same pocket.
  WaterlineOptions fine = coarse;
  fine.sample_step = 0.03125;
  const auto ref = pockets(tmm::waterline(index, ball, {z}, fine, {})[0]);
  ASSERT_EQ(ref.size(), 1u);
  EXPECT_NEAR(found[0]->area(), ref[0]->area(), 0.02 * std::abs(ref[0]->area()));
}

// Count, orientation and area of each loop (sorted by area) equal to a uniform grid's at the fine step.
void expect_same_loops(const std::vector<WaterlineLoop>& a, const std::vector<WaterlineLoop>& b, double tol) {
  ASSERT_EQ(a.size(), b.size());
  std::vector<double> aa, bb;
  for (const auto& l : a) aa.push_back(l.area());
  for (const auto& l : b) bb.push_back(l.area());
  std::sort(aa.begin(), aa.end());
  std::sort(bb.begin(), bb.end());
  for (std::size_t i = 0; i < aa.size(); ++i) EXPECT_NEAR(aa[i], bb[i], tol * std::max(1.0, std::abs(bb[i])));
}

TEST(WaterlineAdaptive, LoopsAsAUniformFineGridsOnTheExistingCases) {
  const MeshIndex ball_sphere = sphere(10, 2, 48), b = box(0, 0, 20, 10, 5), f = frame();
  std::vector<double> zs;
  for (int k = 0; k < 6; ++k) zs.push_back(-1.5 + 2.1 * k);
  for (const Cutter& c : {Cutter(3, 0), Cutter(3, 1), Cutter(3, 3)}) {
    const struct {
      const MeshIndex* index;
      WaterlineOptions o;
    } cases[] = {{&ball_sphere, options(-16, -16, 16, 16, 1.0, 1e-3)},
                 {&b, options(-10, -10, 30, 20, 1.0, 1e-3)},
                 {&f, options(-10, -10, 50, 50, 1.0, 1e-3)}};
    for (const auto& cs : cases) {
      const auto a = tmm::waterline(*cs.index, c, zs, adaptive(cs.o, 0.125), {});
      WaterlineOptions u = cs.o;
      u.sample_step = 0.125;
      const auto ref = tmm::waterline(*cs.index, c, zs, u, {});
      for (std::size_t k = 0; k < zs.size(); ++k) {
        expect_same_loops(a[k], ref[k], 1e-3);
        for (const auto& loop : a[k]) expect_contacts(*cs.index, c, loop);
        expect_simple(a[k]);
      }
    }
  }
}

TEST(WaterlineAdaptive, ThreadsGiveIdenticalLoops) {
  const MeshIndex index = box_with_ridge();
  const Cutter ball(3, 3);
  const std::vector<double> zs = {0.2, 0.5, 0.9, 0.99, 0.999, 2.0};
  tmm::BatchOptions one, two;
  one.threads = 1;
  two.threads = 2;
  const WaterlineOptions o = adaptive(options(-10, -10, 20, 10, 1.0, 1e-3), 0.05);
  const auto a = tmm::waterline(index, ball, zs, o, one);
  const auto b = tmm::waterline(index, ball, zs, o, two);
  for (std::size_t k = 0; k < zs.size(); ++k) {
    ASSERT_EQ(a[k].size(), b[k].size());
    for (std::size_t l = 0; l < a[k].size(); ++l) EXPECT_EQ(a[k][l].xy, b[k][l].xy);
    // One level alone (its crossings and chords on both threads) gives the points it gives on one thread.
    // (Not bit-identical to the level in the batch: the grid's floor is below the lowest level.)
    const auto c1 = tmm::waterline(index, ball, {zs[k]}, o, one);
    const auto c2 = tmm::waterline(index, ball, {zs[k]}, o, two);
    ASSERT_EQ(c1[0].size(), c2[0].size());
    for (std::size_t l = 0; l < c1[0].size(); ++l) EXPECT_EQ(c1[0][l].xy, c2[0][l].xy);
  }
}

TEST(WaterlineAdaptive, ProgressFalseCancelsWithinALevel) {
  const MeshIndex index = sphere(10, 0, 48);
  const Cutter ball(3, 3);
  tmm::BatchOptions batch;
  batch.threads = 2;
  // The grid is 0.72 of the estimated work (301 x 301 nodes against 60 drops per grid line), the level's
  // crossings the next half of the rest: their end reports 0.86, and the cancel there stops the level.
  double last = 0;
  std::string seen;
  batch.progress = [&](double f) {
    last = f;
    seen += std::to_string(f) + " ";
    return f < 0.75;
  };
  EXPECT_THROW(tmm::waterline(index, ball, {1.0}, options(-15, -15, 15, 15, 0.1, 1e-6), batch), tmm::Cancelled);
  EXPECT_GE(last, 0.75);
  EXPECT_LT(last, 1.0) << seen;
}

TEST(WaterlineAdaptive, BadMinimumStepIsRefusedByName) {
  const MeshIndex index = sphere(10, 0, 16);
  const Cutter ball(3, 3);
  for (double bad : {-0.1, 1e-4, std::nan("")}) {
    try {
      tmm::waterline(index, ball, {0.0}, adaptive(options(0, 0, 10, 10, 1, 0.01), bad), {});
      ADD_FAILURE() << "min_step " << bad << " accepted";
    } catch (const std::invalid_argument& e) {
      EXPECT_NE(std::string(e.what()).find("minimum step"), std::string::npos) << e.what();
    }
  }
}

}  // namespace
