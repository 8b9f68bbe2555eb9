// Drop-cutter with the CL point exactly over a triangle edge's XY projection (issue 11 item 5), on a vertex,
// and 1e-9 mm off the edge, for every cutter family, against an independent reference:
//  - an edge: the exact vertical distance z_edge(t) - h(rho(t)) maximised along the edge by golden-section
//    search over the part of the edge inside the cutter's shadow (the chord solved from |p(t) - axis| = R),
//    ends included. The function is concave (h convex and non-decreasing, rho(t) convex), so the search
//    needs no derivative and does not care about the kink of a cone's apex;
//  - the facet: the plane's highest cutter contact lies uphill of the axis (symmetry of revolution); the
//    lift rho |grad| - h(rho) is maximised over 0 <= rho <= R by golden section; it is the triangle's
//    contact when that point lies in the triangle, otherwise an edge gives it (a concave function whose
//    maximum over the shadow lies outside the triangle takes its maximum over the triangle on the edges);
//  - the triangle: the highest of the facet and its three edges (the vertices are the edges' ends).
// Only the profile h(rho) (the cutter's definition) is shared with the kernel; none of its contact code.
// Tolerance 1e-9 mm: the searches stop below 1e-15 of the edge's parameter (1e-14 mm) and the maximum is
// flat to first order (or at an end, evaluated exactly), so the reference is good to ~1e-12 mm; the kernel
// solves to 1e-12 mm in u. The misses this guards against were 0.1 to 2.6 mm.
#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <random>
#include <string>
#include <utility>
#include <vector>

#include "support/test_geometry.hpp"
#include "support/test_meshes.hpp"
#include "tmm/mesh/mesh_index.hpp"
#include "tmm/query/drop_contacts.hpp"
#include "tmm/query/drop_cutter.hpp"

