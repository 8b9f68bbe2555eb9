// The tool assembly dropped along a direction (drop_assembly_direction.hpp):
//  - its convex solids are the grown assembly: a point lies in one of them exactly when it lies within a
//    body's clearance of that body (the signed distance to the body's meridian trapezoid, in closed form) or
//    within the cutter's clearance of the cutter solid (the distance to its sampled meridian section);
//  - the mesh query equals the earliest contact of every solid with every triangle (drop_along, itself
//    checked against a brute force in test_drop_direction.cpp), with the piece that touched;
//  - closed forms: a wall met sideways by the widest grown body, a plate under a tilted tool met by the
//    lowest grown rim;
//  - along the tool's axis the vertical assembly drop, bit for bit; a hair off the axis (the solids' path) the
//    same within the hair's effect;
//  - the batch equals the points, threads agree, also where the holder stops the tool beside a dome (the
//    bodies dropped first on the triangle that last stopped them); an endless cutter with nothing above it is
//    refused.
#include <gtest/gtest.h>

#include <Eigen/Core>
#include <algorithm>
#include <cmath>
#include <limits>
#include <random>
#include <stdexcept>
#include <utility>
#include <vector>

#include "support/test_meshes.hpp"
#include "tmm/query/drop_assembly_direction.hpp"

