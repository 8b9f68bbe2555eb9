// The tool's bodies above the flutes against the stock during the cut (tmm/sim/body_check.hpp): hand-checkable
// cases (a holder over a tall boss, a shank entering a wall above the flutes, a plunge), a brute force that
// grows each body's densely sampled surface by its clearance, the tilted frustum's closed form against a scan,
// the heights unchanged by the check and the same collisions for any thread count and band split.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <random>
#include <stdexcept>
#include <string>
#include <vector>

#include <Eigen/Geometry>

#include "tmm/sim/body_check.hpp"
#include "tmm/sim/sweep3.hpp"
#include "tmm/sim/sweep5.hpp"

namespace {

using tmm::BodyCheck;
using tmm::BodyCollision;
using tmm::Cutter;
using tmm::MoveKind;
using tmm::ToolBody;
using tmm::ZMap;

// A ball or flat D4 under a shank (8..30, r 2.5, clearance c) and a holder (30..60, r 10, clearance 1).
BodyCheck tool_bodies(double shank_clearance = 0.0, double flute_top = 8.0) {
  BodyCheck b;
  b.bodies = {{8.0, 30.0, 2.5, 2.5, shank_clearance}, {30.0, 60.0, 10.0, 10.0, 1.0}};
  b.flute_top = flute_top;
  return b;
}

tmm::SimReport cut3(ZMap& z, const Cutter& c, const std::vector<double>& tips, const BodyCheck* check,
                    int threads = 1, std::size_t band_rows = 0) {
  tmm::Sweep3Options o;
  o.body_check = check;
  o.band_rows = band_rows;
  tmm::BatchOptions b;
  b.threads = threads;
  const std::vector<MoveKind> kinds(tips.size() / 3 - 1, MoveKind::Cut);
  return tmm::cut_3axis(z, c, tips.data(), kinds.data(), tips.size() / 3, o, b);
}

// A flat stock at 0 with a block [x0, x1] x [y0, y1] standing to `top`.
ZMap block_stock(double x0, double x1, double y0, double y1, double top, double cell = 0.25) {
  ZMap z(-40.0, -40.0, cell, static_cast<std::size_t>(80.0 / cell), static_cast<std::size_t>(80.0 / cell), 0.0);
  for (std::size_t j = 0; j < z.ny(); ++j)
    for (std::size_t i = 0; i < z.nx(); ++i)
      if (z.cx(i) >= x0 && z.cx(i) <= x1 && z.cy(j) >= y0 && z.cy(j) <= y1) z.at(i, j) = top;
  return z;
}

const BodyCollision* find(const std::vector<BodyCollision>& all, std::size_t move, std::size_t piece) {
  for (const BodyCollision& c : all)
    if (c.move == move && c.piece == piece) return &c;
  return nullptr;
}

TEST(BodyCheck, HolderOverATallBossCollidesByTheBossAboveItsGrownFace) {
  // The tip at z = -5 passes y = 14 beside a boss 10 mm square and 30 mm tall: the holder grown by its
  // clearance (radius 10 + 1, face at z = -5 + 30 - 1 = 24) covers the boss' strip y in [3, 5]: 6 mm deep; the shank
  // (reach 2.5) stays away from it.
  ZMap z = block_stock(-5, 5, -5, 5, 30.0);
  const BodyCheck check = tool_bodies();
  const tmm::SimReport r = cut3(z, Cutter(2.0, 2.0), {-30, 14, -5, 30, 14, -5}, &check);
  ASSERT_EQ(r.body_collisions.size(), 1u);
  const BodyCollision& c = r.body_collisions[0];
  EXPECT_EQ(c.move, 0u);
  EXPECT_EQ(c.piece, 1u);
  EXPECT_NEAR(c.depth, 6.0, 1e-9);
  EXPECT_EQ(c.z, 30.0);
  EXPECT_LE(std::fabs(c.x), 5.0);
  EXPECT_GE(c.y, 3.0);
  EXPECT_LE(c.y, 5.0);
  // Passing at y = 16.5 the holder's reach (11 mm) ends at y = 5.5, beyond the boss.
  ZMap z2 = block_stock(-5, 5, -5, 5, 30.0);
  EXPECT_TRUE(cut3(z2, Cutter(2.0, 2.0), {-30, 16.5, -5, 30, 16.5, -5}, &check).body_collisions.empty());
}

TEST(BodyCheck, ShankEnteringAWallAboveTheFlutesIsACollision) {
  // A slot at z = 0 into a wall 20 mm tall at x >= 10: the flutes reach 8 mm up, the wall's material above
  // them stands under the shank (bottom 8 above the tip): 12 mm deep. The column model of the z-map would
  // have cut it: only the flute rule sees it.
  ZMap z = block_stock(10, 40, -40, 40, 20.0);
  const BodyCheck check = tool_bodies();
  const tmm::SimReport r = cut3(z, Cutter(2.0, 0.0), {0, 0, 0, 12, 0, 0}, &check);
  const BodyCollision* shank = find(r.body_collisions, 0, 0);
  ASSERT_NE(shank, nullptr);
  EXPECT_NEAR(shank->depth, 12.0, 1e-9);
  EXPECT_EQ(shank->z, 20.0);
  EXPECT_GE(shank->x, 10.0);
  // The holder (face at 30 - 1 = 29 above the tip) stays above the wall's top (20).
  EXPECT_EQ(find(r.body_collisions, 0, 1), nullptr);
  // The same slot into a wall lower than the flutes' top: the flutes cut it, nothing collides.
  ZMap low = block_stock(10, 40, -40, 40, 7.0);
  EXPECT_TRUE(cut3(low, Cutter(2.0, 0.0), {0, 0, 0, 12, 0, 0}, &check).body_collisions.empty());
}

TEST(BodyCheck, APlungeDeeperThanTheFlutesCutsItsOwnWayForTheShank) {
  // The flutes cut the hole as the tool goes down, so a shank no wider than the cutter meets nothing; with
  // a clearance the hole's wall lies inside it: 20 deep at the tip's last height, minus the shank's bottom
  // (8) less its clearance 0.5 (the Minkowski ball's lowest just outside the cutter radius).
  const BodyCheck narrow = [] { BodyCheck b = tool_bodies(); b.bodies[0].r0 = b.bodies[0].r1 = 2.0; return b; }();
  ZMap z = block_stock(100, 101, 100, 101, 0.0);
  EXPECT_TRUE(cut3(z, Cutter(2.0, 0.0), {0.1, 0.1, 30, 0.1, 0.1, -20}, &narrow).body_collisions.empty());
  BodyCheck grown = narrow;
  grown.bodies[0].clearance = 0.5;
  ZMap z2 = block_stock(100, 101, 100, 101, 0.0);
  const tmm::SimReport r = cut3(z2, Cutter(2.0, 0.0), {0.1, 0.1, 30, 0.1, 0.1, -20}, &grown);
  const BodyCollision* shank = find(r.body_collisions, 0, 0);
  ASSERT_NE(shank, nullptr);
  EXPECT_GT(shank->depth, 12.0);
  EXPECT_LE(shank->depth, 12.5 + 1e-9);
  const double d = std::hypot(shank->x - 0.1, shank->y - 0.1);
  EXPECT_GT(d, 2.0);
  EXPECT_LE(d, 2.5);
}

// The brute force: each body's meridian (bottom radius, side) sampled densely; the grown body's lowest point at
// the radial distance d is the lowest of the clearance discs about the samples (a body of revolution's nearest
// point to a point lies in the meridian plane through it).
struct SampledBodies {
  struct P { double r, z; std::size_t piece; double c; };
  std::vector<P> pts;
  explicit SampledBodies(const BodyCheck& b, double ds = 0.005) {
    for (std::size_t k = 0; k < b.bodies.size(); ++k) {
      const ToolBody& t = b.bodies[k];
      for (double r = 0.0; r < t.r0; r += ds) pts.push_back({r, t.z0, k, t.clearance});
      const double len = std::hypot(t.z1 - t.z0, t.r1 - t.r0);
      const int n = static_cast<int>(std::ceil(len / ds));
      for (int i = 0; i <= n; ++i)
        pts.push_back({t.r0 + (t.r1 - t.r0) * i / n, t.z0 + (t.z1 - t.z0) * i / n, k, t.clearance});
    }
  }
  // Lowest grown point above the tip at the offset (dx, dy), per piece (inf: none).
  void lowest(double dx, double dy, std::vector<double>& out) const {
    std::fill(out.begin(), out.end(), INFINITY);
    const double d = std::hypot(dx, dy);
    for (const P& p : pts) {
      const double e = std::fabs(d - p.r);
      if (e > p.c && !(p.c == 0.0 && e < 1e-3)) continue;
      out[p.piece] = std::min(out[p.piece], p.z - std::sqrt(std::max(0.0, p.c * p.c - e * e)));
    }
  }
};

TEST(BodyCheck, DeepestCollisionsMatchTheBruteForceOfSampledBodies) {
  // Boxes of random heights, a path at random heights; a widening holder cone with clearances. The brute force
  // replays the same poses (the kernel's documented sampling) and flute rule with its own geometry.
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> U(0.0, 1.0);
  ZMap z(-20.0, -20.0, 0.5, 80, 80, 0.0);
  for (int b = 0; b < 6; ++b) {
    const double x0 = -20 + 36 * U(rng), y0 = -20 + 36 * U(rng), top = 4 + 26 * U(rng);
    for (std::size_t j = 0; j < z.ny(); ++j)
      for (std::size_t i = 0; i < z.nx(); ++i)
        if (z.cx(i) >= x0 && z.cx(i) <= x0 + 6 && z.cy(j) >= y0 && z.cy(j) <= y0 + 6) z.at(i, j) = top;
  }
  BodyCheck check;
  check.bodies = {{6.0, 20.0, 2.0, 2.0, 0.5}, {20.0, 26.0, 4.0, 9.0, 1.0}, {26.0, 50.0, 9.0, 9.0, 1.0}};
  check.flute_top = 6.0;
  check.step = 0.5;
  std::vector<double> tips;
  for (int k = 0; k < 6; ++k) tips.insert(tips.end(), {-15 + 30 * U(rng), -15 + 30 * U(rng), -2 + 12 * U(rng)});
  const Cutter cutter(2.0, 1.0);
  const ZMap before = z;
  const tmm::SimReport r = cut3(z, cutter, tips, &check);
  ASSERT_FALSE(r.body_collisions.empty());

  const SampledBodies sampled(check);
  std::vector<double> low(3), worst, credited;
  std::size_t compared = 0;
  ZMap scratch = before;  // the brute force's stock: each move on a copy of the stock before it
  for (std::size_t k = 0; k + 1 < tips.size() / 3; ++k) {
    const double* a = &tips[3 * k];
    const double* b = a + 3;
    ZMap s = scratch;
    worst.assign(3, -INFINITY);     // each piece on its own
    credited.assign(3, -INFINITY);  // each cell credited to its lowest piece, as the kernel reports
    double any = -INFINITY;
    const double len = std::sqrt((b[0] - a[0]) * (b[0] - a[0]) + (b[1] - a[1]) * (b[1] - a[1]) + (b[2] - a[2]) * (b[2] - a[2]));
    const auto poses = static_cast<std::size_t>(std::max(1.0, std::ceil(len / check.step)));
    for (std::size_t i = 0; i <= poses; ++i) {
      const double t = static_cast<double>(i) / poses;
      const double px = a[0] + t * (b[0] - a[0]), py = a[1] + t * (b[1] - a[1]), pz = a[2] + t * (b[2] - a[2]);
      for (std::size_t j = 0; j < s.ny(); ++j)
        for (std::size_t ii = 0; ii < s.nx(); ++ii) {
          const double dx = s.cx(ii) - px, dy = s.cy(j) - py, d = std::hypot(dx, dy);
          double& zc = s.at(ii, j);
          if (d <= cutter.max_radius() && zc <= pz + check.flute_top) zc = std::min(zc, pz + cutter.height(d));
          if (d > 10.0 || zc <= pz + 5.0) continue;
          sampled.lowest(dx, dy, low);
          for (int p = 0; p < 3; ++p) worst[p] = std::max(worst[p], zc - (pz + low[p]));
          const auto owner = std::min_element(low.begin(), low.end()) - low.begin();
          credited[owner] = std::max(credited[owner], zc - (pz + low[owner]));
          any = std::max(any, zc - (pz + low[owner]));
        }
    }
    // The samples lie 0.005 mm apart on the meridian (well under a um of depth): the brute force is that much
    // shallower at most, never deeper. A cell counts for the piece lowest over it (where two are
    // about as low, sampling may credit the other: only the move's deepest and each piece's bounds compare).
    double kernel_any = -INFINITY;
    for (std::size_t p = 0; p < 3; ++p) {
      const BodyCollision* c = find(r.body_collisions, k, p);
      if (c) {
        kernel_any = std::max(kernel_any, c->depth);
        EXPECT_LE(c->depth, worst[p] + 1e-3) << "move " << k << " piece " << p;
        EXPECT_GE(c->depth, credited[p] - 1e-3) << "move " << k << " piece " << p;
      } else {
        EXPECT_LT(credited[p], 0.03) << "move " << k << " piece " << p;
      }
    }
    if (any > 0.05) {
      EXPECT_NEAR(kernel_any, any, 1e-3) << "move " << k;
      ++compared;
    } else if (any < -0.05) {
      EXPECT_EQ(kernel_any, -INFINITY) << "move " << k;
    }
    // The next move starts from the stock the exact cut left.
    tmm::ZMap next = scratch;
    cut3(next, cutter, {a[0], a[1], a[2], b[0], b[1], b[2]}, nullptr);
    scratch = next;
  }
  EXPECT_GE(compared, 2u);
}

TEST(BodyCheck, HeightsAreTheSameWithTheCheckAndCollisionsTheSameForAnySplit) {
  ZMap plain = block_stock(-5, 5, -5, 5, 30.0, 0.2);
  const std::vector<double> tips{-30, 14, -5, 30, 14, -5, 8, 0, 0, 8, -20, 2, -20, -3, 1};
  cut3(plain, Cutter(2.0, 1.0), tips, nullptr);
  const BodyCheck check = tool_bodies(0.5);
  std::vector<BodyCollision> first;
  for (const auto& [threads, rows] : {std::pair{1, 0}, std::pair{2, 7}, std::pair{3, 64}, std::pair{1, 1000}}) {
    ZMap z = block_stock(-5, 5, -5, 5, 30.0, 0.2);
    const tmm::SimReport r = cut3(z, Cutter(2.0, 1.0), tips, &check, threads, static_cast<std::size_t>(rows));
    EXPECT_EQ(z.heights(), plain.heights()) << threads << " threads, band " << rows;
    ASSERT_FALSE(r.body_collisions.empty());
    if (first.empty()) first = r.body_collisions;
    ASSERT_EQ(r.body_collisions.size(), first.size());
    for (std::size_t i = 0; i < first.size(); ++i) {
      EXPECT_EQ(r.body_collisions[i].move, first[i].move);
      EXPECT_EQ(r.body_collisions[i].piece, first[i].piece);
      EXPECT_EQ(r.body_collisions[i].depth, first[i].depth);  // (the cell among equally deep ones may differ)
    }
  }
}

TEST(BodyCheck, TiltedFrustumLowestPointMatchesAScanOfTheLine) {
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> U(-1.0, 1.0);
  int hits = 0;
  for (int trial = 0; trial < 400; ++trial) {
    Eigen::Vector3d a(0.7 * U(rng), 0.7 * U(rng), 1.0);
    a.normalize();
    const Eigen::Vector3d tip(U(rng), U(rng), U(rng));
    const double h0 = 5 + 3 * U(rng), h1 = h0 + 4 + 3 * U(rng), r0 = 3 + 2 * U(rng), r1 = 3 + 2.9 * U(rng);
    const double x = tip.x() + 8 * U(rng), y = tip.y() + 8 * U(rng);
    const double got = tmm::frustum_lowest(tip, a, h0, h1, r0, r1, x, y);
    // Scan z upwards in 1e-4 steps for the first point inside.
    double scan = INFINITY;
    for (double zz = tip.z() - 5; zz < tip.z() + 20; zz += 1e-4) {
      const Eigen::Vector3d q = Eigen::Vector3d(x, y, zz) - tip;
      const double h = q.dot(a), rho = (q - h * a).norm();
      if (h >= h0 && h <= h1 && rho <= r0 + (r1 - r0) * (h - h0) / (h1 - h0)) { scan = zz; break; }
    }
    if (std::isinf(scan)) {
      EXPECT_TRUE(std::isinf(got) || got > tip.z() + 19) << trial;
      continue;
    }
    ++hits;
    EXPECT_NEAR(got, scan, 2e-4) << trial;
  }
  EXPECT_GT(hits, 50);
}

TEST(BodyCheck, FiveAxisHolderOverTheBossAndTiltedAwayFromIt) {
  // The same pass as the 3-axis boss case with a vertical axis: a cylinder's enclosure is exact below its face,
  // 6 mm deep. Tilted 30 degrees away from the boss (about x, the spindle leaning to +y) the holder clears it.
  const tmm::TorusTool tool{0.0, 2.0, tmm::ToolShape::BullNose};
  const BodyCheck check = tool_bodies();
  const std::vector<double> tips{-30, 14, -5, 30, 14, -5};
  const std::vector<MoveKind> kinds{MoveKind::Cut};
  tmm::Sweep5Options o;
  o.max_step = 0.5;
  o.body_check = &check;
  ZMap z = block_stock(-5, 5, -5, 5, 30.0);
  const std::vector<double> up{0, 0, 1, 0, 0, 1};
  tmm::SimReport r = tmm::cut_5axis(z, tool, tips.data(), up.data(), kinds.data(), 2, o, {});
  ASSERT_EQ(r.body_collisions.size(), 1u);
  EXPECT_EQ(r.body_collisions[0].piece, 1u);
  EXPECT_NEAR(r.body_collisions[0].depth, 6.0, 1e-6);
  const double s = std::sin(30 * M_PI / 180), c = std::cos(30 * M_PI / 180);
  const std::vector<double> away{0, s, c, 0, s, c};
  ZMap z2 = block_stock(-5, 5, -5, 5, 30.0);
  r = tmm::cut_5axis(z2, tool, tips.data(), away.data(), kinds.data(), 2, o, {});
  EXPECT_TRUE(r.body_collisions.empty());
  // Tilted towards it, deeper than upright.
  const std::vector<double> toward{0, -s, c, 0, -s, c};
  ZMap z3 = block_stock(-5, 5, -5, 5, 30.0);
  r = tmm::cut_5axis(z3, tool, tips.data(), toward.data(), kinds.data(), 2, o, {});
  ASSERT_FALSE(r.body_collisions.empty());
  EXPECT_GT(r.body_collisions.back().depth, 6.0);
  // Heights are the same with and without the check.
  ZMap plain = block_stock(-5, 5, -5, 5, 30.0);
  o.body_check = nullptr;
  tmm::cut_5axis(plain, tool, tips.data(), toward.data(), kinds.data(), 2, o, {});
  EXPECT_EQ(plain.heights(), z3.heights());
}

// The grown tilted bodies sampled on their surface (rings about the axis in the tool's frame), each sample's
// clearance ball met by the vertical line: the exact grown body's lowest point, to sampling accuracy.
double sampled_lowest_tilted(const ToolBody& b, const Eigen::Vector3d& tip, const Eigen::Vector3d& a, double x,
                             double y, double ds = 0.05) {
  const Eigen::Vector3d u = a.unitOrthogonal(), v = a.cross(u);
  double best = INFINITY;
  auto ring = [&](double h, double r) {
    const int n = std::max(1, static_cast<int>(std::ceil(2 * M_PI * r / ds)));
    for (int i = 0; i < n; ++i) {
      const double t = 2 * M_PI * i / n;
      const Eigen::Vector3d q = tip + h * a + r * (std::cos(t) * u + std::sin(t) * v);
      const double e2 = (q.x() - x) * (q.x() - x) + (q.y() - y) * (q.y() - y);
      if (e2 <= b.clearance * b.clearance) best = std::min(best, q.z() - std::sqrt(b.clearance * b.clearance - e2));
    }
  };
  const int nh = static_cast<int>(std::ceil((b.z1 - b.z0) / ds));
  for (int i = 0; i <= nh; ++i) ring(b.z0 + (b.z1 - b.z0) * i / nh, b.r0 + (b.r1 - b.r0) * i / nh);
  for (double r = 0.0; r < b.r0; r += ds) ring(b.z0, r);
  for (double r = 0.0; r < b.r1; r += ds) ring(b.z1, r);
  return best;
}

TEST(BodyCheck, FiveAxisEnclosureIsConservativeAgainstTheSampledGrownBody) {
  // A tilted pass beside a boss that only the holder cone reaches (the torus and its endless shank stay off it,
  // so the stock does not change during the move): the kernel's depth is never below the sampled grown body's
  // and above it by at most what the enclosure adds (c (1 + |dr/dh|) sideways, c down the axis).
  BodyCheck check;
  check.bodies = {{10.0, 20.0, 1.5, 1.5, 0.5}, {20.0, 28.0, 6.0, 12.0, 1.0}};
  ZMap z = block_stock(4, 9, -3, 3, 19.0, 0.5);
  const std::vector<double> tips{-3, -8, 1, -3, 8, 1};  // the tilted ball's lowest point is below its tip
  const std::vector<MoveKind> kinds{MoveKind::Cut};
  const double tilt = 15 * M_PI / 180;
  const Eigen::Vector3d axis(std::sin(tilt), 0.0, std::cos(tilt));
  const std::vector<double> axes{axis.x(), 0, axis.z(), axis.x(), 0, axis.z()};
  tmm::Sweep5Options o;
  o.max_step = 0.5;
  o.body_check = &check;
  const ZMap before = z;
  const tmm::SimReport r = tmm::cut_5axis(z, tmm::TorusTool{0.0, 2.0, tmm::ToolShape::BullNose}, tips.data(),
                                          axes.data(), kinds.data(), 2, o, {});
  EXPECT_EQ(z.heights(), before.heights());  // the tool itself cut nothing
  const BodyCollision* holder = find(r.body_collisions, 0, 1);
  ASSERT_NE(holder, nullptr);
  // The brute force over the same instances (the tip every 0.5 mm: the kernel's sub-steps for a fixed axis).
  double brute = -INFINITY;
  for (int step = 0; step <= 32; ++step) {
    const Eigen::Vector3d tip(-3.0, -8.0 + 0.5 * step, 1.0);
    for (std::size_t j = 0; j < z.ny(); ++j)
      for (std::size_t i = 0; i < z.nx(); ++i) {
        if (z.at(i, j) < 18.0) continue;
        brute = std::max(brute, z.at(i, j) - sampled_lowest_tilted(check.bodies[1], tip, axis, z.cx(i), z.cy(j), 0.1));
      }
  }
  ASSERT_GT(brute, 0.5);
  EXPECT_GE(holder->depth, brute - 5e-3);  // the samples' sag: the brute force is at most that shallow
  const double k = (12.0 - 6.0) / 8.0;
  EXPECT_LE(holder->depth, brute + 1.0 * (1.0 + k) * 2.0);
}

TEST(BodyCheck, RefusesBadChecksNamingTheValue) {
  ZMap z = block_stock(-5, 5, -5, 5, 30.0);
  auto message = [&](BodyCheck b) {
    try {
      cut3(z, Cutter(2.0, 0.0), {0, 0, 0, 1, 0, 0}, &b);
    } catch (const std::invalid_argument& e) {
      return std::string(e.what());
    }
    return std::string("no error");
  };
  BodyCheck b = tool_bodies();
  b.flute_top = -1;
  EXPECT_NE(message(b).find("flute_top"), std::string::npos);
  b = tool_bodies();
  b.step = NAN;
  EXPECT_NE(message(b).find("step"), std::string::npos);
  b = tool_bodies();
  b.bodies[1].z0 = 10;  // overlaps the shank
  EXPECT_NE(message(b), "no error");
  b = tool_bodies();
  b.step = 1e-10;
  EXPECT_NE(message(b).find("poses"), std::string::npos);
}

}  // namespace