namespace {

using Eigen::Vector3d;
using tmm::Cutter;

constexpr double kTol = 1e-9;
constexpr double kNone = -INFINITY;

// Maximum of a concave function, finite on [lo, hi], by golden section; both ends evaluated too.
template <class F>
double golden_max(F&& f, double lo, double hi, double* arg = nullptr) {
  const double g = 0.5 * (std::sqrt(5.0) - 1.0);
  double a = lo, b = hi;
  double m1 = b - g * (b - a), m2 = a + g * (b - a), f1 = f(m1), f2 = f(m2);
  for (int it = 0; it < 200 && b - a > 1e-15 * (1.0 + std::fabs(lo) + std::fabs(hi)); ++it) {
    if (f1 < f2) {
      a = m1; m1 = m2; f1 = f2; m2 = a + g * (b - a); f2 = f(m2);
    } else {
      b = m2; m2 = m1; f2 = f1; m1 = b - g * (b - a); f1 = f(m1);
    }
  }
  double best = f1, at = m1;
  if (f2 > best) { best = f2; at = m2; }
  const double flo = f(lo), fhi = f(hi);
  if (flo > best) { best = flo; at = lo; }
  if (fhi > best) { best = fhi; at = hi; }
  if (arg) *arg = at;
  return best;
}

// Reference edge contact: max over the edge's chord in the shadow of z(t) - h(rho(t)).
double ref_edge(const Cutter& c, double x, double y, const Vector3d& p, const Vector3d& q) {
  const double R = c.max_radius();
  const double ex = q.x() - p.x(), ey = q.y() - p.y(), sx = p.x() - x, sy = p.y() - y;
  const double A = ex * ex + ey * ey, B = 2 * (ex * sx + ey * sy), C = sx * sx + sy * sy - R * R;
  if (A < 1e-24) return std::hypot(sx, sy) <= R ? std::max(p.z(), q.z()) - c.height(std::hypot(sx, sy)) : kNone;
  const double D = B * B - 4 * A * C;
  if (D < 0) return kNone;
  const double t0 = std::max(0.0, (-B - std::sqrt(D)) / (2 * A)), t1 = std::min(1.0, (-B + std::sqrt(D)) / (2 * A));
  if (t0 > t1) return kNone;
  auto f = [&](double t) {
    const double rho = std::min(std::hypot(sx + t * ex, sy + t * ey), R);  // the chord's ends round to R
    return p.z() + t * (q.z() - p.z()) - c.height(rho);
  };
  return golden_max(f, t0, t1);
}

using tmm_test::inside_xy;

// Reference facet contact (the plane's contact if it lies in the triangle), or -inf.
double ref_facet(const Cutter& c, double x, double y, const Vector3d& a, const Vector3d& b, const Vector3d& p) {
  const Vector3d n = (b - a).cross(p - a);
  if (std::fabs(n.z()) < 1e-9 * n.norm()) return kNone;  // vertical: the edges give the contact
  const double gx = -n.x() / n.z(), gy = -n.y() / n.z();  // the plane's gradient
  const double G = std::hypot(gx, gy);
  const double ux = G > 0 ? gx / G : 1.0, uy = G > 0 ? gy / G : 0.0;
  const double z_axis = a.z() + gx * (x - a.x()) + gy * (y - a.y());
  double rho = 0;
  const double lift = golden_max([&](double s) { return s * G - c.height(s); }, 0.0, c.max_radius(), &rho);
  if (!inside_xy(x + rho * ux, y + rho * uy, a, b, p)) return kNone;
  return z_axis + lift;
}

double ref_triangle(const Cutter& c, double x, double y, const Vector3d& a, const Vector3d& b, const Vector3d& p) {
  return std::max({ref_facet(c, x, y, a, b, p), ref_edge(c, x, y, a, b), ref_edge(c, x, y, b, p),
                   ref_edge(c, x, y, p, a)});
}

bool agree(double z, double ref) {
  if (z == kNone || ref == kNone) return z == ref;
  return std::fabs(z - ref) <= kTol;
}

double drop1(const Cutter& c, double x, double y, const Vector3d& a, const Vector3d& b, const Vector3d& p) {
  const auto index = tmm_test::one_triangle(a, b, p);
  return tmm::drop_on_triangle(c, x, y, index.triangles()[0]);
}

struct Family {
  std::string name;
  Cutter cutter;
};

std::vector<Family> families() {
  const double deg = M_PI / 180;
  return {
      {"ball", Cutter(3, 3)},
      {"flat", Cutter(3, 0)},
      {"bull", Cutter(5, 2)},
      {"V-bit 120", Cutter::apt(4, 0, 4 * std::tan(60 * deg), 60 * deg, 0)},
      {"cone 30 + taper 10", Cutter::apt(5, 0, 8, 30 * deg, 10 * deg)},
      {"cone 20 + corner", Cutter::apt(5, 1.2, 40, 20 * deg, 0)},
      {"cone 10 + corner + taper 8", Cutter::apt(5, 1.2, 8, 10 * deg, 8 * deg)},
      {"cone 35 + corner + taper -5", Cutter::apt(4, 0.8, 6, 35 * deg, -5 * deg)},
      {"tapered ball", Cutter::apt(1.5 / std::cos(0.1) + 8.5 * std::tan(0.1), 1.5, 10, 0, 0.1)},
      {"tapered bull", Cutter::apt(4, 1.0, 10, 0, 5 * deg)},
  };
}

// Thousands of random triangles (fixed seed); the CL point on a random edge (a quarter of the edges axis
// parallel with the CL point's coordinate copied, so the distance is exactly 0; the rest at a rounded
// point of the edge, distance ~1e-16), on a vertex, or 1e-9 mm off the edge. Both the edge's contact
// (edge_drop) and the triangle's (drop_on_triangle) are compared with the reference.
TEST(EdgeContact, OnEdgeVertexAndOffEdgeEqualTheReference) {
  const char* modes[3] = {"on edge", "on vertex", "1e-9 off"};
  int total_fail = 0;
  for (const Family& fam : families()) {
    const Cutter& cut = fam.cutter;
    const double R = cut.max_radius();
    std::mt19937_64 rng(20240511);
    std::uniform_real_distribution<double> u(-1.0, 1.0), t01(0.0, 1.0);
    constexpr int kCases = 2000;
    int edge_fail[3] = {0, 0, 0}, tri_fail[3] = {0, 0, 0}, contacts[3] = {0, 0, 0};
    double worst[3] = {0, 0, 0};
    for (int k = 0; k < kCases; ++k) {
      Vector3d v[3];
      for (auto& w : v) w = Vector3d(u(rng) * 1.5 * R, u(rng) * 1.5 * R, u(rng) * R);
      const int e = static_cast<int>(rng() % 3);
      const Vector3d& p = v[e];
      Vector3d& q = v[(e + 1) % 3];
      const bool axis_parallel = k % 4 == 0;
      if (axis_parallel) {
        if (k % 8 == 0) q.y() = p.y(); else q.x() = p.x();
      }
      if (std::fabs(((v[1] - v[0]).cross(v[2] - v[0])).z()) < 1e-3) continue;  // near vertical
      const double t = t01(rng), side = u(rng) < 0 ? -1.0 : 1.0;
      const double ex = q.x() - p.x(), ey = q.y() - p.y(), L = std::hypot(ex, ey);
      for (int mode = 0; mode < 3; ++mode) {
        double x = p.x() + t * ex, y = p.y() + t * ey;
        if (axis_parallel) (k % 8 == 0 ? y : x) = (k % 8 == 0 ? p.y() : p.x());
        if (mode == 1) { x = p.x(); y = p.y(); }
        if (mode == 2) { x += side * 1e-9 * -ey / L; y += side * 1e-9 * ex / L; }
        const double ze = tmm::edge_drop(cut, x, y, p.data(), q.data());
        const double re = ref_edge(cut, x, y, p, q);
        const double zt = drop1(cut, x, y, v[0], v[1], v[2]);
        const double rt = ref_triangle(cut, x, y, v[0], v[1], v[2]);
        if (rt != kNone) ++contacts[mode];
        if (!agree(ze, re)) {
          ++edge_fail[mode];
          if (re != kNone && ze != kNone) worst[mode] = std::max(worst[mode], std::fabs(ze - re));
        }
        if (!agree(zt, rt)) {
          ++tri_fail[mode];
          if (rt != kNone && zt != kNone) worst[mode] = std::max(worst[mode], std::fabs(zt - rt));
          if (tri_fail[mode] <= 3)
            ADD_FAILURE() << fam.name << ", " << modes[mode] << ", case " << k << ": drop " << zt
                          << ", reference " << rt;
        }
      }
    }
    std::printf("[ edge contact ] %-28s", fam.name.c_str());
    for (int mode = 0; mode < 3; ++mode)
      std::printf("  %s: %d edge / %d triangle misses (worst %.3g mm)", modes[mode], edge_fail[mode],
                  tri_fail[mode], worst[mode]);
    std::printf("\n");
    for (int mode = 0; mode < 3; ++mode) {
      EXPECT_EQ(edge_fail[mode], 0) << fam.name << ", " << modes[mode];
      EXPECT_EQ(tri_fail[mode], 0) << fam.name << ", " << modes[mode];
      EXPECT_GT(contacts[mode], kCases / 3) << fam.name << ", " << modes[mode];
      total_fail += edge_fail[mode] + tri_fail[mode];
    }
  }
  EXPECT_EQ(total_fail, 0);
}

// A regular grid of 12.5 x 11.5 mm cells (diagonals i,j - i+1,j+1), coarse as CAD exports flat-ish
// regions: its edges span the whole shadow of the cutters. Heights: a wave with random bumps of up to 4 mm,
// so that ridges carry edge contacts. A raster through its vertices as a CAM operation lays it: rows and
// columns from the mesh's bounds, stepping by (max - min) / count from line to line (8 points per cell),
// which meets the vertices' coordinates to rounding, and points along the diagonal edges (distance from
// the edge's line 0 or of rounding size). drop_point and drop_batch against the reference maximised over
// all triangles.
TEST(EdgeContact, RegularGridRasterThroughVerticesEqualsTheReference) {
  constexpr int n = 6;
  constexpr double hx = 12.5, hy = 11.5, x0 = -37.5, y0 = -34.5;
  tmm::Vertices V((n + 1) * (n + 1), 3);
  std::mt19937_64 rng(7);
  std::uniform_real_distribution<double> bump(-4.0, 4.0);
  for (int i = 0; i <= n; ++i)
    for (int j = 0; j <= n; ++j) {
      const double x = x0 + i * hx, y = y0 + j * hy;
      V.row(i * (n + 1) + j) << x, y, 2.5 * std::sin(x / 9) * std::cos(y / 12) + bump(rng);
    }
  tmm::Triangles F(2 * n * n, 3);
  int f = 0;
  for (int i = 0; i < n; ++i)
    for (int j = 0; j < n; ++j) {
      const int a = i * (n + 1) + j;
      F.row(f++) << a, a + n + 1, a + n + 2;
      F.row(f++) << a, a + n + 2, a + 1;
    }
  const tmm::MeshIndex index(V, F);
  // Triangles by decreasing top for the reference: a contact is never above the triangle's top (h >= 0).
  std::vector<std::pair<double, int>> order;
  for (int t = 0; t < F.rows(); ++t)
    order.emplace_back(std::max({V(F(t, 0), 2), V(F(t, 1), 2), V(F(t, 2), 2)}), t);
  std::sort(order.begin(), order.end(), [](const auto& a, const auto& b) { return a.first > b.first; });

  constexpr int per_cell = 8;
  const double xmin = V.col(0).minCoeff(), xmax = V.col(0).maxCoeff();
  const double ymin = V.col(1).minCoeff(), ymax = V.col(1).maxCoeff();
  const double sx = (xmax - xmin) / (per_cell * n), sy = (ymax - ymin) / (per_cell * n);
  const double stepx = (xmax - xmin) / n, stepy = (ymax - ymin) / n;
  std::vector<double> xy;
  double line = ymin;
  for (int j = 0; j <= n; ++j, line += stepy)  // rows through the vertices
    for (int k = 0; k <= per_cell * n; ++k) xy.insert(xy.end(), {xmin + k * sx, line});
  line = xmin;
  for (int i = 0; i <= n; ++i, line += stepx)  // columns
    for (int k = 0; k <= per_cell * n; ++k) xy.insert(xy.end(), {line, ymin + k * sy});
  for (int i = 0; i < n; ++i)  // along the diagonal edges
    for (int j = 0; j < n; ++j) {
      const Eigen::Vector2d a = V.row(i * (n + 1) + j).head<2>().transpose();
      const Eigen::Vector2d b = V.row((i + 1) * (n + 1) + j + 1).head<2>().transpose();
      for (int k = 1; k < per_cell; ++k) {
        const Eigen::Vector2d p = a + (b - a) * (double(k) / per_cell);
        xy.insert(xy.end(), {p.x(), p.y()});
      }
    }
  const std::size_t m = xy.size() / 2;
  const double floor_z = -50;
  int total_fail = 0;
  for (const Family& fam : families()) {
    const Cutter& cut = fam.cutter;
    const double R = cut.max_radius();
    std::vector<double> zb(m);
    tmm::BatchOptions options;
    options.threads = 1;
    tmm::drop_batch(index, cut, xy.data(), m, floor_z, zb.data(), options);
    int fail_point = 0, fail_batch = 0;
    double worst = 0;
    for (std::size_t i = 0; i < m; ++i) {
      const double x = xy[2 * i], y = xy[2 * i + 1];
      double ref = floor_z;
      for (const auto& [top, t] : order) {
        if (top <= ref) break;
        const Vector3d a = V.row(F(t, 0)).transpose(), b = V.row(F(t, 1)).transpose(), c = V.row(F(t, 2)).transpose();
        const double dx = std::max({a.x() - x, b.x() - x, c.x() - x}), dx2 = std::min({a.x() - x, b.x() - x, c.x() - x});
        const double dy = std::max({a.y() - y, b.y() - y, c.y() - y}), dy2 = std::min({a.y() - y, b.y() - y, c.y() - y});
        if (dx < -R || dx2 > R || dy < -R || dy2 > R) continue;
        ref = std::max(ref, ref_triangle(cut, x, y, a, b, c));
      }
      const double zp = tmm::drop_point(index, cut, x, y, floor_z);
      if (std::fabs(zp - ref) > kTol) {
        ++fail_point;
        worst = std::max(worst, std::fabs(zp - ref));
        if (fail_point <= 3)
          ADD_FAILURE() << fam.name << ": drop_point at (" << x << ", " << y << ") " << zp << ", reference " << ref;
      }
      if (std::fabs(zb[i] - ref) > kTol) {
        ++fail_batch;
        worst = std::max(worst, std::fabs(zb[i] - ref));
      }
    }
    std::printf("[ edge contact ] grid %-28s %zu CL points: %d drop_point / %d drop_batch misses (worst %.3g mm)\n",
                fam.name.c_str(), m, fail_point, fail_batch, worst);
    EXPECT_EQ(fail_point, 0) << fam.name;
    EXPECT_EQ(fail_batch, 0) << fam.name;
    total_fail += fail_point + fail_batch;
  }
  EXPECT_EQ(total_fail, 0);
}

}  // namespace
