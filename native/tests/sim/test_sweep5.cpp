// 5-axis z-map simulation (tmm/sim/sweep5.hpp) against independent references:
//  - lowest_on_vertical vs the vertical line scanned every 1e-4 mm and bisected on the sign of
//    tmm::tool_distance (the kernel's signed distance to the same solid), random tilted poses of both shapes,
//    balls, near-tangent lines and lines through the round insert's hollow;
//  - sweeps vs closed forms (a vertical tool on a plane: the discrete cusp of the closed-form profile) and
//    vs the tool stamped densely (100000 instants), and the stated error bound s^2 / (8 Ri) / cos(slope);
//  - rapids, jumps, determinism over thread counts, cancel, refusal of bad input.
#include <gtest/gtest.h>

#include <Eigen/Geometry>

#include <algorithm>
#include <cmath>
#include <functional>
#include <limits>
#include <random>
#include <string>
#include <vector>

#include "tmm/cutter/torus_tool.hpp"
#include "tmm/sim/sweep5.hpp"

namespace {

using Eigen::Vector3d;
using tmm::MoveKind;
using tmm::TorusTool;
using tmm::ToolShape;
using tmm::ZMap;

constexpr double kInf = std::numeric_limits<double>::infinity();
constexpr double kDeg = M_PI / 180.0;

Vector3d tilted(double beta_deg, double azimuth_deg) {
  const double b = beta_deg * kDeg, c = azimuth_deg * kDeg;
  return {std::sin(b) * std::cos(c), std::sin(b) * std::sin(c), std::cos(b)};
}

TorusTool make_tool(double Ro, double Ri, ToolShape shape) {
  TorusTool t;
  t.Ro = Ro;
  t.Ri = Ri;
  t.shape = shape;
  return t;
}

// Independent lowest point: scan the line upwards every 1e-4 mm for the first point inside the solid
// (tool_distance <= 0), then bisect on the sign; +inf if none up to zhi.
double brute_lowest(const TorusTool& tool, const Vector3d& tip, const Vector3d& a, double x, double y, double zlo,
                    double zhi) {
  auto inside = [&](double z) { return tmm::tool_distance(tool, tip, a, Vector3d(x, y, z)) <= 0.0; };
  if (inside(zlo)) return -kInf;
  for (double z = zlo + 1e-4; z <= zhi; z += 1e-4) {
    if (!inside(z)) continue;
    double lo = z - 1e-4, hi = z;
    for (int i = 0; i < 60; ++i) {
      const double mid = 0.5 * (lo + hi);
      (inside(mid) ? hi : lo) = mid;
    }
    return hi;
  }
  return kInf;
}

struct Compare {
  int lines = 0, hits = 0, touching = 0;
};

// Checks one line: equal to 1e-6 mm, or a near-tangent line (the kernel counts a line within 1e-7 mm of the
// tool as touching it: then its point is within that of the solid, and a later point of the same skim lies
// on a segment that stays that close).
void compare_line(const TorusTool& tool, const Vector3d& tip, const Vector3d& a, double x, double y, Compare& c) {
  const Vector3d C = tip + tool.Ri * a;
  const double zlo = C.z() - tool.radius() - 0.01, zhi = C.z() + 25.0;
  const double ze = tmm::lowest_on_vertical(tool, tip, a, x, y);
  const double zb = brute_lowest(tool, tip, a, x, y, zlo, zhi);
  ASSERT_GT(zb, -kInf);
  ++c.lines;
  auto dist = [&](double z) { return tmm::tool_distance(tool, tip, a, Vector3d(x, y, z)); };
  const double ze_capped = ze < zhi ? ze : kInf;
  if (std::isinf(zb) && std::isinf(ze_capped)) return;
  if (std::isfinite(zb)) ++c.hits;
  if (std::isfinite(zb) && std::isfinite(ze_capped) && std::abs(ze - zb) <= 1e-6) return;
  ASSERT_TRUE(std::isfinite(ze_capped)) << "kernel misses a line the solid meets at z = " << zb << " (x " << x
                                        << ", y " << y << ")";
  if (!std::isfinite(zb) || ze < zb) {
    ASSERT_LE(std::abs(dist(ze)), 2e-7) << "kernel " << ze << " below the solid, brute " << zb << " x " << x << " y " << y;
  } else {
    for (int k = 0; k <= 100; ++k) {
      const double z = zb + (ze - zb) * k / 100.0;
      ASSERT_LE(std::abs(dist(z)), 2e-7) << "kernel " << ze << " above the lowest point " << zb << " x " << x << " y " << y;
    }
  }
  ++c.touching;
}

TEST(Sweep5Lowest, MatchesBruteForceOnRandomTiltedPoses) {
  std::mt19937_64 rng(20240);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  const std::vector<TorusTool> tools = {
      make_tool(6.7, 6.0, ToolShape::RoundInsert), make_tool(6.7, 6.0, ToolShape::BullNose),
      make_tool(0.0, 5.0, ToolShape::RoundInsert), make_tool(0.0, 5.0, ToolShape::BullNose),
      make_tool(2.0, 3.0, ToolShape::RoundInsert), make_tool(4.0, 1.5, ToolShape::BullNose)};
  Compare c;
  for (const TorusTool& tool : tools) {
    for (int pose = 0; pose < 6; ++pose) {
      const double beta = pose == 0 ? 0.0 : 40.0 * u(rng), az = 360.0 * u(rng);
      const Vector3d a = tilted(beta, az);
      const Vector3d tip(10.0 * u(rng) - 5.0, 10.0 * u(rng) - 5.0, 3.0 * u(rng));
      const Vector3d C = tip + tool.Ri * a;
      const double Rt = tool.radius();
      for (int k = 0; k < 12; ++k) {  // random lines over the footprint and a little beyond (the shank uphill)
        const double r = (Rt + 3.0) * std::sqrt(u(rng)), phi = 2 * M_PI * u(rng);
        compare_line(tool, tip, a, C.x() + r * std::cos(phi), C.y() + r * std::sin(phi), c);
      }
      // Near the outer silhouette (away from the shank's lean): where the lines start to miss.
      for (int k = 0; k < 2; ++k) {
        const double psi = (az + 180.0 + 150.0 * (u(rng) - 0.5)) * kDeg;
        auto hits = [&](double r) {
          return tmm::lowest_on_vertical(tool, tip, a, C.x() + r * std::cos(psi), C.y() + r * std::sin(psi)) <
                 C.z() + 25.0;
        };
        double lo = 0.0, hi = Rt + 1.0;
        ASSERT_TRUE(hits(lo));
        ASSERT_FALSE(hits(hi));
        for (int i = 0; i < 80; ++i) (hits(0.5 * (lo + hi)) ? lo : hi) = 0.5 * (lo + hi);
        for (double d : {-1e-3, -1e-5, -1e-7, 1e-7, 1e-5, 1e-3}) {
          compare_line(tool, tip, a, C.x() + (lo + d) * std::cos(psi), C.y() + (lo + d) * std::sin(psi), c);
        }
      }
      // Through the hollow and the inner tube (round insert, Ro > Ri: rho < Ro - Ri is open below h = 0).
      if (tool.shape == ToolShape::RoundInsert && tool.Ro > tool.Ri) {
        for (int k = 0; k < 8; ++k) {
          const double r = 2.0 * (tool.Ro - tool.Ri) * u(rng), phi = 2 * M_PI * u(rng);
          compare_line(tool, tip, a, C.x() + r * std::cos(phi), C.y() + r * std::sin(phi), c);
        }
      }
    }
  }
  EXPECT_GT(c.hits, 400);
  EXPECT_LT(c.touching, c.lines / 10);  // tolerance cases stay the exception
}

TEST(Sweep5Lowest, ClosedFormsOfTheVerticalTool) {
  const TorusTool ri = make_tool(6.7, 6.0, ToolShape::RoundInsert), bn = make_tool(6.7, 6.0, ToolShape::BullNose);
  const Vector3d tip(3.0, -2.0, 10.0), z(0, 0, 1);
  // The hollow centre is closed by the body at the centre plane; the bull nose is flat there.
  EXPECT_NEAR(tmm::lowest_on_vertical(ri, tip, z, 3.0, -2.0), 16.0, 1e-12);
  EXPECT_NEAR(tmm::lowest_on_vertical(ri, tip, z, 3.3, -2.0), 16.0, 1e-12);
  EXPECT_NEAR(tmm::lowest_on_vertical(bn, tip, z, 3.3, -2.0), 10.0, 1e-12);
  for (double r : {1.0, 3.0, 6.7, 9.0, 12.0, 12.69}) {
    const double want = 10.0 + 6.0 - std::sqrt(36.0 - (r - 6.7) * (r - 6.7));
    EXPECT_NEAR(tmm::lowest_on_vertical(ri, tip, z, 3.0 + r, -2.0), want, 1e-9) << r;
    if (r >= 6.7) {
      EXPECT_NEAR(tmm::lowest_on_vertical(bn, tip, z, 3.0, -2.0 - r), want, 1e-9) << r;
    }
  }
  EXPECT_TRUE(std::isinf(tmm::lowest_on_vertical(ri, tip, z, 3.0 + 12.71, -2.0)));
  // A ball: closed form.
  const TorusTool ball = make_tool(0.0, 4.0, ToolShape::BullNose);
  EXPECT_NEAR(tmm::lowest_on_vertical(ball, tip, tilted(30, 20), 3.0 + 4.0 * std::sin(30 * kDeg) * std::cos(20 * kDeg),
                                      -2.0 + 4.0 * std::sin(30 * kDeg) * std::sin(20 * kDeg)),
              10.0 + 4.0 * std::cos(30 * kDeg) - 4.0, 1e-12);
}

TEST(Sweep5Lowest, FlatEndMillIsTheBullNoseWithoutCorner) {
  // Ri = 0: the flat bottom disc of radius R, the cylinder above; tilted by b about Y its bottom is the plane
  // z = tip_z - (x - tip_x) tan(b), out to R cos(b) each side; beyond the low rim nothing
  const TorusTool flat = make_tool(5.0, 0.0, ToolShape::BullNose);
  EXPECT_NO_THROW(flat.validate_solid());
  EXPECT_THROW(flat.validate(), std::invalid_argument);  // multipoint positioning still needs a corner
  EXPECT_THROW(make_tool(5.0, 0.0, ToolShape::RoundInsert).validate_solid(), std::invalid_argument);
  EXPECT_THROW(make_tool(0.0, 0.0, ToolShape::BullNose).validate_solid(), std::invalid_argument);
  const Vector3d tip(1.0, 2.0, 3.0), a = tilted(12, 0);
  for (double u : {-4.8, -2.0, 0.0, 1.5, 4.8}) {
    EXPECT_NEAR(tmm::lowest_on_vertical(flat, tip, a, 1.0 + u, 2.0), 3.0 - u * std::tan(12 * kDeg), 1e-12) << u;
    EXPECT_NEAR(tmm::lowest_on_vertical(flat, tip, a, 1.0 + u, 2.0),
                brute_lowest(flat, tip, a, 1.0 + u, 2.0, -5.0, 20.0), 2e-4) << u;
  }
  EXPECT_TRUE(std::isinf(tmm::lowest_on_vertical(flat, tip, a, 1.0 - 5.0 * std::cos(12 * kDeg) - 0.01, 2.0)));
}

// ---------------------------------------------------------------------------------------------------------
// Sweeps.
// ---------------------------------------------------------------------------------------------------------

struct Path {
  std::vector<double> tips, axes;
  std::vector<MoveKind> kinds;
  void add(const Vector3d& t, const Vector3d& a, MoveKind kind_before = MoveKind::Cut) {
    if (!tips.empty()) kinds.push_back(kind_before);
    const Vector3d an = a.normalized();
    tips.insert(tips.end(), {t.x(), t.y(), t.z()});
    axes.insert(axes.end(), {an.x(), an.y(), an.z()});
  }
  std::size_t size() const { return tips.size() / 3; }
};

tmm::SimReport run(ZMap& stock, const TorusTool& tool, const Path& p, double max_step, int threads = 0,
                   tmm::Sweep5Stats* stats = nullptr, double collision_tol = 1e-3) {
  tmm::Sweep5Options o;
  o.max_step = max_step;
  o.collision_tol = collision_tol;
  tmm::BatchOptions b;
  b.threads = threads;
  return tmm::cut_5axis(stock, tool, p.tips.data(), p.axes.data(), p.kinds.data(), p.size(), o, b, stats);
}

double profile(double rho, double Ro, double Ri, bool bull) {  // lower surface of the vertical tool above the tip
  if (rho > Ro + Ri) return kInf;
  if (bull && rho <= Ro) return 0.0;
  if (!bull && rho < Ro - Ri) return Ri;
  return Ri - std::sqrt(std::max(Ri * Ri - (rho - Ro) * (rho - Ro), 0.0));
}

TEST(Sweep5Cut, VerticalTorusOnAPlaneLeavesTheClosedFormCusp) {
  for (const bool bull : {true, false}) {
    const double Ro = 6.7, Ri = 6.0, Rt = Ro + Ri, len = 40.0, step = 0.4;
    const TorusTool tool = make_tool(Ro, Ri, bull ? ToolShape::BullNose : ToolShape::RoundInsert);
    ZMap stock(-15.0, -14.05, 0.1, 300, 680, 50.0);  // cell centres on the midpoints
    Path p;
    p.add({0, 0, 5}, {0, 0, 1});
    p.add({0, len, 5}, {0, 0, 1});
    tmm::Sweep5Stats st;
    run(stock, tool, p, step, 0, &st);
    const int n = static_cast<int>(std::ceil(len / step - 1e-12));
    EXPECT_EQ(st.instances, static_cast<std::size_t>(n + 1));
    const double s = len / n, bound = s * s / (8 * Ri);
    double worst = 0.0;
    int checked = 0;
    for (std::size_t j = 0; j < stock.ny(); ++j) {
      for (std::size_t i = 0; i < stock.nx(); ++i) {
        const double x = stock.cx(i), y = stock.cy(j);
        double discrete = kInf;  // the instances stamped: tips at y = k s
        bool steep = false;      // a vertical wall of the profile within 1e-3 mm: ill-conditioned heights
        for (int k = 0; k <= n; ++k) {
          const double rho = std::hypot(x, y - k * s);
          discrete = std::min(discrete, profile(rho, Ro, Ri, bull));
          steep = steep || std::abs(rho - Rt) < 1e-3 || (!bull && std::abs(rho - (Ro - Ri)) < 1e-3);
        }
        if (!steep) {
          const double want = std::isinf(discrete) ? 50.0 : 5.0 + discrete;
          ASSERT_NEAR(stock.at(i, j), want, 1e-9) << i << " " << j;
        }
        // Between the ends the swept envelope is the profile across the path (flat within Ro for the bull
        // nose, the lowest circle for the round insert); the cusp stays under s^2 / (8 Ri) / cos(slope)
        // where the cut surface is no steeper than 45 deg.
        const double ax = std::abs(x);
        if (y > Rt && y < len - Rt && ax - Ro <= Ri * std::sin(M_PI / 4)) {
          const double env = 5.0 + (ax <= Ro ? 0.0 : profile(ax, Ro, Ri, true));
          const double slope = ax <= Ro ? 0.0 : std::asin((ax - Ro) / Ri);
          EXPECT_GE(stock.at(i, j), env - 1e-9);
          EXPECT_LE(stock.at(i, j) - env, bound / std::cos(slope) + 1e-9) << x << " " << y;
          worst = std::max(worst, stock.at(i, j) - env);
          ++checked;
        }
      }
    }
    EXPECT_GT(checked, 1000);
    // The bound is what the round insert leaves under its lowest circle; the bull nose's flat leaves none
    // and its corner less.
    if (bull) EXPECT_GT(worst, 0.05 * bound);
    else EXPECT_GT(worst, 0.9 * bound);
  }
}


// The slope of the swept surface at the lowest point of one instance on a line: the tool's normal there.
double slope_at(const TorusTool& tool, const Vector3d& tip, const Vector3d& a, double x, double y, double z) {
  Vector3d g;
  tmm::tool_distance(tool, tip, a, Vector3d(x, y, z), &g);
  return std::acos(std::min(1.0, std::abs(g.z())));
}

TEST(Sweep5Cut, TiltedFixedAxisLineMatchesDenseStamping) {
  for (const ToolShape shape : {ToolShape::RoundInsert, ToolShape::BullNose}) {
    const TorusTool tool = make_tool(6.7, 6.0, shape);
    const Vector3d a = tilted(20.0, 30.0), t0(0.0, 0.0, 2.0), t1(8.0, 3.0, 0.0);
    const double max_step = 0.05, top = 4.0;
    ZMap stock(-15.0, -15.0, 0.1, 380, 330, top);
    Path p;
    p.add(t0, a);
    p.add(t1, a);
    tmm::Sweep5Stats st;
    run(stock, tool, p, max_step, 0, &st);
    const std::size_t n = st.instances - 1;
    ASSERT_EQ(n, static_cast<std::size_t>(std::ceil((t1 - t0).norm() / max_step - 1e-12)));
    const double s = (t1 - t0).norm() / static_cast<double>(n), bound = s * s / (8 * tool.Ri);
    std::mt19937_64 rng(7);
    std::uniform_int_distribution<std::size_t> ui(0, stock.nx() - 1), uj(0, stock.ny() - 1);
    int checked = 0, cut = 0;
    double worst = 0.0;
    constexpr int kInstants = 100000;
    while (checked < 120) {
      const std::size_t i = ui(rng), j = uj(rng);
      const double x = stock.cx(i), y = stock.cy(j);
      double dense = top, best_s = -1.0;
      for (int k = 0; k <= kInstants; ++k) {
        const double f = static_cast<double>(k) / kInstants;
        const double zl = tmm::lowest_on_vertical(tool, (1 - f) * t0 + f * t1, a, x, y);
        if (zl < dense) dense = zl, best_s = f;
      }
      if (best_s < 0.0) {
        ASSERT_EQ(stock.at(i, j), top);
        continue;
      }
      ++cut;
      const double slope = slope_at(tool, (1 - best_s) * t0 + best_s * t1, a, x, y, dense);
      EXPECT_GE(stock.at(i, j), dense - 1e-8) << x << " " << y;
      if (slope > 60.0 * kDeg) continue;
      ++checked;
      EXPECT_LE(stock.at(i, j) - dense, bound / std::cos(slope) + 1e-8) << x << " " << y << " slope " << slope;
      worst = std::max(worst, stock.at(i, j) - dense);
    }
    EXPECT_GT(worst, 0.0);
    EXPECT_GE(cut, checked);
  }
}

// A curved path with a turning axis: the tip along an arc, up and down, tilt 5..25 deg turning with it.
Path curved_path(int points, double z0) {
  Path p;
  for (int k = 0; k < points; ++k) {
    const double f = static_cast<double>(k) / (points - 1), ang = f * 60.0 * kDeg;
    const Vector3d tip(30.0 * std::cos(ang) - 30.0, 30.0 * std::sin(ang), z0 + 1.5 * std::sin(3.0 * ang));
    p.add(tip, tilted(5.0 + 20.0 * f, 90.0 + 60.0 * f + 40.0 * std::sin(4 * ang)));
  }
  return p;
}

TEST(Sweep5Cut, HalvingTheStepStaysWithinTheBound) {
  const TorusTool tool = make_tool(6.7, 6.0, ToolShape::RoundInsert);
  const Path p = curved_path(16, 0.0);
  const double coarse_step = 0.4, top = 3.0;
  ZMap coarse(-27.0, -13.0, 0.1, 420, 470, top), fine = coarse;
  run(coarse, tool, p, coarse_step);
  run(fine, tool, p, coarse_step / 2);
  const double bound = coarse_step * coarse_step / (8 * tool.Ri);
  double worst = 0.0;
  int checked = 0;
  for (std::size_t j = 1; j + 1 < fine.ny(); ++j) {
    for (std::size_t i = 1; i + 1 < fine.nx(); ++i) {
      const double c = fine.at(i, j);
      if (!(c < top && fine.at(i - 1, j) < top && fine.at(i + 1, j) < top && fine.at(i, j - 1) < top &&
            fine.at(i, j + 1) < top))
        continue;
      const double gx = (fine.at(i + 1, j) - fine.at(i - 1, j)) / (2 * fine.cell());
      const double gy = (fine.at(i, j + 1) - fine.at(i, j - 1)) / (2 * fine.cell());
      const double slope = std::atan(std::hypot(gx, gy));
      if (slope > 45.0 * kDeg) continue;
      ++checked;
      const double d = std::abs(coarse.at(i, j) - c);
      // 10 % for the slope estimated by differences across cusps
      EXPECT_LE(d, 1.1 * bound / std::cos(slope) + 1e-9) << i << " " << j;
      worst = std::max(worst, d);
    }
  }
  EXPECT_GT(checked, 20000);
  EXPECT_GT(worst, 0.1 * bound);
}

TEST(Sweep5Cut, RapidsThroughTheStockAreCollisionsAboveNot) {
  const TorusTool tool = make_tool(6.7, 6.0, ToolShape::RoundInsert);
  ZMap stock(-25.0, -25.0, 0.2, 250, 250, 10.0);
  Path p;
  p.add({-5, 0, 9.5}, {0, 0, 1});
  p.add({5, 0, 9.5}, {0, 0, 1}, MoveKind::Cut);               // 0: cuts 0.5 mm
  p.add({5, 0, 15}, {0, 0, 1}, MoveKind::Rapid);              // 1: lift
  p.add({-8, 8, 15}, tilted(10, 45), MoveKind::Rapid);        // 2: above the stock, turning
  p.add({-8, 8, 15.5}, {0, 0, 1}, MoveKind::Rapid);           // 3: turning back, above
  p.add({-8, 8, 8}, {0, 0, 1}, MoveKind::Rapid);              // 4: plunges 2 mm into it
  p.add({-8, 8, 12}, {0, 0, 1}, MoveKind::Rapid);             // 5: back up through the hole it made
  p.add({-12, -15, 12}, {0, 0, 1}, MoveKind::Rapid);          // 6: above
  p.add({-12, -15, 9.9995}, {0, 0, 1}, MoveKind::Rapid);      // 7: grazes 0.5 um: within collision_tol
  const tmm::SimReport r = run(stock, tool, p, 0.05);
  EXPECT_EQ(r.moves_cut, 8u);
  ASSERT_EQ(r.collisions.size(), 1u);
  EXPECT_EQ(r.collisions[0].move, 4u);
  EXPECT_NEAR(r.collisions[0].depth, 2.0, 1e-6);  // the cells nearest the lowest circle
  const ZMap& s = stock;
  auto at = [&](double x, double y) { return s.at(static_cast<std::size_t>((x + 25.0) / 0.2), static_cast<std::size_t>((y + 25.0) / 0.2)); };
  EXPECT_NEAR(at(0.1, -6.7), 9.5, 1e-3);     // the cut
  EXPECT_NEAR(at(-12.1, -8.3), 9.9995, 1e-6);  // the grazing rapid lowered cells all the same
  EXPECT_EQ(at(20.1, 20.1), 10.0);
  // The same path with a looser tolerance: no collision at all; cells_lowered does not depend on it.
  ZMap again(-25.0, -25.0, 0.2, 250, 250, 10.0);
  const tmm::SimReport r2 = run(again, tool, p, 0.05, 0, nullptr, 2.5);
  EXPECT_TRUE(r2.collisions.empty());
  EXPECT_EQ(r2.cells_lowered, r.cells_lowered);
  std::size_t lowered = 0;
  for (double h : stock.heights()) lowered += h < 10.0;
  EXPECT_EQ(r.cells_lowered, lowered);
}

TEST(Sweep5Cut, JumpsAreNotSimulated) {
  const TorusTool tool = make_tool(6.7, 6.0, ToolShape::BullNose);
  ZMap stock(-25.0, -25.0, 0.2, 250, 250, 10.0);
  Path p;
  p.add({-15, -15, 9}, {0, 0, 1});
  p.add({-15, -10, 9}, {0, 0, 1}, MoveKind::Cut);
  p.add({15, 15, 9}, {0, 0, 1}, MoveKind::Jump);   // straight through the middle if it were a move
  p.add({15, 10, 9}, {0, 0, 1}, MoveKind::Cut);
  const tmm::SimReport r = run(stock, tool, p, 0.05);
  EXPECT_EQ(r.moves_cut, 2u);
  EXPECT_TRUE(r.collisions.empty());
  auto at = [&](double x, double y) {
    return stock.at(static_cast<std::size_t>((x + 25.0) / 0.2), static_cast<std::size_t>((y + 25.0) / 0.2));
  };
  EXPECT_EQ(at(0.1, 0.1), 10.0);
  EXPECT_NEAR(at(-15.1, -12.1), 9.0, 1e-9);
  EXPECT_NEAR(at(15.1, 16.1), 9.0, 1e-9);   // the start of the cut after the jump is stamped
  EXPECT_NEAR(at(15.1, 8.1), 9.0, 1e-9);
}

TEST(Sweep5Cut, BitIdenticalForAnyThreadCount) {
  const TorusTool tool = make_tool(6.7, 6.0, ToolShape::RoundInsert);
  Path p = curved_path(12, 0.0);
  p.add({-10, 20, 10}, {0, 0, 1}, MoveKind::Rapid);
  p.add({-10, 20, 1}, {0, 0, 1}, MoveKind::Rapid);
  p.add({-12, 10, 1}, tilted(12, 200), MoveKind::Cut);
  std::vector<double> ref;
  tmm::SimReport r0;
  for (int threads : {1, 2, 3}) {
    ZMap stock(-27.0, -13.0, 0.1, 420, 470, 3.0);
    const tmm::SimReport r = run(stock, tool, p, 0.1, threads);
    if (threads == 1) {
      ref = stock.heights();
      r0 = r;
      ASSERT_EQ(r.collisions.size(), 1u);
      continue;
    }
    EXPECT_TRUE(stock.heights() == ref) << threads;
    EXPECT_EQ(r.cells_lowered, r0.cells_lowered);
    ASSERT_EQ(r.collisions.size(), r0.collisions.size());
    EXPECT_EQ(r.collisions[0].move, r0.collisions[0].move);
    EXPECT_EQ(r.collisions[0].depth, r0.collisions[0].depth);
  }
}

TEST(Sweep5Cut, CancelThrowsAndProgressReports) {
  const TorusTool tool = make_tool(6.7, 6.0, ToolShape::RoundInsert);
  const Path p = curved_path(12, 0.0);
  tmm::Sweep5Options o;
  tmm::BatchOptions b;
  b.threads = 2;
  b.progress = [](double) { return false; };
  ZMap stock(-27.0, -13.0, 0.1, 420, 470, 3.0);
  EXPECT_THROW(tmm::cut_5axis(stock, tool, p.tips.data(), p.axes.data(), p.kinds.data(), p.size(), o, b),
               tmm::Cancelled);
  std::vector<double> seen;
  b.progress = [&](double f) {
    seen.push_back(f);
    return true;
  };
  ZMap again(-27.0, -13.0, 0.1, 420, 470, 3.0);
  tmm::cut_5axis(again, tool, p.tips.data(), p.axes.data(), p.kinds.data(), p.size(), o, b);
  ASSERT_FALSE(seen.empty());
  EXPECT_EQ(seen.back(), 1.0);
  EXPECT_TRUE(std::is_sorted(seen.begin(), seen.end()));
}

void expect_refused(const std::function<void()>& f, const std::string& needle) {
  try {
    f();
    ADD_FAILURE() << "not refused: " << needle;
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find(needle), std::string::npos) << e.what();
  }
}

