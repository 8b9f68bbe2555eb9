// The exact 3-axis sweep against closed forms (cusps, holes) and an independent brute force (the tool
// stamped at 200000 instants per move with nothing but h(rho)); rapids, threads, bands, cancel, refusals.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <random>
#include <stdexcept>
#include <string>
#include <vector>

#include "tmm/sim/sweep3.hpp"

namespace {

using tmm::Cutter;
using tmm::MoveKind;
using tmm::ZMap;

constexpr double kDeg = M_PI / 180.0;
constexpr double kTop = 100.0;

tmm::SimReport cut(ZMap& z, const Cutter& c, const std::vector<double>& tips, const std::vector<MoveKind>& kinds,
                   int threads = 1, std::size_t band_rows = 0, double tol = 1e-3) {
  tmm::Sweep3Options o;
  o.collision_tol = tol;
  o.band_rows = band_rows;
  tmm::BatchOptions b;
  b.threads = threads;
  return tmm::cut_3axis(z, c, tips.data(), kinds.data(), tips.size() / 3, o, b);
}

// The tool at N + 1 instants t = i / N of the move a -> b over the point (x, y): the lowest stamp, and a lower
// bound of the exact minimum (the minimiser lies within a sample of the best one and the function is convex,
// so the slopes of the neighbouring secants bound how far below the best sample it can be).
struct Brute {
  double best = INFINITY, lower = INFINITY;
};

Brute brute_force(const Cutter& c, const double* a, const double* b, double x, double y, int N = 200000) {
  const double R = c.max_radius();
  auto f = [&](long i) -> double {
    if (i < 0 || i > N) return INFINITY;
    const double t = static_cast<double>(i) / N;
    const double px = a[0] + t * (b[0] - a[0]), py = a[1] + t * (b[1] - a[1]), pz = a[2] + t * (b[2] - a[2]);
    const double rho = std::hypot(x - px, y - py);
    return rho <= R ? pz + c.height(rho) : INFINITY;
  };
  Brute r;
  long arg = -1;
  for (long i = 0; i <= N; ++i) {
    const double v = f(i);
    if (v < r.best) r.best = v, arg = i;
  }
  if (arg < 0) return r;
  double gap = 0.0;
  for (const long d : {-2L, -1L, 1L, 2L}) {
    const double near = f(arg + (d < 0 ? d + 1 : d - 1)), far = f(arg + d);
    if (std::isfinite(far) && std::isfinite(near)) gap = std::max(gap, std::fabs(far - near));
  }
  r.lower = r.best - 2.0 * gap;
  return r;
}

double seg_dist(const double* a, const double* b, double x, double y) {
  const double dx = b[0] - a[0], dy = b[1] - a[1], L2 = dx * dx + dy * dy;
  const double t = L2 > 0 ? std::clamp(((x - a[0]) * dx + (y - a[1]) * dy) / L2, 0.0, 1.0) : 0.0;
  return std::hypot(x - a[0] - t * dx, y - a[1] - t * dy);
}

struct Agreement {
  double above = -INFINITY;  // max of kernel - best stamp: the kernel is never above the sampled tool
  double below = -INFINITY;  // max of lower bound - kernel: the kernel is never below the exact envelope
  double tight = 0.0;        // max |kernel - best| where the brute force itself is within 1e-10
  int cells = 0;
};

// One move into a fresh stock at kTop, every cell against the brute force.
Agreement against_brute_force(const Cutter& c, const std::vector<double>& move) {
  const double* a = move.data();
  const double* b = a + 3;
  const double R = c.max_radius(), cell = 0.61;
  const double x0 = std::min(a[0], b[0]) - R - 1.013, y0 = std::min(a[1], b[1]) - R - 0.977;
  const auto nx = static_cast<std::size_t>((std::max(a[0], b[0]) + R + 1 - x0) / cell) + 1;
  const auto ny = static_cast<std::size_t>((std::max(a[1], b[1]) + R + 1 - y0) / cell) + 1;
  ZMap z(x0, y0, cell, nx, ny, kTop);
  cut(z, c, move, {MoveKind::Cut});
  Agreement g;
  for (std::size_t j = 0; j < ny; ++j) {
    for (std::size_t i = 0; i < nx; ++i) {
      const double x = z.cx(i), y = z.cy(j), k = z.at(i, j);
      const double d = seg_dist(a, b, x, y);
      if (d > R + 1e-9) {
        EXPECT_EQ(k, kTop) << "beyond the reach at " << x << ", " << y;
        continue;
      }
      const Brute br = brute_force(c, a, b, x, y);
      if (!std::isfinite(br.best)) {  // the reach crosses the move between two instants
        if (d < R - 1e-6) ADD_FAILURE() << "no stamp within " << R - d << " of the reach at " << x << ", " << y;
        continue;
      }
      ++g.cells;
      g.above = std::max(g.above, k - br.best);
      g.below = std::max(g.below, br.lower - k);
      if (br.best - br.lower < 1e-10) g.tight = std::max(g.tight, std::fabs(k - br.best));
    }
  }
  return g;
}

void expect_agreement(const Cutter& c, const std::vector<double>& move, const std::string& what) {
  const Agreement g = against_brute_force(c, move);
  if (std::getenv("TMM_SWEEP3_VERBOSE"))
    std::printf("%-34s cells %4d  above %9.2e  below %9.2e  tight %9.2e\n", what.c_str(), g.cells, g.above, g.below,
                g.tight);
  EXPECT_GT(g.cells, 20) << what;
  EXPECT_LE(g.above, tmm::kSweep3Tolerance) << what;
  EXPECT_LE(g.below, tmm::kSweep3Tolerance) << what;
  EXPECT_LE(g.tight, tmm::kSweep3Tolerance + 1e-10) << what;
}

struct Family {
  std::string name;
  Cutter cutter;
};

std::vector<Family> families() {
  return {
      {"flat", Cutter(3.0, 0.0)},
      {"ball", Cutter(3.0, 3.0)},
      {"bull", Cutter(3.0, 1.0)},
      {"apt cone+arc+taper", Cutter::apt(3.0, 0.5, 10.0, 10 * kDeg, 5 * kDeg)},
      {"apt negative taper", Cutter::apt(3.0, 0.5, 10.0, 10 * kDeg, -5 * kDeg)},
      {"apt sharp cone+taper", Cutter::apt(3.0, 0.0, 10.0, 30 * kDeg, 10 * kDeg)},
  };
}

TEST(Sweep3, RampsForEveryCutterFamilyMatchTheBruteForce) {
  // Oblique in XY, gentle and steep (steeper than the cones and the taper), descending and ascending.
  const std::vector<std::vector<double>> ramps = {
      {-2.0, -1.3, 1.0, 2.5, 1.7, -0.5},
      {2.5, 1.7, -0.5, -2.0, -1.3, 1.0},
      {-1.0, 0.4, 2.0, 0.8, -0.3, -3.5},
      {0.8, -0.3, -3.5, -1.0, 0.4, 2.0},
  };
  for (const Family& f : families()) {
    EXPECT_EQ(f.cutter.kind() == tmm::CutterKind::General, f.name.rfind("apt", 0) == 0) << f.name;
    for (std::size_t k = 0; k < ramps.size(); ++k) expect_agreement(f.cutter, ramps[k], f.name + " ramp " + std::to_string(k));
  }
}

TEST(Sweep3, RandomMovesMatchTheBruteForce) {
  std::mt19937 rng(12);
  std::uniform_real_distribution<double> xy(-3, 3), len(0, 5), ang(0, 2 * M_PI), slope(-4, 4), z(-1, 1);
  const std::vector<Family> fams = families();
  for (int k = 0; k < 12; ++k) {
    const Family& f = fams[static_cast<std::size_t>(k) % fams.size()];
    const double x0 = xy(rng), y0 = xy(rng), z0 = z(rng), L = k % 5 == 4 ? 0.0 : len(rng), a = ang(rng);
    const double dz = L > 0 ? slope(rng) * L : -2.0;  // every fifth a plunge
    expect_agreement(f.cutter, {x0, y0, z0, x0 + L * std::cos(a), y0 + L * std::sin(a), z0 + dz},
                     f.name + " random move " + std::to_string(k));
  }
}

TEST(Sweep3, BallRasterLeavesTheCuspHeight) {
  const double R = 3.0, s = 0.5, cell = 0.25;
  // Centres at y = j * 0.25: on every pass (y = 0.5 k) and every cusp line between them.
  ZMap z(-10.125, -0.125, cell, 81, 41, 1.0);
  std::vector<double> tips;
  std::vector<MoveKind> kinds;
  for (int p = 0; p <= 20; ++p) {  // passes along x in short moves of 0.3 mm, zig-zag
    const double y = s * p;
    for (int i = 0; i <= 60; ++i) {
      const double x = (p % 2 == 0) ? -9.0 + 0.3 * i : 9.0 - 0.3 * i;
      tips.insert(tips.end(), {x, y, 0.0});
    }
  }
  kinds.assign(tips.size() / 3 - 1, MoveKind::Cut);
  const tmm::SimReport r = cut(z, Cutter(R, R), tips, kinds);
  EXPECT_EQ(r.moves_cut, kinds.size());
  const double cusp = R - std::sqrt(R * R - s * s / 4);
  for (std::size_t j = 12; j <= 28; ++j) {
    for (std::size_t i = 20; i <= 60; ++i) {
      const double y = z.cy(j), off = std::fabs(std::remainder(y, s));
      const double want = R - std::sqrt(R * R - off * off);
      EXPECT_NEAR(z.at(i, j), want, 1e-9) << i << ", " << j;
      if (j % 2 == 1) {
        EXPECT_NEAR(z.at(i, j), cusp, 1e-9);
      } else {
        EXPECT_NEAR(z.at(i, j), 0.0, 1e-12);
      }
    }
  }
}

TEST(Sweep3, BullNoseOnAPlaneLeavesTheTorusCusp) {
  const double R = 3.0, r = 1.0, e = R - r, s = 5.0;  // s / 2 > e: the corner arc leaves the cusp
  ZMap z(-10.125, -10.125, 0.25, 81, 81, 5.0);
  std::vector<double> tips;
  for (int p = -2; p <= 2; ++p) tips.insert(tips.end(), {p % 2 ? 9.0 : -9.0, s * p, 0.0, p % 2 ? -9.0 : 9.0, s * p, 0.0});
  std::vector<MoveKind> kinds;
  for (std::size_t k = 0; k + 1 < tips.size() / 3; ++k) kinds.push_back(k % 2 ? MoveKind::Jump : MoveKind::Cut);
  cut(z, Cutter(R, r), tips, kinds);
  auto torus = [&](double q) { return q <= e ? 0.0 : r - std::sqrt(r * r - (q - e) * (q - e)); };
  for (std::size_t j = 0; j < 81; ++j) {
    const double y = z.cy(j), off = std::fabs(std::remainder(y, s));
    if (std::fabs(y) > 8.0) continue;
    for (std::size_t i = 30; i <= 50; ++i) EXPECT_NEAR(z.at(i, j), torus(off), 1e-9) << y;
  }
  EXPECT_NEAR(z.at(40, 50), torus(2.5), 1e-12);  // y = 2.5: on the cusp line
  EXPECT_NEAR(torus(2.5), 1.0 - std::sqrt(0.75), 1e-15);
}

TEST(Sweep3, FlatPlungeLeavesAFlatBottomedHoleOfTheToolRadius) {
  const double R = 2.02;  // no centre at exactly R
  ZMap z(-5, -5, 0.2, 50, 50, 0.0);
  const double cx = 0.1, cy = 0.1;  // a cell centre: the plunge ends exactly on it
  const tmm::SimReport r = cut(z, Cutter(R, 0.0), {cx, cy, 5.0, cx, cy, -1.5}, {MoveKind::Cut});
  std::size_t inside = 0;
  for (std::size_t j = 0; j < 50; ++j)
    for (std::size_t i = 0; i < 50; ++i) {
      const double d = std::hypot(z.cx(i) - cx, z.cy(j) - cy);
      if (d <= R) {
        EXPECT_EQ(z.at(i, j), -1.5);
        ++inside;
      } else {
        EXPECT_EQ(z.at(i, j), 0.0);
      }
    }
  EXPECT_EQ(r.cells_lowered, inside);
  EXPECT_NEAR(static_cast<double>(inside) * 0.04, M_PI * R * R, 0.5);
}

TEST(Sweep3, BallPlungeAndZeroLengthMoveStampTheProfile) {
  const double R = 1.5;
  const Cutter ball(R, R);
  for (const double top_of_move : {3.0, -0.7}) {  // a plunge, then no motion at all
    ZMap z(-2, -2, 0.1, 40, 40, 1.0);
    cut(z, ball, {0.05, 0.05, top_of_move, 0.05, 0.05, -0.7}, {MoveKind::Cut});
    for (std::size_t j = 0; j < 40; ++j)
      for (std::size_t i = 0; i < 40; ++i) {
        const double rho = std::hypot(z.cx(i) - 0.05, z.cy(j) - 0.05);
        const double want = rho <= R ? std::min(1.0, -0.7 + R - std::sqrt(R * R - rho * rho)) : 1.0;
        EXPECT_NEAR(z.at(i, j), want, 1e-12) << rho;
      }
  }
}

TEST(Sweep3, HeightsOnlyDecreaseAndCellsLoweredCountsThem) {
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> u(0, 10), h(-1, 1);
  ZMap z(0, 0, 0.1, 100, 100, 0.0);
  for (std::size_t k = 0; k < z.heights().size(); ++k) z.heights()[k] = 0.3 * std::sin(0.37 * k);
  const std::vector<double> before = z.heights();
  std::vector<double> tips;
  for (int k = 0; k < 40; ++k) tips.insert(tips.end(), {u(rng), u(rng), h(rng)});
  std::vector<MoveKind> kinds(39, MoveKind::Cut);
  const tmm::SimReport r = cut(z, Cutter::apt(1.0, 0.2, 5.0, 5 * kDeg, 3 * kDeg), tips, kinds, 2);
  std::size_t lowered = 0;
  for (std::size_t k = 0; k < before.size(); ++k) {
    EXPECT_LE(z.heights()[k], before[k]);
    lowered += z.heights()[k] < before[k];
  }
  EXPECT_EQ(r.cells_lowered, lowered);
  EXPECT_GT(lowered, 100u);
  EXPECT_EQ(r.moves_cut, 39u);
  // A second pass over the same path lowers nothing.
  EXPECT_EQ(cut(z, Cutter::apt(1.0, 0.2, 5.0, 5 * kDeg, 3 * kDeg), tips, kinds).cells_lowered, 0u);
}

TEST(Sweep3, RapidsThroughTheStockAreCollisionsWithTheirDepth) {
  const Cutter flat(1.0, 0.0), ball(1.0, 1.0);
  const std::vector<double> tips = {
      -4, -4, 2.0,    //
      -4, 0, 2.0,     // 0: rapid above the stock
      -3, 0, -0.5,    // 1: cut down into the stock
      3, 0, -0.5,     // 2: cut a slot along y = 0
      3, 0, 1.0,      // 3: rapid retract out of the slot: removes nothing
      3, 3, 1.0,      // 4: rapid above
      3, 3, -0.25,    // 5: rapid plunge into the stock: 0.25 deep
      -3, 3, -0.75,   // 6: jump (through the stock, but not simulated)
      -3, 3, 1.0,     // 7: rapid up from inside the stock: 0.75
      -2, 0, 1.0,     // 8: rapid above
      -2, 0, -0.6,    // 9: rapid into the slot already cut to -0.5: removes 0.1
  };
  const std::vector<MoveKind> kinds = {MoveKind::Rapid, MoveKind::Cut,  MoveKind::Cut,   MoveKind::Rapid,
                                       MoveKind::Rapid, MoveKind::Rapid, MoveKind::Jump, MoveKind::Rapid,
                                       MoveKind::Rapid, MoveKind::Rapid};
  for (const Cutter& c : {flat, ball}) {
    ZMap z(-5.05, -5.05, 0.1, 101, 101, 0.0);  // centres on multiples of 0.1
    const tmm::SimReport r = cut(z, c, tips, kinds, 2, 7, 0.05);
    EXPECT_EQ(r.moves_cut, 9u);
    ASSERT_EQ(r.collisions.size(), 3u);
    EXPECT_EQ(r.collisions[0].move, 5u);
    EXPECT_NEAR(r.collisions[0].depth, 0.25, 1e-12);
    EXPECT_EQ(r.collisions[1].move, 7u);
    EXPECT_NEAR(r.collisions[1].depth, 0.75, 1e-12);
    EXPECT_EQ(r.collisions[2].move, 9u);
    EXPECT_NEAR(r.collisions[2].depth, 0.1, 1e-9);
    // The slot is there, the jump cut nothing (its middle is untouched).
    EXPECT_NEAR(z.at(50, 50), -0.5, 1e-12);
    EXPECT_EQ(z.at(50, 80), 0.0);
    // With a tolerance above 0.1 the last rapid is no collision; with none, the retract of move 3 is none
    // either (it only re-traces the tool already there).
    ZMap z2(-5.05, -5.05, 0.1, 101, 101, 0.0);
    const tmm::SimReport r2 = cut(z2, c, tips, kinds, 1, 0, 0.11);
    ASSERT_EQ(r2.collisions.size(), 2u);
    EXPECT_EQ(r2.collisions[1].move, 7u);
    ZMap z3(-5.05, -5.05, 0.1, 101, 101, 0.0);
    for (const tmm::RapidCollision& k : cut(z3, c, tips, kinds, 1, 0, 1e-12).collisions)
      EXPECT_TRUE(k.move == 5 || k.move == 7 || k.move == 9) << k.move << " " << k.depth;
  }
}

TEST(Sweep3, JumpMovesChangeNothing) {
  ZMap z(-5, -5, 0.1, 100, 100, 0.0);
  const tmm::SimReport r = cut(z, Cutter(2.0, 1.0), {-3, 0, -1, 3, 0, -1, 3, 3, -2}, {MoveKind::Jump, MoveKind::Jump});
  EXPECT_EQ(r.moves_cut, 0u);
  EXPECT_EQ(r.cells_lowered, 0u);
  for (const double h : z.heights()) EXPECT_EQ(h, 0.0);
}

TEST(Sweep3, BitIdenticalForAnyThreadCountAndBandSplit) {
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> u(-1, 21), h(-2, 1);
  std::vector<double> tips;
  for (int k = 0; k < 100; ++k) tips.insert(tips.end(), {u(rng), u(rng), h(rng)});
  std::vector<MoveKind> kinds(99, MoveKind::Cut);
  for (std::size_t k = 0; k < kinds.size(); k += 7) kinds[k] = MoveKind::Rapid;
  for (const Cutter& c : {Cutter(1.5, 1.5), Cutter(2.0, 0.6), Cutter::apt(2.0, 0.3, 8.0, 8 * kDeg, 4 * kDeg)}) {
    std::vector<double> first;
    tmm::SimReport first_report;
    for (const auto& [threads, band] : std::vector<std::pair<int, std::size_t>>{{1, 0}, {2, 0}, {2, 1}, {1, 3}, {2, 17}, {2, 1000}}) {
      ZMap z(0, 0, 0.1, 201, 199, 0.5);
      const tmm::SimReport r = cut(z, c, tips, kinds, threads, band);
      if (first.empty()) {
        first = z.heights();
        first_report = r;
        continue;
      }
      EXPECT_EQ(std::memcmp(first.data(), z.heights().data(), first.size() * sizeof(double)), 0)
          << threads << " threads, " << band << " rows a band";
      EXPECT_EQ(r.cells_lowered, first_report.cells_lowered);
      ASSERT_EQ(r.collisions.size(), first_report.collisions.size());
      for (std::size_t k = 0; k < r.collisions.size(); ++k) {
        EXPECT_EQ(r.collisions[k].move, first_report.collisions[k].move);
        EXPECT_EQ(r.collisions[k].depth, first_report.collisions[k].depth);
      }
    }
    EXPECT_GT(first_report.collisions.size(), 5u);
  }
}

TEST(Sweep3, ProgressReturningFalseCancels) {
  ZMap z(0, 0, 0.1, 200, 200, 0.0);
  const std::vector<double> tips = {1, 1, -1, 19, 19, -1};
  tmm::BatchOptions b;
  b.threads = 2;
  int calls = 0;
  b.progress = [&](double f) {
    ++calls;
    EXPECT_GE(f, 0.0);
    EXPECT_LE(f, 1.0);
    return false;
  };
  const MoveKind kinds[] = {MoveKind::Cut};
  EXPECT_THROW(tmm::cut_3axis(z, Cutter(1, 1), tips.data(), kinds, 2, {}, b), tmm::Cancelled);
  EXPECT_GE(calls, 1);
  b.progress = [](double) { return true; };
  EXPECT_NO_THROW(tmm::cut_3axis(z, Cutter(1, 1), tips.data(), kinds, 2, {}, b));
}

std::string refusal(const std::vector<double>& tips, const std::vector<MoveKind>& kinds, double tol = 1e-3) {
  ZMap z(0, 0, 1, 10, 10, 0.0);
  try {
    cut(z, Cutter(1, 1), tips, kinds, 1, 0, tol);
  } catch (const std::invalid_argument& e) {
    for (const double h : z.heights()) EXPECT_EQ(h, 0.0);  // refused before cutting
    return e.what();
  }
  return "";
}

TEST(Sweep3, RefusesBadInputNamingIt) {
  const std::vector<MoveKind> two = {MoveKind::Cut, MoveKind::Cut};
  EXPECT_NE(refusal({1, 1, 0, 2, 2, NAN, 3, 3, 0}, two).find("tip 1"), std::string::npos);
  EXPECT_NE(refusal({1, 1, 0, 2, 2, 0, INFINITY, 3, 0}, two).find("tip 2"), std::string::npos);
  EXPECT_NE(refusal({1, 1, 0, 2, 2, 0, 3, 3, 0}, {MoveKind::Cut, static_cast<MoveKind>(7)}).find("move 1 is 7"),
            std::string::npos);
  EXPECT_NE(refusal({1, 1, 0, 2, 2, 0}, {MoveKind::Cut}, -1.0).find("collision_tol"), std::string::npos);
  EXPECT_NE(refusal({1, 1, 0, 2, 2, 0}, {MoveKind::Cut}, NAN).find("collision_tol"), std::string::npos);
  // No moves: nothing to do.
  ZMap z(0, 0, 1, 10, 10, 0.0);
  tmm::BatchOptions b;
  EXPECT_EQ(tmm::cut_3axis(z, Cutter(1, 1), nullptr, nullptr, 0, {}, b).moves_cut, 0u);
  const double one[] = {5, 5, -1};
  EXPECT_EQ(tmm::cut_3axis(z, Cutter(1, 1), one, nullptr, 1, {}, b).cells_lowered, 0u);
}

TEST(Sweep3, MovesOutsideTheGridOrAboveTheStockCutNothing) {
  ZMap z(0, 0, 0.5, 20, 20, 0.0);
  const tmm::SimReport r = cut(z, Cutter(1, 0.5), {-50, -50, -5, -40, 60, -5, 5, 5, 0.0, 8, 8, 3.0},
                               {MoveKind::Cut, MoveKind::Jump, MoveKind::Cut});
  EXPECT_EQ(r.moves_cut, 2u);
  EXPECT_EQ(r.cells_lowered, 0u);
}

}  // namespace