namespace {

using Eigen::Vector2d;
using Eigen::Vector3d;
using tmm::Cutter;
using tmm::ToolAssembly;
using tmm::ToolBody;

constexpr double kDeg = M_PI / 180.0;
constexpr double kInf = std::numeric_limits<double>::infinity();

// Signed distance from p to the convex polygon `poly` (counter-clockwise): negative inside.
double signed_distance(const std::vector<Vector2d>& poly, const Vector2d& p) {
  double d = kInf;
  bool inside = true;
  for (std::size_t i = 0; i < poly.size(); ++i) {
    const Vector2d a = poly[i], b = poly[(i + 1) % poly.size()], t = b - a;
    if (t.squaredNorm() < 1e-18) continue;  // a cone's point, a corner's rounding crumb
    const double s = std::clamp((p - a).dot(t) / t.squaredNorm(), 0.0, 1.0);
    d = std::min(d, (a + s * t - p).norm());
    if (t.x() * (p.y() - a.y()) - t.y() * (p.x() - a.x()) < 0) inside = false;
  }
  return inside ? -d : d;
}

// The meridian section of a body (both sides of the axis), counter-clockwise.
std::vector<Vector2d> trapezoid(const ToolBody& b) {
  return {{-b.r0, b.z0}, {b.r0, b.z0}, {b.r1, b.z1}, {-b.r1, b.z1}};
}

// The meridian section of drop_direction's cutter solid {h(rho) <= z <= L_C, rho <= max_radius} cut at L,
// sampled densely along its lower profile.
std::vector<Vector2d> cutter_section(const Cutter& k, double L) {
  const int m = 1000;
  const double R = k.max_radius();
  std::vector<Vector2d> lower;
  for (int i = -m; i <= m; ++i) {
    const double rho = R * i / m;
    lower.emplace_back(rho, k.height(std::fabs(rho)));
  }
  lower.emplace_back(R, L);
  lower.emplace_back(-R, L);
  return lower;
}

// Is (rho, z) (tool frame) inside one of the solids?
bool in_solids(const std::vector<tmm::AssemblySolid>& solids, double rho, double z, double tol) {
  for (const tmm::AssemblySolid& s : solids) {
    const double zs = s.flipped ? s.lift - z : z - s.lift;
    const Cutter& k = s.profile;
    if (rho <= k.max_radius() + tol && zs >= k.height(std::min(rho, k.max_radius())) - tol &&
        zs <= k.cutting_length() + tol)
      return true;
  }
  return false;
}

struct Tool {
  Cutter cutter;
  std::vector<ToolBody> bodies;
  double clearance;
};

std::vector<Tool> tools() {
  return {
      // A ball (endless: cut at 15) under a shank, a widening cone, a holder and its narrowing nose.
      {Cutter(3, 3),
       {{15, 25, 3, 3, 0.5}, {25, 30, 3, 8, 1.0}, {30, 90, 20, 20, 2.0}, {90, 100, 20, 10, 1.5}},
       0.0},
      // A tapered bull with its own clearance; bodies without one, a cone to a point on top.
      {Cutter::apt(3, 1, 10, 0, 10 * kDeg), {{10, 20, 4, 4, 0.0}, {20, 26, 4, 0, 0.0}}, 0.4},
      // An inward taper with a clearance (its solid is the widest cylinder); a gap, then a wide body.
      {Cutter::apt(3, 1, 8, 0, -5 * kDeg), {{9, 12, 2, 6, 0.7}, {12, 40, 6, 6, 0.2}}, 0.3},
  };
}

TEST(DropAssemblyDirection, SolidsAreTheGrownAssembly) {
  std::mt19937_64 rng(5);
  for (const Tool& t : tools()) {
    const ToolAssembly tool(t.cutter, t.bodies, t.clearance);
    const auto solids = tmm::assembly_solids(tool);
    const double L = std::isfinite(t.cutter.cutting_length()) ? t.cutter.cutting_length() : t.bodies[0].z0;
    const auto section = cutter_section(t.cutter, L);
    const double top = t.bodies.back().z1 + 3, wide = 25;
    std::uniform_real_distribution<double> rr(0, wide), zz(-3, top);
    int in = 0, out = 0;
    for (int k = 0; k < 30000; ++k) {
      const double rho = rr(rng), z = zz(rng);
      // Within each piece's clearance: the signed distance to its section less its clearance.
      double m = signed_distance(section, {rho, z}) - t.clearance;
      for (const ToolBody& b : t.bodies) m = std::min(m, signed_distance(trapezoid(b), {rho, z}) - b.clearance);
      if (std::fabs(m) < 1e-5) continue;  // on the surface (to the sampling's accuracy): either answer
      const bool inside = m < 0;
      EXPECT_EQ(in_solids(solids, rho, z, 0.0), inside) << t.clearance << " rho " << rho << " z " << z << " m " << m;
      (inside ? in : out)++;
    }
    EXPECT_GT(in, 1000);
    EXPECT_GT(out, 1000);
  }
}

// A height field z(x, y) over a plate 40 wide about the origin, 1 mm cells of two triangles.
template <class Height>
std::pair<tmm::Vertices, tmm::Triangles> height_grid(Height&& z) {
  const int cells = 40;
  tmm::Vertices V((cells + 1) * (cells + 1), 3);
  tmm::Triangles F(2 * cells * cells, 3);
  for (int i = 0; i <= cells; ++i)
    for (int j = 0; j <= cells; ++j) {
      const double x = i - 20.0, y = j - 20.0;
      V.row(i * (cells + 1) + j) << x, y, z(x, y);
    }
  for (int i = 0, f = 0; i < cells; ++i)
    for (int j = 0; j < cells; ++j) {
      const int a = i * (cells + 1) + j;
      F.row(f++) << a, a + cells + 1, a + 1;
      F.row(f++) << a + 1, a + cells + 1, a + cells + 2;
    }
  return {V, F};
}

// Every solid against every triangle by drop_along: the earliest travel and its piece.
double brute_travel(const std::vector<tmm::AssemblySolid>& solids, const tmm::Vertices& V, const tmm::Triangles& F,
                    const Vector3d& start, const Vector3d& axis, const Vector3d& dir, int32_t& by) {
  double best = tmm::kNoTravel;
  by = tmm::kSetByFloor;
  for (const tmm::AssemblySolid& s : solids) {
    const Vector3d a = s.flipped ? Vector3d(-axis) : axis;
    for (int f = 0; f < F.rows(); ++f) {
      const double t = tmm::drop_along(s.profile, start + s.lift * axis, a, dir, V.row(F(f, 0)).transpose(),
                                       V.row(F(f, 1)).transpose(), V.row(F(f, 2)).transpose());
      if (t < best) {
        best = t;
        by = s.owner;
      }
    }
  }
  return best;
}

TEST(DropAssemblyDirection, MeshQueryEqualsBruteForce) {
  std::mt19937_64 rng(11);
  const auto [V, F] = tmm_test::bumpy_grid(24, 3.0, 4.0, rng);
  std::uniform_real_distribution<double> pos(-6, 30), u(-1, 1);
  int by_body = 0, by_cutter = 0;
  for (const Tool& t : tools()) {
    const ToolAssembly tool(t.cutter, t.bodies, t.clearance);
    const auto solids = tmm::assembly_solids(tool);
    for (int k = 0; k < 8; ++k) {
      // Mostly downwards, some nearly sideways (the bodies' sides and the top discs touch first).
      const Vector3d dir = Vector3d(u(rng), u(rng), k % 3 == 2 ? -0.2 : -1).normalized();
      const tmm::DirectionalIndex index(V, F, dir);
      for (int j = 0; j < 5; ++j) {
        const Vector3d axis = Vector3d(1.5 * u(rng), 1.5 * u(rng), 1).normalized();
        const Vector3d start(pos(rng), pos(rng), 10);
        int32_t brute_by = 0, by = 0;
        const double brute = brute_travel(solids, V, F, start, axis, dir, brute_by);
        const double travel = tmm::drop_assembly_along_point(index, tool, start, axis, tmm::kNoTravel, &by);
        if (brute == tmm::kNoTravel) {
          EXPECT_EQ(travel, brute) << k << " " << j;
        } else {
          EXPECT_NEAR(travel, brute, 1e-9) << k << " " << j;
        }
        EXPECT_EQ(by, brute_by) << k << " " << j;
        (by >= 0 ? by_body : by_cutter)++;
      }
    }
  }
  EXPECT_GT(by_body, 5);  // the bodies matter in this test (10 of 120 touch first)
  EXPECT_GT(by_cutter, 5);
}

// Two triangles spanning the plane through o with edges u and v (both ways to +-1e4).
std::pair<tmm::Vertices, tmm::Triangles> big_plane(const Vector3d& o, const Vector3d& u, const Vector3d& v) {
  tmm::Vertices V(4, 3);
  V.row(0) = (o - 1e4 * u - 1e4 * v).transpose();
  V.row(1) = (o + 1e4 * u - 1e4 * v).transpose();
  V.row(2) = (o + 1e4 * u + 1e4 * v).transpose();
  V.row(3) = (o - 1e4 * u + 1e4 * v).transpose();
  tmm::Triangles F(2, 3);
  F << 0, 1, 2, 0, 2, 3;
  return {V, F};
}

TEST(DropAssemblyDirection, ClosedForms) {
  const Tool t = tools()[0];
  const ToolAssembly tool(t.cutter, t.bodies, t.clearance);
  // Sideways into the wall x = 50: the widest grown body (the holder, 20 + 2) touches first.
  {
    const auto [V, F] = big_plane({50, 0, 0}, Vector3d::UnitY(), Vector3d::UnitZ());
    const tmm::DirectionalIndex index(V, F, Vector3d::UnitX());
    int32_t by = 0;
    const double travel = tmm::drop_assembly_along_point(index, tool, {0, 0, 0}, Vector3d::UnitZ(), kInf, &by);
    EXPECT_NEAR(travel, 50 - 22, 1e-9);
    EXPECT_EQ(by, 2);
  }
  // Down onto the plate z = 0 with the axis 60 deg off the vertical: the lowest point of a rim circle of
  // radius r at height h along the axis, grown by c, lies h cos 60 - r sin 60 - c below the tip's height.
  {
    const auto [V, F] = big_plane({0, 0, 0}, Vector3d::UnitX(), Vector3d::UnitY());
    const tmm::DirectionalIndex index(V, F, -Vector3d::UnitZ());
    const Vector3d axis(std::sin(60 * kDeg), 0, std::cos(60 * kDeg));
    double lowest = 3 * std::cos(60 * kDeg) - 3;  // the ball's centre 3 up the axis
    int32_t expect_by = tmm::kSetByCutter;
    for (std::size_t i = 0; i < t.bodies.size(); ++i) {
      const ToolBody& b = t.bodies[i];
      for (const auto& [h, r] : {std::pair{b.z0, b.r0}, std::pair{b.z1, b.r1}}) {
        const double low = h * std::cos(60 * kDeg) - r * std::sin(60 * kDeg) - b.clearance;
        if (low < lowest) {
          lowest = low;
          expect_by = static_cast<int32_t>(i);
        }
      }
    }
    int32_t by = 0;
    const double travel = tmm::drop_assembly_along_point(index, tool, {0, 0, 40}, axis, kInf, &by);
    EXPECT_NEAR(travel, 40 + lowest, 1e-9);
    EXPECT_EQ(by, expect_by);
    EXPECT_EQ(expect_by, 2);  // the holder's rim
  }
}

TEST(DropAssemblyDirection, AlongTheAxisIsTheVerticalDrop) {
  std::mt19937_64 rng(23);
  const auto [V, F] = tmm_test::bumpy_grid(30, 3.0, 5.0, rng);
  const tmm::MeshIndex plain(V, F);
  const tmm::DirectionalIndex down(V, F, -Vector3d::UnitZ());
  const std::size_t n = 3000;
  std::vector<double> xy, starts, z(n), travel(n);
  std::vector<int32_t> by(n), by_dir(n);
  for (std::size_t i = 0; i < n; ++i) {
    xy.insert(xy.end(), {-5 + 0.7 * static_cast<double>(i % 60), -5 + 0.8 * static_cast<double>(i / 60)});
    starts.insert(starts.end(), {xy[2 * i], xy[2 * i + 1], 64.0});
  }
  const tmm::BatchOptions one;
  for (const Tool& t : tools()) {
    const ToolAssembly tool(t.cutter, t.bodies, t.clearance);
    tmm::drop_assembly_batch(plain, tool, xy.data(), n, -64.0, z.data(), by.data(), one);
    const Vector3d up = Vector3d::UnitZ();
    tmm::drop_assembly_along_batch(down, tool, starts.data(), up.data(), false, n, 128.0, travel.data(),
                                   by_dir.data(), one);
    for (std::size_t i = 0; i < n; ++i) {
      ASSERT_EQ(travel[i], 64.0 - z[i]) << i;
      ASSERT_EQ(by_dir[i], by[i]) << i;
    }
    // A hair (1e-7 rad) off the axis takes the solids' path: the same travels within the hair's effect.
    const Vector3d tilted = Vector3d(1e-7, 0, 1).normalized();
    for (std::size_t i = 0; i < n; i += 7) {
      int32_t b = 0;
      const double tr = tmm::drop_assembly_along_point(down, tool, Vector3d(&starts[3 * i]), tilted, 128.0, &b);
      EXPECT_NEAR(tr, travel[i], 1e-4) << i;
    }
  }
}

TEST(DropAssemblyDirection, BatchIsPointByPointAndThreadsAgree) {
  std::mt19937_64 rng(31);
  const auto [V, F] = tmm_test::bumpy_grid(20, 3.0, 4.0, rng);
  const Vector3d dir = Vector3d(0.3, -0.2, -1).normalized();
  const tmm::DirectionalIndex index(V, F, dir);
  const Tool t = tools()[0];
  const ToolAssembly tool(t.cutter, t.bodies, t.clearance);
  const std::size_t n = 600;
  std::vector<double> starts, axes;
  std::uniform_real_distribution<double> pos(-5, 25), u(-1, 1);
  for (std::size_t i = 0; i < n; ++i) {
    starts.insert(starts.end(), {pos(rng), pos(rng), 15.0});
    const Vector3d a = i % 5 == 0 ? Vector3d(-dir) : Vector3d(0.5 * u(rng), 0.5 * u(rng), 1).normalized();
    axes.insert(axes.end(), {a.x(), a.y(), a.z()});
  }
  tmm::BatchOptions one, two;
  two.threads = 2;
  std::vector<double> t1(n), t2(n);
  std::vector<int32_t> b1(n), b2(n);
  tmm::drop_assembly_along_batch(index, tool, starts.data(), axes.data(), true, n, 40.0, t1.data(), b1.data(), one);
  tmm::drop_assembly_along_batch(index, tool, starts.data(), axes.data(), true, n, 40.0, t2.data(), b2.data(), two);
  int misses = 0;
  for (std::size_t i = 0; i < n; ++i) {
    EXPECT_EQ(t1[i], t2[i]) << i;
    EXPECT_EQ(b1[i], b2[i]) << i;
    int32_t b = 0;
    const double tp = tmm::drop_assembly_along_point(index, tool, Vector3d(&starts[3 * i]), Vector3d(&axes[3 * i]),
                                                     40.0, &b);
    EXPECT_NEAR(t1[i], tp, 1e-12) << i;
    EXPECT_EQ(b1[i], b) << i;
    if (t1[i] == 40.0) {
      ++misses;
      EXPECT_EQ(b1[i], tmm::kSetByFloor) << i;
    }
  }
  EXPECT_GT(misses, 0);
  EXPECT_LT(misses, static_cast<int>(n) / 2);
}

// One tilted axis for the whole batch (the solids set up once, the solid that stopped the last start dropped
// first) over a pocket: the points where a body stops the tool come in runs, so that order changes along the
// batch; every travel and piece is the point's own, and the exact per-triangle reference's on a sample.
TEST(DropAssemblyDirection, SharedTiltedAxisBatchIsPointByPoint) {
  // A plate 40 wide with a pocket 16 wide and 18 deep (its floor a dome): the bodies meet the walls and the rim.
  const auto [V, F] = height_grid([](double x, double y) {
    const bool inside = std::fabs(x) < 8 && std::fabs(y) < 8;
    return inside ? -18 + 2 * std::cos(x / 4) * std::cos(y / 4) : 0.0;
  });
  const Vector3d dir = Vector3d(0.2, 0.1, -1).normalized();
  const tmm::DirectionalIndex index(V, F, dir);
  const Vector3d axis = Vector3d(0.45, -0.2, 1).normalized();  // about 26 deg off -dir
  const std::size_t n = 900;
  std::vector<double> starts;
  for (std::size_t i = 0; i < n; ++i)  // a zig-zag raster, as a path visits it
    starts.insert(starts.end(), {-13 + 0.9 * static_cast<double>(i / 30 % 2 ? 29 - i % 30 : i % 30),
                                 -13 + 0.9 * static_cast<double>(i / 30), 20.0});
  for (const Tool& t : tools()) {
    const ToolAssembly tool(t.cutter, t.bodies, t.clearance);
    const auto solids = tmm::assembly_solids(tool);
    tmm::BatchOptions one, two;
    two.threads = 2;
    std::vector<double> t1(n), t2(n);
    std::vector<int32_t> b1(n), b2(n);
    tmm::drop_assembly_along_batch(index, tool, starts.data(), axis.data(), false, n, 60.0, t1.data(), b1.data(), one);
    tmm::drop_assembly_along_batch(index, tool, starts.data(), axis.data(), false, n, 60.0, t2.data(), b2.data(), two);
    int by_body = 0, switches = 0;
    for (std::size_t i = 0; i < n; ++i) {
      ASSERT_EQ(t1[i], t2[i]) << i;
      ASSERT_EQ(b1[i], b2[i]) << i;
      int32_t b = 0;
      const double tp = tmm::drop_assembly_along_point(index, tool, Vector3d(&starts[3 * i]), axis, 60.0, &b);
      ASSERT_NEAR(t1[i], tp, 1e-12) << i;
      ASSERT_EQ(b1[i], b) << i;
      by_body += b1[i] >= 0;
      switches += i > 0 && b1[i] != b1[i - 1];
      if (i % 30 == 0) {
        int32_t brute_by = 0;
        const double brute = brute_travel(solids, V, F, Vector3d(&starts[3 * i]), axis, dir, brute_by);
        ASSERT_NEAR(t1[i], std::min(brute, 60.0), 1e-9) << i;
        ASSERT_EQ(b1[i], brute < 60.0 ? brute_by : tmm::kSetByFloor) << i;
      }
    }
    EXPECT_GT(by_body, 20);
    EXPECT_LT(by_body, static_cast<int>(n) * 19 / 20);
    EXPECT_GT(switches, 10);
  }
}

// One tilted axis over thin posts standing on a low plate, a dense raster: the batch takes the bodies from one
// candidate list per tile of starts, gathered once for all of them. Within a tile the cutter reaches the plate
// at most starts and a post at a few (the caps far apart), and the holder meets a post from some starts only,
// a post out of reach of the others: every travel and piece must be the point query's, which walks per start
// (a list cut to one start's reach or cap, or a plane proof taken at the best start rather than the worst,
// loses these contacts).
TEST(DropAssemblyDirection, TiledBatchKeepsNeighboursCandidates) {
  std::mt19937_64 rng(7);
  std::uniform_real_distribution<double> pos(-14, 14), tall(-12, 6);
  const int posts = 40;
  tmm::Vertices V(4 + 3 * posts, 3);
  tmm::Triangles F(2 + posts, 3);
  V.row(0) << -60, -60, -30;
  V.row(1) << 60, -60, -30;
  V.row(2) << 60, 60, -30;
  V.row(3) << -60, 60, -30;
  F.row(0) << 0, 1, 2;
  F.row(1) << 0, 2, 3;
  for (int k = 0; k < posts; ++k) {  // a fin 0.4 wide from the plate up to its top
    const double x = pos(rng), y = pos(rng), a = pos(rng);
    const int v = 4 + 3 * k;
    V.row(v) << x, y, -30;
    V.row(v + 1) << x + 0.4 * std::cos(a), y + 0.4 * std::sin(a), -30;
    V.row(v + 2) << x + 0.2 * std::cos(a), y + 0.2 * std::sin(a), tall(rng);
    F.row(2 + k) << v, v + 1, v + 2;
  }
  const Vector3d dir = Vector3d(0.15, -0.1, -1).normalized();
  const tmm::DirectionalIndex index(V, F, dir);
  const Vector3d axis = Vector3d(-0.3, 0.2, 1).normalized();
  std::vector<double> starts;
  for (int i = 0; i < 40; ++i)
    for (int j = 0; j < 40; ++j) starts.insert(starts.end(), {-10 + 0.5 * (i % 2 ? 39 - j : j), -10 + 0.5 * i, 20.0});
  const std::size_t n = starts.size() / 3;
  for (const Tool& t : tools()) {
    const ToolAssembly tool(t.cutter, t.bodies, t.clearance);
    std::vector<double> travel(n);
    std::vector<int32_t> by(n);
    tmm::drop_assembly_along_batch(index, tool, starts.data(), axis.data(), false, n, kInf, travel.data(), by.data(),
                                   tmm::BatchOptions());
    int cutter_on_post = 0, body = 0;
    for (std::size_t i = 0; i < n; ++i) {
      int32_t b = 0;
      const double tp = tmm::drop_assembly_along_point(index, tool, Vector3d(&starts[3 * i]), axis, kInf, &b);
      ASSERT_NEAR(travel[i], tp, 1e-12) << i;
      ASSERT_EQ(by[i], b) << i;
      body += b >= 0;
      cutter_on_post += b == tmm::kSetByCutter && tp < 49.0;  // the plate is about 50 below the starts
    }
    EXPECT_GT(body, 100);  // the bodies stop the tool at many starts, not all
    EXPECT_LT(body, static_cast<int>(n) * 9 / 10);
    EXPECT_GT(cutter_on_post, 10);
  }
}

// One tilted axis over a dome on a plate (as sphere_on_plate): beside the dome the holder stops the tool while
// the cutter hangs over the plate, and the batch drops each body first against the triangle that last stopped it
// nearby (its travel caps the cutter's walk), then solves the rest of its list past that contact's plane of
// support; the dome's triangles meet the tool at shared vertices (ties no clearance proof separates). Every
// travel and piece is the point query's, and the exact per-triangle reference's on a sample.
TEST(DropAssemblyDirection, HolderStopsTheToolFirstBesideADome) {
  const auto [V, F] = height_grid([](double x, double y) {  // a dome of radius 12
    const double r2 = x * x + y * y;
    return r2 < 144 ? std::sqrt(144 - r2) : 0.0;
  });
  const Vector3d dir = Vector3d(0.2, 0.1, -1).normalized();
  const tmm::DirectionalIndex index(V, F, dir);
  const Vector3d axis = Vector3d(0.45, 0.1, 1).normalized();  // about 15 deg off -dir
  const ToolAssembly tool(Cutter::apt(3, 1, 8, 0, 0), {{8, 16, 3, 3, 0.5}, {16, 60, 14, 14, 1.5}}, 0.0);
  const auto solids = tmm::assembly_solids(tool);
  std::vector<double> starts;
  for (int i = 0; i < 26; ++i)  // a zig-zag raster, as a path visits it
    for (int j = 0; j < 26; ++j) starts.insert(starts.end(), {-26 + 1.5 * (i % 2 ? 25 - j : j), -22 + 1.5 * i, 40.0});
  const std::size_t n = starts.size() / 3;
  std::vector<double> travel(n);
  std::vector<int32_t> by(n);
  tmm::drop_assembly_along_batch(index, tool, starts.data(), axis.data(), false, n, 80.0, travel.data(), by.data(),
                                 tmm::BatchOptions());
  int holder = 0, cutter = 0;
  for (std::size_t i = 0; i < n; ++i) {
    int32_t b = 0;
    const double tp = tmm::drop_assembly_along_point(index, tool, Vector3d(&starts[3 * i]), axis, 80.0, &b);
    ASSERT_NEAR(travel[i], tp, 1e-12) << i;
    ASSERT_EQ(by[i], b) << i;
    holder += b == 1;
    cutter += b == tmm::kSetByCutter;
    if (i % 23 == 0) {
      int32_t brute_by = 0;
      const double brute = brute_travel(solids, V, F, Vector3d(&starts[3 * i]), axis, dir, brute_by);
      ASSERT_NEAR(travel[i], std::min(brute, 80.0), 1e-9) << i;
      ASSERT_EQ(by[i], brute < 80.0 ? brute_by : tmm::kSetByFloor) << i;
    }
  }
  EXPECT_GT(holder, static_cast<int>(n) / 10) << cutter;
  EXPECT_GT(cutter, static_cast<int>(n) / 5) << holder;
}

TEST(DropAssemblyDirection, Refusals) {
  const auto [V, F] = big_plane({0, 0, 0}, Vector3d::UnitX(), Vector3d::UnitY());
  const tmm::DirectionalIndex index(V, F, -Vector3d::UnitZ());
  const ToolAssembly bare(Cutter(3, 3), {});
  // Along the axis the endless cutter is fine; tilted it needs a length or a body above it.
  EXPECT_NEAR(tmm::drop_assembly_along_point(index, bare, {0, 0, 10}, Vector3d::UnitZ()), 10, 1e-12);
  EXPECT_THROW(tmm::drop_assembly_along_point(index, bare, {0, 0, 10}, Vector3d(0, 0.6, 0.8)), std::invalid_argument);
  EXPECT_THROW(tmm::drop_assembly_along_point(index, bare, {0, 0, 10}, Vector3d(0, 0, 2)), std::invalid_argument);
  const ToolAssembly with_body(Cutter(3, 3), {{12, 20, 3, 3, 0.5}});
  EXPECT_GT(tmm::drop_assembly_along_point(index, with_body, {0, 0, 10}, Vector3d(0, 0.6, 0.8)), 0.0);
}

}  // namespace