TEST(Sweep5Cut, RefusesBadInputByName) {
  ZMap stock(0.0, 0.0, 1.0, 10, 10, 5.0);
  tmm::BatchOptions b;
  auto call = [&](Path p, double max_step = 0.05, double tol = 1e-3, const TorusTool& t = make_tool(6.7, 6.0, ToolShape::RoundInsert)) {
    return [=, &stock, &b]() mutable {
      tmm::Sweep5Options o;
      o.max_step = max_step;
      o.collision_tol = tol;
      tmm::cut_5axis(stock, t, p.tips.data(), p.axes.data(), p.kinds.data(), p.size(), o, b);
    };
  };
  Path good;
  for (int k = 0; k < 4; ++k) good.add({1.0 * k, 0, 4}, {0, 0, 1});
  Path bad_tip = good;
  bad_tip.tips[3 * 2 + 1] = std::nan("");
  expect_refused(call(bad_tip), "tips row 2");
  Path zero_axis = good;
  zero_axis.axes[3] = zero_axis.axes[4] = zero_axis.axes[5] = 0.0;
  expect_refused(call(zero_axis), "axes row 1");
  Path inf_axis = good;
  inf_axis.axes[3 * 3] = kInf;
  expect_refused(call(inf_axis), "axes row 3");
  Path down = good;
  down.axes[2] = -1.0;
  expect_refused(call(down), "axes row 0");
  Path bad_kind = good;
  bad_kind.kinds[1] = static_cast<MoveKind>(7);
  expect_refused(call(bad_kind), "kinds[1]");
  expect_refused(call(good, 0.0), "max_step");
  expect_refused(call(good, std::nan("")), "max_step");
  expect_refused(call(good, 0.05, -1.0), "collision_tol");
  expect_refused(call(good, 0.05, 1e-3, make_tool(6.7, 0.0, ToolShape::RoundInsert)), "minor radius");
  // Nothing was cut by the refused calls; the good one cuts.
  for (double h : stock.heights()) EXPECT_EQ(h, 5.0);
  EXPECT_NO_THROW(call(good)());
  EXPECT_LT(*std::min_element(stock.heights().begin(), stock.heights().end()), 5.0);
}

}  // namespace
