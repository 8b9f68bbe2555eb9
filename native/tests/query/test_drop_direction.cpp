// Drop along any direction with any axis, against slow independent references (seeded, thousands of cases):
//  (1) V = -Z, axis = +Z: equal to drop_on_triangle (the -Z kernel), for every cutter kind;
//  (2) rotating triangle, axis and V together leaves the travel unchanged;
//  (3) random axes and directions:
//      (a) cutter sampling: points of the boundary of K (profile surface, cylinder band, top cap) moved along V
//          and intersected with the triangle (ray-triangle): none may hit before the exact travel, and the
//          earliest hit is close to it;
//      (b) triangle sampling: at the returned position no sample lies inside K (G >= -1e-9 in the tool frame),
//          and the least clearance is close to 0 (touch).
#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <cmath>
#include <random>
#include <vector>

#include "tmm/query/drop_contacts.hpp"
#include "tmm/query/drop_cutter.hpp"
#include "tmm/query/drop_direction.hpp"
#include "tmm/mesh/mesh_index.hpp"
#include "support/test_meshes.hpp"

namespace {

using Eigen::Vector3d;
using tmm::Cutter;

constexpr double kDeg = M_PI / 180;

using tmm_test::one_triangle;

Vector3d random_unit(std::mt19937_64& rng) {
  std::normal_distribution<double> g;
  for (;;) {
    const Vector3d v(g(rng), g(rng), g(rng));
    if (v.norm() > 1e-6) return v.normalized();
  }
}

Eigen::Matrix3d random_rotation(std::mt19937_64& rng) {
  std::normal_distribution<double> g;
  return Eigen::Quaterniond(Eigen::Vector4d(g(rng), g(rng), g(rng), g(rng)).normalized()).toRotationMatrix();
}

// Every cutter kind, with a finite cutting length (a tilted drop needs one).
std::vector<Cutter> finite_cutters() {
  return {
      Cutter::apt(3, 3, 9, 0, 0),                                         // ball
      Cutter::apt(3, 0, 7, 0, 0),                                         // flat
      Cutter::apt(5, 2, 8, 0, 0),                                         // bull
      Cutter::apt(4, 0, 4 * std::tan(60 * kDeg), 60 * kDeg, 0),          // V-bit (bottom cone)
      Cutter::apt(5, 0, 4, 0, 45 * kDeg),                                 // chamfer (flat tip, taper)
      Cutter::apt(1.5 / std::cos(0.1) + 8.5 * std::tan(0.1), 1.5, 10, 0, 0.1),  // tapered ball
      Cutter::apt(5, 1.2, 8, 10 * kDeg, 8 * kDeg),                        // cone-bottom tapered bull
      Cutter::apt(3.5, 1.0, 6, 0, -5 * kDeg),                             // inward taper
      Cutter::apt(3, 0, 3, 0, 45 * kDeg),                                 // sharp V-bit by a taper
  };
}

// ---- independent references -------------------------------------------------------------------------------

// Möller–Trumbore, two-sided: the parameter where o + t d crosses the triangle, or +inf.
double ray_triangle(const Vector3d& o, const Vector3d& d, const Vector3d& a, const Vector3d& b, const Vector3d& c) {
  const Vector3d e1 = b - a, e2 = c - a;
  const Vector3d p = d.cross(e2);
  const double det = e1.dot(p);
  if (std::fabs(det) < 1e-14) return INFINITY;
  const double inv = 1.0 / det;
  const Vector3d s = o - a;
  const double u = s.dot(p) * inv;
  if (u < 0 || u > 1) return INFINITY;
  const Vector3d q = s.cross(e1);
  const double v = d.dot(q) * inv;
  if (v < 0 || u + v > 1) return INFINITY;
  return e2.dot(q) * inv;
}

// Points of the boundary of K in the tool frame: the lower profile (uniform in arc length: cone, arc, taper),
// the cylinder band above a vertical arc end, and the top cap; each ring sampled in angle.
std::vector<Vector3d> boundary_samples(const Cutter& c, int n_profile, int n_angles) {
  std::vector<std::pair<double, double>> meridian;  // (rho, z)
  const double rho_a = c.flat_radius(), e = c.arc_centre_radius(), r = c.corner_radius();
  const double phi_end = c.beta2() > 0 ? M_PI / 2 - c.beta2() : M_PI / 2;
  const double rho_b = e + r * std::sin(phi_end);
  const double l1 = rho_a / std::cos(c.beta1()), l2 = r * (phi_end - c.beta1());
  const double l3 = c.max_radius() > rho_b + 1e-12 ? (c.max_radius() - rho_b) / std::sin(c.beta2()) : 0.0;
  const double total = l1 + l2 + l3;
  for (int i = 0; i <= n_profile; ++i) {
    const double s = total * i / n_profile;
    double rho;
    if (s <= l1) rho = l1 > 0 ? rho_a * s / l1 : 0.0;
    else if (s <= l1 + l2) rho = e + r * std::sin(c.beta1() + (s - l1) / r);
    else rho = rho_b + (c.max_radius() - rho_b) * (s - l1 - l2) / l3;
    rho = std::min(rho, c.max_radius());
    meridian.emplace_back(rho, c.height(rho));
  }
  const double L = c.cutting_length(), rm = c.max_radius();
  const double zb = c.height(rm);
  const int n_band = std::max(2, static_cast<int>(n_profile * (L - zb) / std::max(total, 1e-9)));
  for (int i = 1; i <= n_band && L > zb; ++i) meridian.emplace_back(rm, zb + (L - zb) * i / n_band);
  const int n_cap = std::max(2, static_cast<int>(n_profile * rm / std::max(total, 1e-9)));
  for (int i = 0; i < n_cap; ++i) meridian.emplace_back(rm * i / n_cap, L);
  std::vector<Vector3d> out;
  for (const auto& [rho, z] : meridian) {
    const int na = rho == 0.0 ? 1 : n_angles;
    for (int j = 0; j < na; ++j) {
      const double th = 2 * M_PI * j / na;
      out.emplace_back(rho * std::cos(th), rho * std::sin(th), z);
    }
  }
  return out;
}

// Inside K iff G <= 0 (tool frame, tip at the origin).
double clearance(const Cutter& c, const Vector3d& q) {
  const double rho = std::hypot(q.x(), q.y());
  return std::max({c.height(std::min(rho, c.max_radius())) - q.z(), q.z() - c.cutting_length(),
                   rho - c.max_radius()});
}

// The same sign, scaled near the lower surface to a first-order distance (for the touch check only).
double scaled_clearance(const Cutter& c, const Vector3d& q) {
  const double rho = std::hypot(q.x(), q.y()), rr = std::min(rho, c.max_radius());
  const double s = c.slope(rr);
  const double low = std::isfinite(s) ? (c.height(rr) - q.z()) / std::sqrt(1 + s * s) : 0.0;
  return std::max({low, q.z() - c.cutting_length(), rho - c.max_radius()});
}

// Reference for edges and vertices: the first t at which the line p + t V (a point of the triangle moving
// against the cutter) is inside K, scanning t over K's bounding ball in steps of `step` and bisecting on G.
// Every value returned is a true contact (within 1e-12), so the exact answer may never be later.
double line_entry_by_scan(const Cutter& c, const tmm::ToolFrame& fr, const Vector3d& start, const Vector3d& V,
                          const Vector3d& p, double step) {
  const Vector3d centre = start + fr.a * (0.5 * c.cutting_length());
  const double radius = std::hypot(c.max_radius(), 0.5 * c.cutting_length()) * 1.001;
  const double tc = (p - centre).dot(V);  // the tip at start + t V passes p's foot at t = -tc... see below
  // Q(t) = p - (start + t V) in the tool frame: inside K for t in a chord about t* = (p - centre) . V.
  const double lo = tc - radius, hi = tc + radius;
  auto G = [&](double t) { return clearance(c, fr.to_tool(p - start - t * V)); };
  double prev = lo;
  for (double t = lo; t <= hi + step; t += step) {
    if (G(t) <= 0) {
      double a = prev, b = t;
      if (G(a) <= 0) return a;
      for (int i = 0; i < 200 && b - a > 1e-13; ++i) {
        const double m = 0.5 * (a + b);
        (G(m) <= 0 ? b : a) = m;
      }
      return b;
    }
    prev = t;
  }
  return INFINITY;
}

struct Sampled {
  double least = INFINITY;     // min G over the triangle samples
  double least_scaled = INFINITY;
};

Sampled triangle_samples(const Cutter& c, const tmm::ToolFrame& fr, const Vector3d& tip, const Vector3d& a,
                         const Vector3d& b, const Vector3d& p, int n) {
  Sampled s;
  for (int i = 0; i <= n; ++i)
    for (int j = 0; i + j <= n; ++j) {
      const Vector3d q = fr.to_tool(a + (b - a) * (double(i) / n) + (p - a) * (double(j) / n) - tip);
      s.least = std::min(s.least, clearance(c, q));
      s.least_scaled = std::min(s.least_scaled, scaled_clearance(c, q));
    }
  return s;
}

// ---- (1) V = -Z with axis = +Z is the -Z drop ------------------------------------------------------------

void check_minus_z(const Cutter& cut, int cases, unsigned seed) {
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  const double R = cut.max_radius(), span = 1.5 * R;
  int contacts = 0;
  for (int k = 0; k < cases; ++k) {
    const Vector3d a(u(rng) * span, u(rng) * span, u(rng) * R), b(u(rng) * span, u(rng) * span, u(rng) * R),
        c(u(rng) * span, u(rng) * span, u(rng) * R);
    const double x = u(rng) * R * 0.5, y = u(rng) * R * 0.5, z0 = 3 * R * u(rng);
    const auto index = one_triangle(a, b, c);
    const double tip = tmm::drop_on_triangle(cut, x, y, index.triangles()[0]);
    const Vector3d start(x, y, z0);
    const double t = tmm::drop_along(cut, start, Vector3d::UnitZ(), -Vector3d::UnitZ(), index.triangles()[0]);
    // The general method needs a finite cutting length: far above the triangles, it changes nothing here.
    const Cutter finite = std::isfinite(cut.cutting_length())
                              ? cut
                              : Cutter::apt(cut.radius(), cut.corner_radius(), 100 * R, 0, 0);
    const double tg = tmm::drop_along_general(finite, start, Vector3d::UnitZ(), -Vector3d::UnitZ(), a, b, c);
    if (tip == tmm::kNoContact) {
      EXPECT_EQ(t, tmm::kNoTravel) << "case " << k;
      // The general method may only find a grazing contact the -Z form rounds away.
      if (tg != tmm::kNoTravel) {
        const Sampled s = triangle_samples(cut, tmm::ToolFrame(Vector3d::UnitZ()), start - tg * Vector3d::UnitZ(), a,
                                           b, c, 60);
        EXPECT_GE(s.least, -1e-9) << k;
      }
      continue;
    }
    ++contacts;
    EXPECT_NEAR(z0 - t, tip, 1e-12) << "case " << k;
    EXPECT_NEAR(z0 - tg, tip, 1e-9) << "case " << k << " (general method)";
  }
  EXPECT_GT(contacts, cases / 3);
}

TEST(DropDirection, MinusZEqualsDropCutterPlain) {
  check_minus_z(Cutter(3, 3), 1500, 1);
  check_minus_z(Cutter(3, 0), 1500, 2);
  check_minus_z(Cutter(5, 2), 1500, 3);
  check_minus_z(Cutter(5, 0.3), 800, 4);
}

TEST(DropDirection, MinusZEqualsDropCutterApt) {
  unsigned seed = 10;
  for (const Cutter& c : finite_cutters()) check_minus_z(c, 800, seed++);
}

// ---- (3) random axes and directions against the references ------------------------------------------------

void check_random_directions(const Cutter& cut, int cases, unsigned seed) {
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  const double size = std::max(cut.max_radius(), cut.cutting_length());
  const std::vector<Vector3d> samples = boundary_samples(cut, 90, 120);
  int contacts = 0, checked_close = 0;
  for (int k = 0; k < cases; ++k) {
    const Vector3d axis = random_unit(rng), V = random_unit(rng);
    const Vector3d start(u(rng) * size, u(rng) * size, u(rng) * size);
    const Vector3d centre = start + axis * (0.5 * cut.cutting_length()) + V * (u(rng) * size);
    const double S = 0.8 * size;
    const Vector3d a = centre + Vector3d(u(rng), u(rng), u(rng)) * S, b = centre + Vector3d(u(rng), u(rng), u(rng)) * S,
                   c = centre + Vector3d(u(rng), u(rng), u(rng)) * S;
    const Vector3d nrm = (b - a).cross(c - a);
    if (nrm.norm() < 1e-3 * S * S) continue;
    const double t = tmm::drop_along(cut, start, axis, V, a, b, c);
    const tmm::ToolFrame fr(axis);
    double ref = INFINITY;
    for (const Vector3d& x : samples) ref = std::min(ref, ray_triangle(start + fr.to_world(x), V, a, b, c));
    const Vector3d corner[3] = {a, b, c};
    for (int i = 0; i < 3; ++i)
      for (int j = 0; j < 150; ++j) {
        const Vector3d p = corner[i] + (corner[(i + 1) % 3] - corner[i]) * (j / 150.0);
        ref = std::min(ref, line_entry_by_scan(cut, fr, start, V, p, 0.01 * size));
      }
    if (t == tmm::kNoTravel) {
      EXPECT_EQ(ref, INFINITY) << "case " << k << " (missed contact)";
      continue;
    }
    ASSERT_TRUE(std::isfinite(t)) << "case " << k;
    const Sampled s = triangle_samples(cut, fr, start + t * V, a, b, c, 120);
    EXPECT_GE(s.least, -1e-9) << "case " << k << " (gouge: triangle inside the cutter)";
    EXPECT_LE(s.least_scaled, 0.03 * size) << "case " << k << " (no touch)";
    if (ref == INFINITY) continue;  // the sampled cutter passes by: a grazing contact
    ++contacts;
    EXPECT_LE(t, ref + 1e-9) << "case " << k << " (a sampled contact happens before the exact one)";
    if (std::fabs(nrm.normalized().dot(V)) > std::cos(75 * kDeg)) {
      ++checked_close;
      EXPECT_LE(ref - t, 0.02 * size) << "case " << k;
    }
  }
  EXPECT_GT(contacts, cases / 3);
  EXPECT_GT(checked_close, cases / 5);
}

TEST(DropDirection, RandomDirectionsBall) { check_random_directions(finite_cutters()[0], 500, 101); }
TEST(DropDirection, RandomDirectionsFlat) { check_random_directions(finite_cutters()[1], 500, 102); }
TEST(DropDirection, RandomDirectionsBull) { check_random_directions(finite_cutters()[2], 500, 103); }
TEST(DropDirection, RandomDirectionsVBit) { check_random_directions(finite_cutters()[3], 400, 104); }
TEST(DropDirection, RandomDirectionsChamfer) { check_random_directions(finite_cutters()[4], 400, 105); }
TEST(DropDirection, RandomDirectionsTaperedBall) { check_random_directions(finite_cutters()[5], 400, 106); }
TEST(DropDirection, RandomDirectionsConeBottomTaperedBull) { check_random_directions(finite_cutters()[6], 400, 107); }
TEST(DropDirection, RandomDirectionsInwardTaper) { check_random_directions(finite_cutters()[7], 400, 108); }
TEST(DropDirection, RandomDirectionsSharpVBitByTaper) { check_random_directions(finite_cutters()[8], 400, 109); }

// ---- (2) rotation invariance ------------------------------------------------------------------------------

TEST(DropDirection, RotationInvariance) {
  std::mt19937_64 rng(7);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  const auto cutters = finite_cutters();
  int contacts = 0;
  for (int k = 0; k < 3000; ++k) {
    const Cutter& cut = cutters[k % cutters.size()];
    const double size = std::max(cut.max_radius(), cut.cutting_length());
    const Vector3d axis = random_unit(rng), V = random_unit(rng), start(u(rng), u(rng), u(rng));
    const Vector3d centre = start + axis * (0.5 * cut.cutting_length());
    Vector3d p[3];
    for (auto& q : p) q = centre + Vector3d(u(rng), u(rng), u(rng)) * size;
    const double t = tmm::drop_along(cut, start, axis, V, p[0], p[1], p[2]);
    const Eigen::Matrix3d Q = random_rotation(rng);
    const Vector3d shift(u(rng) * 50, u(rng) * 50, u(rng) * 50);
    const double tr = tmm::drop_along(cut, Q * start + shift, Q * axis, Q * V, Q * p[0] + shift, Q * p[1] + shift,
                                      Q * p[2] + shift);
    if (t == tmm::kNoTravel) {
      // Only a grazing contact may appear or vanish under rounding.
      if (tr != tmm::kNoTravel) {
        const Sampled s = triangle_samples(cut, tmm::ToolFrame(axis), start + tr * V, p[0], p[1], p[2], 60);
        EXPECT_GE(s.least, -1e-9) << k;
      }
      continue;
    }
    ++contacts;
    EXPECT_NEAR(tr, t, 1e-9) << "case " << k;
  }
  EXPECT_GT(contacts, 1000);
}

// ---- closed forms -----------------------------------------------------------------------------------------

TEST(DropDirection, ClosedForms) {
  const Cutter ball = Cutter::apt(2, 2, 10, 0, 0), flat = Cutter::apt(2, 0, 10, 0, 0);
  // A ball moving along +X onto a vertical wall x = 5: the sphere (centre 2 above the tip) touches at x = 3.
  const Vector3d w0(5, -50, -50), w1(5, 50, -50), w2(5, 0, 50);
  EXPECT_NEAR(tmm::drop_along(ball, Vector3d(0, 0, 0), Vector3d::UnitZ(), Vector3d::UnitX(), w0, w1, w2), 3.0, 1e-12);
  // The flat end mill, axis -X, moving along +X (tip first): its bottom face reaches the wall at travel 5.
  EXPECT_NEAR(tmm::drop_along(flat, Vector3d(0, 0, 0), -Vector3d::UnitX(), Vector3d::UnitX(), w0, w1, w2), 5.0, 1e-12);
  EXPECT_NEAR(tmm::drop_along_general(flat, Vector3d(0, 0, 0), -Vector3d::UnitX(), Vector3d::UnitX(), w0, w1, w2), 5.0,
              1e-12);
  // Axis +X, moving along +X: the top cap (L_C = 10 ahead of the tip) leads: travel 5 - 10.
  EXPECT_NEAR(tmm::drop_along(flat, Vector3d(0, 0, 0), Vector3d::UnitX(), Vector3d::UnitX(), w0, w1, w2), -5.0, 1e-12);
  // Axis +Z, moving along +X onto the wall: the cylinder (radius 2) touches at x = 3.
  EXPECT_NEAR(tmm::drop_along(flat, Vector3d(0, 0, 0), Vector3d::UnitZ(), Vector3d::UnitX(), w0, w1, w2), 3.0, 1e-12);
  // A horizontal edge along Y at height 1, the ball moving along +X: the ball centre (height 2) reaches
  // distance 2 from the edge at x = 5 - sqrt(3).
  const double t = tmm::drop_along(ball, Vector3d(0, 0, 0), Vector3d::UnitZ(), Vector3d::UnitX(), Vector3d(5, -40, 1),
                                   Vector3d(5, 40, 1), Vector3d(5, 0, -30));
  EXPECT_NEAR(t, 5 - std::sqrt(3.0), 1e-9);
  // A vertex: the point (5, 0, 2) (the ball centre's height) is reached at x = 3.
  EXPECT_NEAR(tmm::drop_along(ball, Vector3d(0, 0, 0), Vector3d::UnitZ(), Vector3d::UnitX(), Vector3d(5, 0, 2),
                              Vector3d(9, 1, 2), Vector3d(9, -1, 2)),
              3.0, 1e-9);
  EXPECT_THROW(tmm::drop_along(ball, Vector3d(0, 0, 0), Vector3d(0, 0, 2), Vector3d::UnitX(), w0, w1, w2),
               std::invalid_argument);
  EXPECT_THROW(tmm::drop_along(ball, Vector3d(0, 0, 0), Vector3d::UnitZ(), Vector3d(NAN, 0, 0), w0, w1, w2),
               std::invalid_argument);
}

// ---- mesh level -------------------------------------------------------------------------------------------

struct Grid {
  tmm::Vertices V;
  tmm::Triangles F;
};

Grid bumpy_grid(int n) {
  Grid g;
  g.V.resize((n + 1) * (n + 1), 3);
  std::mt19937_64 rng(5);
  std::uniform_real_distribution<double> jitter(-0.3, 0.3);
  for (int i = 0; i <= n; ++i)
    for (int j = 0; j <= n; ++j) {
      const double x = i + jitter(rng), y = j + jitter(rng);
      g.V.row(i * (n + 1) + j) << x, y, 3 * std::sin(x / 5) * std::cos(y / 7) + jitter(rng);
    }
  g.F.resize(2 * n * n, 3);
  int t = 0;
  for (int i = 0; i < n; ++i)
    for (int j = 0; j < n; ++j) {
      const int v = i * (n + 1) + j;
      g.F.row(t++) << v, v + n + 1, v + 1;
      g.F.row(t++) << v + 1, v + n + 1, v + n + 2;
    }
  return g;
}

TEST(DropDirection, MeshQueryEqualsBruteForce) {
  const Grid g = bumpy_grid(30);
  std::mt19937_64 rng(9);
  std::uniform_real_distribution<double> pos(-2, 32), u(-1, 1);
  for (const Cutter& cut : {Cutter::apt(2, 2, 6, 0, 0), Cutter::apt(3, 1, 8, 10 * kDeg, 5 * kDeg),
                            Cutter::apt(3, 3, 15, 0, 0)}) {
    for (int k = 0; k < 30; ++k) {
      Vector3d V = Vector3d(0.6 * u(rng), 0.6 * u(rng), -1).normalized();
      if (k == 0) V = -Vector3d::UnitZ();
      const tmm::DirectionalIndex index(g.V, g.F, V);
      for (int j = 0; j < 5; ++j) {
        const Vector3d axis = (j == 0) ? Vector3d(-V) : Vector3d(0.7 * u(rng), 0.7 * u(rng), 1).normalized();
        const Vector3d start(pos(rng), pos(rng), 20);
        double brute = tmm::kNoTravel;
        for (int f = 0; f < g.F.rows(); ++f)
          brute = std::min(brute, tmm::drop_along(cut, start, axis, V, g.V.row(g.F(f, 0)).transpose(),
                                                  g.V.row(g.F(f, 1)).transpose(), g.V.row(g.F(f, 2)).transpose()));
        const double t = tmm::drop_along_point(index, cut, start, axis);
        if (brute == tmm::kNoTravel) EXPECT_EQ(t, brute) << k << " " << j;
        else EXPECT_NEAR(t, brute, 1e-9) << k << " " << j;
      }
    }
  }
}

TEST(DropDirection, MinusZMeshIsDropPoint) {
  const Grid g = bumpy_grid(40);
  const tmm::MeshIndex plain(g.V, g.F);
  const tmm::DirectionalIndex index(g.V, g.F, -Vector3d::UnitZ());
  const Cutter cut(2, 1);  // endless cutting length: fine along the axis
  std::mt19937_64 rng(3);
  std::uniform_real_distribution<double> pos(-2, 42);
  for (int k = 0; k < 2000; ++k) {
    const double x = pos(rng), y = pos(rng);
    const double z = tmm::drop_point(plain, cut, x, y, -100);
    const double t = tmm::drop_along_point(index, cut, Vector3d(x, y, 50), Vector3d::UnitZ(), 150);
    EXPECT_NEAR(50 - t, z, 1e-12) << k;
  }
  // A tilted axis needs a finite cutting length.
  EXPECT_THROW(tmm::drop_along_point(index, cut, Vector3d(1, 1, 50), Vector3d(0, 0.6, 0.8)), std::invalid_argument);
}

// With axis = -V for every point the batch runs the tiled -Z batch in the rotated frame, each point with its
// own floor: the same travels as point by point, on a dense raster of starts at different heights, with a
// finite travel (some starts miss) and an endless one.
TEST(DropDirection, AxisAlongVBatchIsPointByPoint) {
  const Grid g = bumpy_grid(40);
  const Vector3d V = Vector3d(0.2, -0.3, -1).normalized();
  const tmm::DirectionalIndex index(g.V, g.F, V);
  const Vector3d axis = -V;
  std::mt19937_64 rng(17);
  std::uniform_real_distribution<double> height(6, 30);
  const int n = 4000;
  std::vector<double> starts;
  for (int i = 0; i < n; ++i) {
    starts.push_back(2 + (i % 80) * 0.45);
    starts.push_back(2 + (i / 80) * 0.7);
    starts.push_back(height(rng));
  }
  for (const Cutter& cut : {Cutter(2, 2), Cutter(2.5, 1), Cutter::apt(2, 0.5, 6, 0, 0.1)}) {
    for (const double max_travel : {22.0, tmm::kNoTravel}) {
      std::vector<double> t(n);
      tmm::BatchOptions two;
      two.threads = 2;
      tmm::DropStats stats;
      tmm::drop_along_batch(index, cut, starts.data(), axis.data(), false, n, max_travel, t.data(), two, &stats);
      EXPECT_GT(stats.triangles_tested, 0u);
      int contacts = 0, misses = 0;
      for (int i = 0; i < n; ++i) {
        const double tp = tmm::drop_along_point(index, cut, Vector3d(&starts[3 * i]), axis, max_travel);
        contacts += t[i] < max_travel;
        misses += t[i] == max_travel;
        if (tp == max_travel) {
          EXPECT_EQ(t[i], max_travel) << i;
        } else {
          EXPECT_NEAR(t[i], tp, 1e-12) << i;
        }
      }
      EXPECT_GT(contacts, n / 2);
      if (max_travel == 22.0) {
        EXPECT_GT(misses, 0);
      }
    }
  }
}

// One tilted axis for a whole raster: the batch sets the solid up with planes every few degrees around the
// axis and tests each candidate's corners against those facing it; the travels equal the minimum over every
// triangle of the per-triangle contact (no index, no planes) at every start, for a wide thin disc (a holder's
// rim: the planes there are far from its edge unless they face it) and a bull-nose.
TEST(DropDirection, TiltedRasterBatchEqualsEveryTriangle) {
  const Grid g = bumpy_grid(24);
  const Vector3d V = Vector3d(0.25, -0.1, -1).normalized();
  const tmm::DirectionalIndex index(g.V, g.F, V);
  const Vector3d axis = Vector3d(-0.2, 0.35, 1).normalized();  // about 28 deg off -V
  const int side = 14, n = side * side;
  std::vector<double> starts;
  for (int i = 0; i < n; ++i)  // a zig-zag raster, as a path visits it
    starts.insert(starts.end(), {-2 + 2.0 * (i / side % 2 ? side - 1 - i % side : i % side), -2 + 2.0 * (i / side), 14});
  for (const Cutter& cut : {Cutter::apt(9, 2, 2, 0, 0), Cutter::apt(3, 1, 8, 0, 0)}) {
    std::vector<double> t(n);
    tmm::BatchOptions one;
    one.threads = 1;
    tmm::drop_along_batch(index, cut, starts.data(), axis.data(), false, n, tmm::kNoTravel, t.data(), one);
    int contacts = 0;
    for (int i = 0; i < n; ++i) {
      const Vector3d start(&starts[3 * i]);
      double brute = tmm::kNoTravel;
      for (int f = 0; f < g.F.rows(); ++f)
        brute = std::min(brute, tmm::drop_along(cut, start, axis, V, g.V.row(g.F(f, 0)).transpose(),
                                                g.V.row(g.F(f, 1)).transpose(), g.V.row(g.F(f, 2)).transpose()));
      if (brute == tmm::kNoTravel) {
        EXPECT_EQ(t[i], brute) << i;
      } else {
        EXPECT_NEAR(t[i], brute, 1e-9) << i;
        ++contacts;
      }
    }
    EXPECT_GT(contacts, n / 2);
  }
}

TEST(DropDirection, BatchThreadsAgreeAndCancel) {
  const Grid g = bumpy_grid(30);
  const Vector3d V = Vector3d(0.3, -0.2, -1).normalized();
  const tmm::DirectionalIndex index(g.V, g.F, V);
  const Cutter cut = Cutter::apt(2, 1, 6, 0, 0);
  const Vector3d axis = Vector3d(-0.2, 0.3, 1).normalized();
  const int n = 3000;
  std::vector<double> starts;
  for (int i = 0; i < n; ++i) {
    starts.push_back((i % 60) * 0.5);
    starts.push_back((i / 60) * 0.6);
    starts.push_back(15);
  }
  std::vector<double> t1(n), t2(n);
  tmm::BatchOptions one;
  one.threads = 1;
  tmm::drop_along_batch(index, cut, starts.data(), axis.data(), false, n, tmm::kNoTravel, t1.data(), one);
  tmm::BatchOptions two;
  two.threads = 2;
  double last = -1;
  two.progress = [&](double f) { EXPECT_GE(f, last); last = f; return true; };
  tmm::drop_along_batch(index, cut, starts.data(), axis.data(), false, n, tmm::kNoTravel, t2.data(), two);
  EXPECT_EQ(last, 1.0);
  // Equal up to rounding: which of the triangles sharing the touched vertex or edge wins depends on the
  // visiting order (hints, chunks per thread).
  int contacts = 0;
  for (int i = 0; i < n; ++i) {
    contacts += std::isfinite(t1[i]);
    const double tp = tmm::drop_along_point(index, cut, Vector3d(&starts[3 * i]), axis);
    EXPECT_TRUE(t1[i] == t2[i] || std::fabs(t1[i] - t2[i]) <= 1e-9) << i << " " << t1[i] << " " << t2[i];
    EXPECT_TRUE(t1[i] == tp || std::fabs(t1[i] - tp) <= 1e-9) << i << " " << t1[i] << " " << tp;
  }
  EXPECT_GT(contacts, n / 2);
  tmm::BatchOptions cancel;
  cancel.progress = [](double) { return false; };
  std::vector<double> big, tb(200000);
  for (int i = 0; i < 200000; ++i) big.insert(big.end(), {15.0, 15.0, 15.0});
  EXPECT_THROW(tmm::drop_along_batch(index, cut, big.data(), axis.data(), false, 200000, tmm::kNoTravel, tb.data(),
                                     cancel),
               tmm::Cancelled);
}

}  // namespace
