// Drop-cutter against closed forms and against slow independent references:
//  - cutter sampling: the highest tip over a dense grid of points of the cutter's lower surface lying over
//    the triangle (never above the exact answer, and close below it),
//  - triangle sampling: no sample of the triangle penetrates the cutter at the returned height (gouge),
//    and the nearest sample touches it,
//  - for the ball, the exact point-triangle distance from the ball centre equals the radius,
//  - the indexed query equals the maximum over all triangles.
#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <random>
#include <utility>
#include <vector>

#include "tmm/query/drop_contacts.hpp"
#include "tmm/query/drop_cutter.hpp"
#include "tmm/mesh/mesh_index.hpp"
#include "support/test_geometry.hpp"
#include "support/test_meshes.hpp"

namespace {

using tmm::Cutter;
using Eigen::Vector3d;

using tmm_test::bumpy_grid;
using tmm_test::one_triangle;

double drop1(const Cutter& c, double x, double y, const Vector3d& a, const Vector3d& b, const Vector3d& p) {
  const auto index = one_triangle(a, b, p);
  return tmm::drop_on_triangle(c, x, y, index.triangles()[0]);
}

// Closest point of a triangle to p (Ericson, Real-Time Collision Detection 5.1.5): independent of the kernel.
Vector3d closest_on_triangle(const Vector3d& p, const Vector3d& a, const Vector3d& b, const Vector3d& c) {
  const Vector3d ab = b - a, ac = c - a, ap = p - a;
  const double d1 = ab.dot(ap), d2 = ac.dot(ap);
  if (d1 <= 0 && d2 <= 0) return a;
  const Vector3d bp = p - b;
  const double d3 = ab.dot(bp), d4 = ac.dot(bp);
  if (d3 >= 0 && d4 <= d3) return b;
  const double vc = d1 * d4 - d3 * d2;
  if (vc <= 0 && d1 >= 0 && d3 <= 0) return a + d1 / (d1 - d3) * ab;
  const Vector3d cp = p - c;
  const double d5 = ab.dot(cp), d6 = ac.dot(cp);
  if (d6 >= 0 && d5 <= d6) return c;
  const double vb = d5 * d2 - d1 * d6;
  if (vb <= 0 && d2 >= 0 && d6 <= 0) return a + d2 / (d2 - d6) * ac;
  const double va = d3 * d6 - d5 * d4;
  if (va <= 0 && (d4 - d3) >= 0 && (d5 - d6) >= 0) return b + (d4 - d3) / ((d4 - d3) + (d5 - d6)) * (c - b);
  const double denom = 1.0 / (va + vb + vc);
  return a + ab * (vb * denom) + ac * (vc * denom);
}

using tmm_test::inside_xy;

double plane_z(double x, double y, const Vector3d& a, const Vector3d& b, const Vector3d& c) {
  const Vector3d n = (b - a).cross(c - a);
  return a.z() - (n.x() * (x - a.x()) + n.y() * (y - a.y())) / n.z();
}

// Reference 1: the highest tip over a grid of the cutter's lower surface, uniform in arc length along each
// piece of the profile (cone in radius, corner arc in angle, taper in radius) and in angle about the axis.
std::vector<double> profile_radii(const Cutter& c, int n) {
  std::vector<double> rho;
  const double rho_a = c.flat_radius(), e = c.arc_centre_radius(), r = c.corner_radius();
  const double phi_end = c.beta2() > 0 ? M_PI / 2 - c.beta2() : M_PI / 2;
  const double rho_b = e + r * std::sin(phi_end);
  const double l1 = rho_a / std::cos(c.beta1()), l2 = r * (phi_end - c.beta1());
  const double l3 = c.max_radius() > rho_b ? (c.max_radius() - rho_b) / std::sin(c.beta2()) : 0.0;
  const double total = l1 + l2 + l3;
  for (int i = 0; i <= n; ++i) {
    const double s = total * i / n;
    if (s <= l1) rho.push_back(l1 > 0 ? rho_a * s / l1 : 0.0);
    else if (s <= l1 + l2) rho.push_back(e + r * std::sin(c.beta1() + (s - l1) / r));
    else rho.push_back(rho_b + (c.max_radius() - rho_b) * (s - l1 - l2) / l3);
  }
  return rho;
}

double cutter_sampling_reference(const Cutter& c, double x, double y, const Vector3d& a, const Vector3d& b,
                                 const Vector3d& p, int rings, int angles) {
  double best = tmm::kNoContact;
  for (const double rho : profile_radii(c, rings)) {
    const int na = rho == 0.0 ? 1 : angles;
    for (int j = 0; j < na; ++j) {
      const double th = 2 * M_PI * j / na;
      const double qx = x + rho * std::cos(th), qy = y + rho * std::sin(th);
      if (!inside_xy(qx, qy, a, b, p)) continue;
      best = std::max(best, plane_z(qx, qy, a, b, p) - c.height(std::fmin(rho, c.max_radius())));
    }
  }
  return best;
}

// Reference 2: over a barycentric grid of the triangle, the least clearance (tip + h(rho)) - q.z of the
// samples in the cutter's shadow. The tool occupies everything above its lower surface, so a negative
// clearance means a triangle point inside the tool (gouge); zero means touching.
double triangle_sampling_clearance(const Cutter& c, double x, double y, double tip, const Vector3d& a,
                                   const Vector3d& b, const Vector3d& p, int n) {
  double least = INFINITY;
  for (int i = 0; i <= n; ++i) {
    for (int j = 0; i + j <= n; ++j) {
      const Vector3d q = a + (b - a) * (double(i) / n) + (p - a) * (double(j) / n);
      const double rho = std::hypot(q.x() - x, q.y() - y);
      if (rho > c.max_radius()) continue;
      least = std::min(least, (tip + c.height(rho)) - q.z());
    }
  }
  return least;
}

TEST(DropClosedForm, HorizontalFacet) {
  const Vector3d a(-50, -50, 7), b(50, -50, 7), c(0, 60, 7);
  for (const Cutter& cut : {Cutter(3, 3), Cutter(3, 0), Cutter(5, 2)}) {
    EXPECT_NEAR(drop1(cut, 1.5, -2.0, a, b, c), 7.0, 1e-12);
  }
}

TEST(DropClosedForm, TiltedFacet) {
  // Plane z = x tan(alpha) + 2, rising along +X.
  for (double alpha_deg : {5.0, 30.0, 60.0, 85.0}) {
    const double t = std::tan(alpha_deg * M_PI / 180), ca = std::cos(alpha_deg * M_PI / 180);
    auto z = [&](double x) { return x * t + 2; };
    const Vector3d a(-100, -100, z(-100)), b(100, -100, z(100)), c(0, 100, z(0));
    const double x = 3, y = -10;
    const double R = 4, r = 1.5;
    EXPECT_NEAR(drop1(Cutter(R, R), x, y, a, b, c), z(x) + R / ca - R, 1e-9) << alpha_deg;
    EXPECT_NEAR(drop1(Cutter(R, 0), x, y, a, b, c), z(x + R), 1e-9) << alpha_deg;
    EXPECT_NEAR(drop1(Cutter(R, r), x, y, a, b, c), z(x) + (R - r) * t + r / ca - r, 1e-9) << alpha_deg;
  }
}

TEST(DropClosedForm, VertexSpike) {
  // A thin vertical sliver whose top vertex at (1, 0.5, 10) is the only reachable point.
  const Vector3d top(1, 0.5, 10), b(1.0, 0.5, -20), c(1.0001, 0.5, -20);
  const double rho = std::hypot(1.0, 0.5);
  EXPECT_NEAR(drop1(Cutter(3, 3), 0, 0, top, b, c), 10 - (3 - std::sqrt(9 - rho * rho)), 1e-9);
  EXPECT_NEAR(drop1(Cutter(3, 0), 0, 0, top, b, c), 10, 1e-9);
  const Cutter bull(3, 2.5);  // rho = 1.118 > R - r = 0.5: on the torus
  EXPECT_NEAR(drop1(bull, 0, 0, top, b, c), 10 - bull.height(rho), 1e-9);
  EXPECT_EQ(drop1(Cutter(1, 1), 0, 0, top, b, c), tmm::kNoContact);
}

TEST(DropClosedForm, HorizontalRidgeEdge) {
  // Edge along X at y = 0, z = 5, the triangle falling away steeply on one side.
  const Vector3d a(-50, 0, 5), b(50, 0, 5), c(0, 0.001, -100);
  for (double d : {0.0, 0.7, 1.9, 2.9}) {
    EXPECT_NEAR(drop1(Cutter(3, 3), 0.3, -d, a, b, c), 5 - 3 + std::sqrt(9 - d * d), 1e-9) << d;
    EXPECT_NEAR(drop1(Cutter(3, 0), 0.3, -d, a, b, c), 5, 1e-9) << d;
    const Cutter bull(3, 1);
    EXPECT_NEAR(drop1(bull, 0.3, -d, a, b, c), 5 - bull.height(d), 1e-9) << d;
  }
}

TEST(DropClosedForm, InclinedEdgeBall) {
  // Edge on the line z = m x, y = 0; the ball centre is where the 3D distance to the line equals R:
  // x0^2 + d^2 + zc^2 - (x0 + m zc)^2 / (1 + m^2) = R^2, the larger root.
  const double R = 3;
  for (double m : {0.2, 1.0, 3.0}) {
    for (double d : {0.0, 1.0, 2.5}) {
      const double x0 = 1.0;
      const Vector3d a(-40, 0, -40 * m), b(40, 0, 40 * m), c(0, 1e-4, -200);
      const double k = 1 + m * m;
      // (1 - m^2/k) zc^2 - (2 x0 m / k) zc + (x0^2 + d^2 - x0^2/k - R^2) = 0
      const double A = 1 - m * m / k, B = -2 * x0 * m / k, C = x0 * x0 + d * d - x0 * x0 / k - R * R;
      const double zc = (-B + std::sqrt(B * B - 4 * A * C)) / (2 * A);
      EXPECT_NEAR(drop1(Cutter(R, R), x0, -d, a, b, c), zc - R, 1e-9) << m << " " << d;
    }
  }
}

struct RandomCase {
  Vector3d a, b, c;
  double x, y;
};

RandomCase random_case(std::mt19937_64& rng, double R) {
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  RandomCase rc;
  const double span = R * 1.5;
  rc.a = Vector3d(u(rng) * span, u(rng) * span, u(rng) * R);
  rc.b = Vector3d(u(rng) * span, u(rng) * span, u(rng) * R);
  rc.c = Vector3d(u(rng) * span, u(rng) * span, u(rng) * R);
  rc.x = u(rng) * R * 0.5;
  rc.y = u(rng) * R * 0.5;
  return rc;
}

void check_against_references(const Cutter& cut, int cases, unsigned seed) {
  std::mt19937_64 rng(seed);
  int contacts = 0;
  for (int k = 0; k < cases; ++k) {
    const RandomCase rc = random_case(rng, cut.max_radius());
    if (std::fabs(((rc.b - rc.a).cross(rc.c - rc.a)).z()) < 1e-3) continue;  // near-vertical: see VertexSpike
    const double tip = drop1(cut, rc.x, rc.y, rc.a, rc.b, rc.c);
    const double ref = cutter_sampling_reference(cut, rc.x, rc.y, rc.a, rc.b, rc.c, 200, 480);
    if (ref == tmm::kNoContact) {
      // The sampled cutter misses the triangle: the exact answer may only be a grazing contact.
      if (tip != tmm::kNoContact) {
        EXPECT_GE(triangle_sampling_clearance(cut, rc.x, rc.y, tip, rc.a, rc.b, rc.c, 200), -1e-9);
      }
      continue;
    }
    ++contacts;
    ASSERT_NE(tip, tmm::kNoContact) << "case " << k;
    // No sampled point of the cutter may lie below the triangle at the exact height...
    EXPECT_LE(ref, tip + 1e-9) << "case " << k << " (gouge)";
    // ...and the exact height is close to the best sampled one where that sampling is fine enough: its
    // error grows with the plane's gradient and the profile's slope, and it cannot land on a vertex, so it
    // is loose; the triangle sampling below is the strict check that the cutter touches.
    const Vector3d nrm = (rc.b - rc.a).cross(rc.c - rc.a).normalized();
    if (std::fabs(nrm.z()) > std::cos(75 * M_PI / 180)) {
      EXPECT_LE(tip - ref, 0.1 * std::max(cut.radius(), cut.height(cut.max_radius()))) << "case " << k;
    }
    // Triangle sampling: nothing penetrates, and the cutter touches.
    const double clearance = triangle_sampling_clearance(cut, rc.x, rc.y, tip, rc.a, rc.b, rc.c, 200);
    EXPECT_GE(clearance, -1e-9) << "case " << k << " (gouge)";
    EXPECT_LE(clearance, 0.02 * cut.radius()) << "case " << k << " (no touch)";
    if (cut.kind() == tmm::CutterKind::Ball) {
      const Vector3d centre(rc.x, rc.y, tip + cut.radius());
      const double dist = (closest_on_triangle(centre, rc.a, rc.b, rc.c) - centre).norm();
      EXPECT_NEAR(dist, cut.radius(), 1e-9) << "case " << k;
    }
  }
  EXPECT_GT(contacts, cases / 3);
}

TEST(DropReference, RandomTrianglesBall) { check_against_references(Cutter(3, 3), 1000, 1); }
TEST(DropReference, RandomTrianglesFlat) { check_against_references(Cutter(3, 0), 1000, 2); }
TEST(DropReference, RandomTrianglesBull) { check_against_references(Cutter(5, 2), 1000, 3); }
TEST(DropReference, RandomTrianglesThinTorus) { check_against_references(Cutter(5, 0.3), 800, 4); }
TEST(DropReference, RandomTrianglesFatTorus) { check_against_references(Cutter(5, 4.7), 800, 5); }

TEST(DropReference, RandomTrianglesVBit) {
  check_against_references(Cutter::apt(4, 0, 4 * std::tan(M_PI / 3), M_PI / 3, 0), 600, 21);
}
TEST(DropReference, RandomTrianglesChamfer) { check_against_references(Cutter::apt(5, 0, 4, 0, M_PI / 4), 600, 22); }
TEST(DropReference, RandomTrianglesTaperedBall) {
  check_against_references(Cutter::apt(1.5 / std::cos(0.1) + 8.5 * std::tan(0.1), 1.5, 10, 0, 0.1), 600, 23);
}
TEST(DropReference, RandomTrianglesConeBottomTaperedBull) {
  check_against_references(Cutter::apt(5, 1.2, 8, 10 * M_PI / 180, 8 * M_PI / 180), 600, 24);
}
TEST(DropReference, RandomTrianglesInwardTaper) {
  check_against_references(Cutter::apt(3.5, 1.0, 6, 0, -5 * M_PI / 180), 600, 25);
}

TEST(DropReference, RandomCutterSizes) {
  std::mt19937_64 rng(11);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  for (int k = 0; k < 30; ++k) {
    const double R = 0.5 + 9.5 * u(rng);
    const double r = R * u(rng);
    check_against_references(Cutter(R, r), 40, 100 + k);
  }
}

// The index finds exactly the maximum over all triangles, on a bumpy random mesh.
TEST(MeshIndex, QueryEqualsBruteForce) {
  const int n = 60;
  std::mt19937_64 rng(7);
  const auto [V, F] = bumpy_grid(n, 5, 7, rng);
  const tmm::MeshIndex index(V, F);
  std::uniform_real_distribution<double> pos(-2, n + 2);
  for (const Cutter& cut : {Cutter(2, 2), Cutter(2, 0), Cutter(3, 1)}) {
    for (int k = 0; k < 300; ++k) {
      const double x = pos(rng), y = pos(rng);
      double brute = -100;
      for (const auto& tri : index.triangles()) brute = std::max(brute, tmm::drop_on_triangle(cut, x, y, tri));
      EXPECT_NEAR(tmm::drop_point(index, cut, x, y, -100), brute, 1e-12);
    }
  }
}

// Batches are solved tile by tile over sorted candidate lists (drop_cutter.cpp): dense rasters take that
// path. Every height equals the maximum over all triangles, for every kind of cutter, with sparse and
// non-finite points mixed in; the same bits whatever the thread count; whatever the order of the points up
// to rounding (a vertex contact is reached through whichever of its edges the pruning leaves).
TEST(DropBatch, TiledRasterEqualsBruteForce) {
  const int n = 24;
  std::mt19937_64 rng(11);
  const auto [V, F] = bumpy_grid(n, 4, 5, rng);
  const tmm::MeshIndex index(V, F);
  std::vector<double> xy;
  for (int i = 0; i < 41; ++i)
    for (int j = 0; j < 41; ++j) {
      xy.push_back(-2 + 0.35 * j);  // rows along X, off the mesh on two sides
      xy.push_back(-2 + 0.35 * i);
    }
  std::uniform_real_distribution<double> far(-10, n + 10);
  for (int k = 0; k < 40; ++k) {  // sparse points: tiles of one or two points
    xy.push_back(far(rng));
    xy.push_back(far(rng));
  }
  xy.push_back(NAN);
  xy.push_back(3.0);
  const std::size_t m = xy.size() / 2;
  std::vector<std::size_t> perm(m);
  for (std::size_t i = 0; i < m; ++i) perm[i] = i;
  std::shuffle(perm.begin(), perm.end(), rng);
  std::vector<double> xy_shuffled(2 * m);
  for (std::size_t i = 0; i < m; ++i) {
    xy_shuffled[2 * i] = xy[2 * perm[i]];
    xy_shuffled[2 * i + 1] = xy[2 * perm[i] + 1];
  }
  const double floor_z = -50;
  for (const Cutter& cut : {Cutter(2, 2), Cutter(2, 0), Cutter(3, 1), Cutter::apt(2, 0.5, 6, 0, 0.1),
                            Cutter::apt(3, 0, 3 * std::tan(M_PI / 3), M_PI / 3, 0)}) {
    std::vector<double> z(m), z2(m), zs(m);
    tmm::BatchOptions one, two;
    one.threads = 1;
    two.threads = 2;
    tmm::DropStats stats;
    tmm::drop_batch(index, cut, xy.data(), m, floor_z, z.data(), one, &stats);
    tmm::drop_batch(index, cut, xy.data(), m, floor_z, z2.data(), two);
    tmm::drop_batch(index, cut, xy_shuffled.data(), m, floor_z, zs.data(), two);
    EXPECT_GT(stats.triangles_tested, 0u);
    for (std::size_t i = 0; i < m; ++i) {
      const double x = xy[2 * i], y = xy[2 * i + 1];
      EXPECT_EQ(z[i], z2[i]);
      EXPECT_NEAR(zs[std::find(perm.begin(), perm.end(), i) - perm.begin()], z[i], 1e-12);
      if (!std::isfinite(x)) {
        EXPECT_EQ(z[i], floor_z);
        continue;
      }
      double brute = floor_z;
      for (const auto& tri : index.triangles()) brute = std::max(brute, tmm::drop_on_triangle(cut, x, y, tri));
      ASSERT_NEAR(z[i], brute, 1e-12) << "point " << i << " at (" << x << ", " << y << ")";
    }
  }
}

TEST(MeshIndex, RejectsBadMeshes) {
  tmm::Vertices V(3, 3);
  V << 0, 0, 0, 1, 0, 0, 0, 1, 0;
  tmm::Triangles F(1, 3);
  F << 0, 1, 3;
  EXPECT_THROW(tmm::MeshIndex(V, F), std::invalid_argument);
  F << 0, 1, 2;
  V(1, 2) = NAN;
  EXPECT_THROW(tmm::MeshIndex(V, F), std::invalid_argument);
  EXPECT_THROW(tmm::MeshIndex(V, tmm::Triangles(0, 3)), std::invalid_argument);
}

TEST(DropBatch, ThreadsAgreeAndCancel) {
  tmm::Vertices V(4, 3);
  V << 0, 0, 0, 10, 0, 1, 10, 10, 2, 0, 10, 1;
  tmm::Triangles F(2, 3);
  F << 0, 1, 2, 0, 2, 3;
  const tmm::MeshIndex index(V, F);
  const Cutter cut(1, 0.5);
  std::vector<double> xy;
  for (int i = 0; i < 5000; ++i) {
    xy.push_back((i % 100) * 0.1);
    xy.push_back((i / 100) * 0.2);
  }
  std::vector<double> z1(5000), z2(5000);
  tmm::BatchOptions one;
  one.threads = 1;
  tmm::drop_batch(index, cut, xy.data(), 5000, -1, z1.data(), one);
  tmm::BatchOptions two;
  two.threads = 2;
  double last = -1;
  two.progress = [&](double f) { EXPECT_GE(f, last); last = f; return true; };
  tmm::drop_batch(index, cut, xy.data(), 5000, -1, z2.data(), two);
  EXPECT_EQ(last, 1.0);
  for (int i = 0; i < 5000; ++i) {
    EXPECT_EQ(z1[i], z2[i]);  // deterministic: the same bits whatever the thread count
    // A single query may reach the same contact through another element: equal up to rounding.
    EXPECT_NEAR(z1[i], tmm::drop_point(index, cut, xy[2 * i], xy[2 * i + 1], -1), 1e-12);
  }
  tmm::BatchOptions cancel;
  cancel.progress = [](double) { return false; };
  std::vector<double> big(2 * 2000000, 5.0), zb(2000000);
  EXPECT_THROW(tmm::drop_batch(index, cut, big.data(), 2000000, -1, zb.data(), cancel), tmm::Cancelled);
}

}  // namespace

namespace {
TEST(DropReference, RandomTrianglesSharpVBitByTaper) {
  // A 90-degree V-bit as a taper from a point on the axis: d/2 = 0.
  const Cutter v = Cutter::apt(3, 0, 3, 0, M_PI / 4);
  EXPECT_NEAR(v.height(1.0), 1.0, 1e-12);
  check_against_references(v, 400, 26);
}
}  // namespace
