// The tool assembly's drop (cutter + shank/neck + holder, each grown by its clearance) against a brute force
// that knows nothing of the APT pieces:
//  - each body's meridian section is its trapezoid (both sides of the axis); grown by c its lowest point at a
//    distance d from the axis is the lowest of the capsules around the trapezoid's four edges there (closed
//    form: an end's disc or the lower offset line), the cutter grown by c the lowest of the discs centred on
//    its profile h(|u|) (a 1-D convex minimisation);
//  - a mesh point p at distance d from the axis keeps the grown piece off it iff tip >= p.z - lowest(d), so a
//    triangle's contact is the maximum over the triangle of that concave function (lowest is convex and
//    non-decreasing in d, d is convex on the triangle): nested golden-section searches over the triangle;
//  - the drop is the highest contact of any piece with any triangle.
// Also: with no bodies the batch equals drop_batch exactly, the point query equals the batch, threads agree,
// the holder sets the height in a deep pocket (closed form), and bad bodies are refused by name.
#include <gtest/gtest.h>

#include <Eigen/Core>
#include <algorithm>
#include <cmath>
#include <functional>
#include <limits>
#include <random>
#include <stdexcept>
#include <string>
#include <vector>

#include "support/test_meshes.hpp"
#include "tmm/query/drop_assembly.hpp"
#include "tmm/query/drop_cutter.hpp"

namespace {

using Eigen::Vector2d;
using Eigen::Vector3d;
using tmm::Cutter;
using tmm::ToolBody;

constexpr double kInf = std::numeric_limits<double>::infinity();
constexpr double kGolden = 0.6180339887498949;

// Maximum of a concave f over [a, b] by golden-section search (to the resolution of doubles).
double golden_max(const std::function<double(double)>& f, double a, double b, int iterations = 64) {
  double x1 = b - kGolden * (b - a), x2 = a + kGolden * (b - a);
  double f1 = f(x1), f2 = f(x2);
  double best = std::max({f(a), f(b), f1, f2});
  for (int k = 0; k < iterations; ++k) {
    if (f1 < f2) {
      a = x1;
      x1 = x2;
      f1 = f2;
      x2 = a + kGolden * (b - a);
      f2 = f(x2);
    } else {
      b = x2;
      x2 = x1;
      f2 = f1;
      x1 = b - kGolden * (b - a);
      f1 = f(x1);
    }
    best = std::max({best, f1, f2});
  }
  return best;
}

// Lowest point at abscissa d of the segment a-b of a meridian plane (x, z) grown by c: an end's disc, or the
// offset of the segment by c along its downward normal. +inf where the capsule does not reach d. A disc spans
// [p.x - c, p.x + c] as rounded, the very sum that gives a piece's reach: |d - p.x| <= c would drop the disc at
// d = reach when r + c - r rounds above c (then the piece's lowest there is +inf and its contact -inf on the
// whole triangle outside the reach, which the searches cannot climb out of).
double capsule_lowest(const Vector2d& a, const Vector2d& b, double c, double d) {
  double low = kInf;
  for (const Vector2d& p : {a, b})
    if (d >= p.x() - c && d <= p.x() + c)
      low = std::min(low, p.y() - std::sqrt(std::max(c * c - (d - p.x()) * (d - p.x()), 0.0)));
  const Vector2d t = b - a;
  const double len = t.norm();
  if (len == 0.0 || t.x() == 0.0) return low;  // a point, or a vertical edge: its discs hold its lowest points
  Vector2d n(t.y() / len, -t.x() / len);
  if (n.y() > 0) n = -n;
  const Vector2d p = a + c * n, q = b + c * n;
  if (d >= std::min(p.x(), q.x()) && d <= std::max(p.x(), q.x()))
    low = std::min(low, p.y() + (d - p.x()) / (q.x() - p.x()) * (q.y() - p.y()));
  return low;
}

// A grown piece of the reference: lowest height (above the tool tip) at distance d from the axis, within
// `reach` of it.
struct RefPiece {
  std::function<double(double)> lowest;
  double reach;
  int owner;
};

RefPiece body_reference(const ToolBody& b, int owner) {
  const Vector2d p0(-b.r0, b.z0), p1(b.r0, b.z0), p2(b.r1, b.z1), p3(-b.r1, b.z1);
  const double c = b.clearance;
  return {[=](double d) {
            return std::min({capsule_lowest(p0, p1, c, d), capsule_lowest(p1, p2, c, d),
                             capsule_lowest(p2, p3, c, d), capsule_lowest(p3, p0, c, d)});
          },
          std::max(b.r0, b.r1) + c, owner};
}

// The cutter grown by c: the lowest of the discs of radius c centred on its profile, u in [-R, R] (points
// above the profile are higher and their discs too).
RefPiece cutter_reference(const Cutter& k, double c) {
  const double R = k.max_radius();
  auto h = [k](double u) { return k.height(std::min(std::fabs(u), k.max_radius())); };
  if (c == 0.0) return {h, R, tmm::kSetByCutter};
  return {[=](double d) {
            const double a = std::max(-R, d - c), b = std::min(R, d + c);
            return -golden_max([&](double u) { return -(h(u) - std::sqrt(std::max(c * c - (u - d) * (u - d), 0.0))); },
                               a, b, 80);
          },
          R + c, tmm::kSetByCutter};
}

std::vector<RefPiece> reference_pieces(const Cutter& k, const std::vector<ToolBody>& bodies, double cc) {
  std::vector<RefPiece> out{cutter_reference(k, cc)};
  for (std::size_t i = 0; i < bodies.size(); ++i) out.push_back(body_reference(bodies[i], static_cast<int>(i)));
  return out;
}

// Distance in XY from (x, y) to the triangle's projection (0 inside).
double xy_distance(double x, double y, const tmm::IndexedTriangle& t) {
  const Vector2d q(x, y);
  const Vector2d a(t.p[0][0], t.p[0][1]), b(t.p[1][0], t.p[1][1]), c(t.p[2][0], t.p[2][1]);
  const double w0 = (b - q).x() * (c - q).y() - (b - q).y() * (c - q).x();
  const double w1 = (c - q).x() * (a - q).y() - (c - q).y() * (a - q).x();
  const double w2 = (a - q).x() * (b - q).y() - (a - q).y() * (b - q).x();
  if ((w0 >= 0 && w1 >= 0 && w2 >= 0) || (w0 <= 0 && w1 <= 0 && w2 <= 0)) return 0.0;
  auto seg = [&](const Vector2d& u, const Vector2d& v) {
    const Vector2d e = v - u;
    const double s = e.squaredNorm() > 0 ? std::clamp((q - u).dot(e) / e.squaredNorm(), 0.0, 1.0) : 0.0;
    return (u + s * e - q).norm();
  };
  return std::min({seg(a, b), seg(b, c), seg(c, a)});
}

// The highest tip at which piece `p` rests on triangle t, -inf if it cannot reach it: the maximum over the
// triangle of p.z - lowest(d), concave; outside the reach `lowest` continues steeply (still convex) so the
// searches see one concave function.
double triangle_contact(const RefPiece& piece, double x, double y, const tmm::IndexedTriangle& t) {
  if (xy_distance(x, y, t) > piece.reach) return -kInf;
  const double edge = piece.lowest(piece.reach);
  auto f = [&](const Vector3d& p) {
    const double d = std::hypot(p.x() - x, p.y() - y);
    const double low = d <= piece.reach ? piece.lowest(d) : edge + 1e9 * (d - piece.reach);
    return p.z() - low;
  };
  const Vector3d a(t.p[0]), b(t.p[1]), c(t.p[2]);
  // Sections parallel to b-c: from a (s = 0) to the edge b-c (s = 1).
  auto section = [&](double s) {
    const Vector3d u = a + s * (b - a), v = a + s * (c - a);
    return golden_max([&](double w) { return f(u + w * (v - u)); }, 0.0, 1.0);
  };
  return golden_max(section, 0.0, 1.0);
}

struct RefDrop {
  double z;
  int owner;
  double margin;  // how far the second-best owner's height is below z
};

RefDrop reference_drop(const tmm::MeshIndex& index, const std::vector<RefPiece>& pieces, double x, double y,
                       double floor_z) {
  // Highest triangles first: a piece rests on a triangle at most zmax - lowest(0) high.
  std::vector<const tmm::IndexedTriangle*> tris;
  for (const auto& t : index.triangles()) tris.push_back(&t);
  std::sort(tris.begin(), tris.end(), [](const auto* a, const auto* b) { return a->zmax > b->zmax; });
  std::vector<double> per(pieces.size(), -kInf);
  for (std::size_t k = 0; k < pieces.size(); ++k) {
    const double top = pieces[k].lowest(0.0);
    for (const auto* t : tris) {
      if (t->zmax - top <= per[k]) break;
      per[k] = std::max(per[k], triangle_contact(pieces[k], x, y, *t));
    }
  }
  RefDrop r{floor_z, tmm::kSetByFloor, kInf};
  for (std::size_t k = 0; k < pieces.size(); ++k)
    if (per[k] > r.z) r = {per[k], pieces[k].owner, kInf};
  for (std::size_t k = 0; k < pieces.size(); ++k)
    if (pieces[k].owner != r.owner) r.margin = std::min(r.margin, r.z - per[k]);
  if (r.owner != tmm::kSetByFloor) r.margin = std::min(r.margin, r.z - floor_z);
  return r;
}

tmm::MeshIndex bumpy(int n, unsigned seed) {
  std::mt19937_64 rng(seed);
  const auto [V, F] = tmm_test::bumpy_grid(n, 2.0, 2.5, rng);
  return tmm::MeshIndex(V, F);
}

// Compares the batch, and the point query, with the reference at the points xy (x0, y0, x1, y1, ...);
// counts in set_by_body the points a body set.
void check_points(const tmm::MeshIndex& index, const Cutter& cutter, const std::vector<ToolBody>& bodies,
                  double cutter_clearance, const std::vector<double>& xy, int* set_by_body = nullptr) {
  const tmm::ToolAssembly tool(cutter, bodies, cutter_clearance);
  const auto pieces = reference_pieces(cutter, bodies, cutter_clearance);
  const std::size_t count = xy.size() / 2;
  std::vector<double> z(count);
  std::vector<int32_t> by(count);
  const double floor_z = -20.0;
  tmm::drop_assembly_batch(index, tool, xy.data(), count, floor_z, z.data(), by.data(), tmm::BatchOptions{});
  for (std::size_t i = 0; i < count; ++i) {
    const double x = xy[2 * i], y = xy[2 * i + 1];
    const RefDrop ref = reference_drop(index, pieces, x, y, floor_z);
    EXPECT_NEAR(z[i], ref.z, 1e-7) << "at (" << x << ", " << y << ")";
    if (ref.margin > 1e-6) {
      EXPECT_EQ(by[i], ref.owner) << "at (" << x << ", " << y << ")";
    }
    if (set_by_body && by[i] >= 0) ++*set_by_body;
    // The batch's tile scans round the facet contact differently from the walk's.
    int32_t point_by = 0;
    EXPECT_NEAR(tmm::drop_assembly_point(index, tool, x, y, floor_z, &point_by), z[i], 1e-9);
    if (ref.margin > 1e-6) {
      EXPECT_EQ(point_by, by[i]);
    }
  }
}

// As check_points at `count` random points of [lo, hi]^2.
void check_against_reference(const tmm::MeshIndex& index, const Cutter& cutter, const std::vector<ToolBody>& bodies,
                             double cutter_clearance, double lo, double hi, int count, unsigned seed,
                             int* set_by_body = nullptr) {
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> u(lo, hi);
  std::vector<double> xy(2 * count);
  for (double& v : xy) v = u(rng);
  check_points(index, cutter, bodies, cutter_clearance, xy, set_by_body);
}

// `count` points at distances [d0, d1] from the origin, evenly around it.
std::vector<double> ring(double d0, double d1, int count) {
  std::vector<double> xy;
  for (int i = 0; i < count; ++i) {
    const double d = d0 + (d1 - d0) * i / (count - 1), a = 2.399963 * i;
    xy.insert(xy.end(), {d * std::cos(a), d * std::sin(a)});
  }
  return xy;
}

// A ball with a short stick-out over bumps 3 high: shank, a widening neck whose top rim is its own piece (the
// holder's clearance is smaller), and a holder.
std::vector<ToolBody> short_assembly() {
  return {{1.2, 2.5, 1.2, 1.2, 0.3}, {2.5, 3.5, 1.2, 3.0, 0.5}, {3.5, 30.0, 5.0, 5.0, 0.25}};
}

TEST(DropAssembly, PiecesOfTheBodies) {
  const Cutter ball(1.0, 1.0);
  // Cutter; shank; neck (its rim not covered: the holder's clearance 0.25 < 0.5) + rim; holder.
  EXPECT_EQ(tmm::ToolAssembly(ball, short_assembly()).pieces().size(), 5u);
  // The holder's clearance at least the neck's and its bottom as wide: the neck's rim is covered.
  auto covered = short_assembly();
  covered[2].clearance = 0.5;
  EXPECT_EQ(tmm::ToolAssembly(ball, covered).pieces().size(), 4u);
  // No clearance: no rim pieces; the cutter's piece is the cutter, lift 0.
  const tmm::ToolAssembly bare(ball, {{2.0, 4.0, 1.0, 3.0, 0.0}});
  ASSERT_EQ(bare.pieces().size(), 2u);
  EXPECT_EQ(bare.pieces()[0].lift, 0.0);
  EXPECT_EQ(bare.pieces()[1].owner, 0);
  // A tapered cutter with a clearance: its top rim is a piece unless the shank covers it.
  const Cutter taper = Cutter::apt(2.0, 0.5, 10.0, 0.0, 0.05);
  EXPECT_EQ(tmm::ToolAssembly(taper, {}, 0.2).pieces().size(), 2u);
  EXPECT_EQ(tmm::ToolAssembly(taper, {{10.0, 20.0, 2.0, 2.0, 0.2}}, 0.2).pieces().size(), 2u);
}

TEST(DropAssembly, BumpyGridAgainstReference) {
  const auto index = bumpy(12, 11);
  int by_body = 0;
  check_against_reference(index, Cutter(1.0, 1.0), short_assembly(), 0.0, 1.0, 11.0, 60, 1, &by_body);
  EXPECT_GT(by_body, 10);  // the bodies, not only the cutter, set heights here
}

// The highest p.z - lowest(d) over a triangular grid of (n + 1)(n + 2) / 2 points of t within the piece's reach
// (its edges and corners included): below the true contact, within the grid's resolution of it. A check of the
// reference that assumes no concavity.
double sampled_contact(const RefPiece& piece, double x, double y, const tmm::IndexedTriangle& t, int n) {
  const Vector3d a(t.p[0]), b(t.p[1]), c(t.p[2]);
  double best = -kInf;
  for (int i = 0; i <= n; ++i)
    for (int j = 0; i + j <= n; ++j) {
      const Vector3d p = a + (b - a) * (static_cast<double>(i) / n) + (c - a) * (static_cast<double>(j) / n);
      const double d = std::hypot(p.x() - x, p.y() - y);
      if (d <= piece.reach) best = std::max(best, p.z() - piece.lowest(d));
    }
  return best;
}

// The reference's searches against dense sampling where the shank rests on a triangle reaching past its
// grown rim (the rim's disc once fell out of the reference at the reach, leaving it 0.05 low there), then the
// kernel against the reference on a raster over the bumps where shank, neck and holder take turns.
TEST(DropAssembly, RasterOverBumpsAgainstReference) {
  const auto index = bumpy(12, 16);
  const Cutter ball(1.0, 1.0);
  const auto pieces = reference_pieces(ball, short_assembly(), 0.0);
  const double x = 5.6, y = 3.0;
  for (const RefPiece& piece : pieces) {
    ASSERT_TRUE(std::isfinite(piece.lowest(piece.reach)));
    double searched = -kInf, sampled = -kInf;  // over the triangles (a sliver may hold no sample)
    for (const auto& t : index.triangles()) {
      if (xy_distance(x, y, t) > piece.reach) continue;
      const double on_t = triangle_contact(piece, x, y, t), grid = sampled_contact(piece, x, y, t, 300);
      EXPECT_LE(grid, on_t + 1e-9);
      searched = std::max(searched, on_t);
      sampled = std::max(sampled, grid);
    }
    EXPECT_GE(sampled, searched - 1e-4) << piece.owner;
  }
  std::vector<double> xy;
  for (int j = 0; j <= 25; ++j)
    for (int i = 0; i <= 25; ++i) xy.insert(xy.end(), {3.0 + 0.2 * i, 3.0 + 0.2 * j});
  int by_body = 0;
  check_points(index, ball, short_assembly(), 0.0, xy, &by_body);
  EXPECT_GT(by_body, 50);
}

TEST(DropAssembly, BodyShapesAgainstReference) {
  const auto index = bumpy(10, 12);
  // A narrowing cone, a pointed widening cone, a bare widening cone, a line grown into a capsule, with gaps.
  const std::vector<ToolBody> bodies = {
      {1.5, 2.5, 2.0, 0.8, 0.4}, {3.0, 4.0, 0.0, 2.5, 0.3}, {4.0, 4.5, 2.5, 3.5, 0.0}, {5.0, 9.0, 0.0, 0.0, 0.7}};
  int by_body = 0;
  check_against_reference(index, Cutter(5.0, 0.0) /* wide flat: any body must reach past it */, {}, 0.0, 1.0,
                          9.0, 10, 2);
  check_against_reference(index, Cutter(0.5, 0.2), bodies, 0.0, 1.0, 9.0, 50, 3, &by_body);
  EXPECT_GT(by_body, 5);
}

TEST(DropAssembly, CutterClearanceAgainstReference) {
  const auto index = bumpy(10, 13);
  check_against_reference(index, Cutter(1.0, 1.0), {}, 0.3, 1.0, 9.0, 25, 4);
  check_against_reference(index, Cutter(1.5, 0.0), {}, 0.2, 1.0, 9.0, 25, 5);
  // Tapered bull-nose, short flutes: the taper's top rim grown by the clearance, then a neck and a holder.
  const Cutter taper = Cutter::apt(1.2, 0.3, 2.0, 0.0, 0.2);
  check_against_reference(index, taper, {}, 0.25, 1.0, 9.0, 25, 6);
  check_against_reference(index, taper, {{2.0, 3.0, 1.0, 2.0, 0.1}, {3.0, 20.0, 4.0, 4.0, 0.5}}, 0.25, 1.0, 9.0,
                          25, 7);
  // An inward taper (the arc's widest point ends the profile).
  check_against_reference(index, Cutter::apt(1.0, 0.4, 3.0, 0.0, -0.1), {}, 0.3, 1.0, 9.0, 20, 8);
}

TEST(DropAssembly, NoBodiesIsTheCutterDropExactly) {
  const auto index = bumpy(30, 14);
  std::mt19937_64 rng(9);
  std::uniform_real_distribution<double> u(-2.0, 32.0);
  const std::size_t n = 4000;
  std::vector<double> xy(2 * n), z(n), z0(n);
  std::vector<int32_t> by(n);
  for (double& v : xy) v = u(rng);
  for (const Cutter& c : {Cutter(2.0, 2.0), Cutter(3.0, 0.0), Cutter(2.5, 0.5), Cutter::apt(3, 0.5, 8, 0.2, 0.1)}) {
    const tmm::ToolAssembly tool(c, {});
    tmm::drop_batch(index, c, xy.data(), n, -3.0, z0.data(), tmm::BatchOptions{});
    tmm::drop_assembly_batch(index, tool, xy.data(), n, -3.0, z.data(), by.data(), tmm::BatchOptions{});
    for (std::size_t i = 0; i < n; ++i) {
      ASSERT_EQ(z[i], z0[i]) << i;
      ASSERT_EQ(by[i], z0[i] > -3.0 ? tmm::kSetByCutter : tmm::kSetByFloor) << i;
    }
  }
}

// The batch (height cells, tiles, the bodies in the cutter's tiles, walks) against the point query, which walks
// each piece: the heights z at the points xy agree; returns how many points a body set (by >= 0).
int points_equal_batch(const tmm::MeshIndex& index, const tmm::ToolAssembly& tool, const std::vector<double>& xy,
                       double floor_z, const std::vector<double>& z, const std::vector<int32_t>& by) {
  int lifted = 0;
  for (std::size_t i = 0; i < z.size(); ++i) {
    EXPECT_NEAR(tmm::drop_assembly_point(index, tool, xy[2 * i], xy[2 * i + 1], floor_z), z[i], 1e-9) << i;
    lifted += by[i] >= 0;
  }
  return lifted;
}

TEST(DropAssembly, ThreadsAgreeAndBatchEqualsPoints) {
  const auto index = bumpy(30, 15);
  const tmm::ToolAssembly tool(Cutter(1.0, 1.0), short_assembly());
  std::vector<double> xy;
  for (double y = 0; y <= 30; y += 0.25)
    for (double x = 0; x <= 30; x += 0.25) xy.insert(xy.end(), {x, y});
  const std::size_t n = xy.size() / 2;
  std::vector<double> z1(n), z2(n);
  std::vector<int32_t> b1(n), b2(n);
  tmm::BatchOptions one, two;
  one.threads = 1;
  two.threads = 2;
  tmm::drop_assembly_batch(index, tool, xy.data(), n, -10.0, z1.data(), b1.data(), one);
  tmm::drop_assembly_batch(index, tool, xy.data(), n, -10.0, z2.data(), b2.data(), two);
  EXPECT_EQ(z1, z2);
  EXPECT_EQ(b1, b2);
  EXPECT_GT(points_equal_batch(index, tool, xy, -10.0, z1, b1), 500);
}

// A raster dense enough that the bodies go with the cutter's tiles (a list per tile and piece, scanned per
// point with the walk's own per-triangle values): the batch equals the point query, which walks each piece.
TEST(DropAssembly, TiledBodiesEqualPoints) {
  const auto index = bumpy(12, 16);
  std::vector<double> xy;
  for (double y = 1.0; y <= 11.0; y += 0.2)
    for (double x = 1.0; x <= 11.0; x += 0.2) xy.insert(xy.end(), {x, y});
  const std::size_t n = xy.size() / 2;
  const std::vector<ToolBody> thin = {{1.0, 2.0, 0.6, 0.6, 0.2}, {2.0, 30.0, 4.0, 4.0, 0.5}};
  for (const tmm::ToolAssembly& tool : {tmm::ToolAssembly(Cutter(1.0, 1.0), short_assembly()),
                                        tmm::ToolAssembly(Cutter(0.5, 0.2), thin, 0.1)}) {
    std::vector<double> z(n);
    std::vector<int32_t> by(n);
    tmm::drop_assembly_batch(index, tool, xy.data(), n, -20.0, z.data(), by.data(), tmm::BatchOptions{});
    EXPECT_GT(points_equal_batch(index, tool, xy, -20.0, z, by), 100);
  }
}

// A pocket 6 x 6 mm, 10 deep, in a plate: a ball on a 3 mm stick-out cannot reach its floor, the holder
// (radius 8, clearance 1, from 8 above the tip) rests on the plate: tip = 10 - (8 - 1) = 3.
TEST(DropAssembly, HolderSetsTheHeightInADeepPocket) {
  const auto index = tmm_test::grid_mesh(
      [](double x, double y) { return std::fabs(x) < 3.01 && std::fabs(y) < 3.01 ? 0.0 : 10.0; }, -20, -20, 20, 20,
      80, 80);
  const std::vector<ToolBody> bodies = {{3.0, 8.0, 1.0, 1.0, 0.5}, {8.0, 40.0, 8.0, 8.0, 1.0}};
  const tmm::ToolAssembly tool(Cutter(1.0, 1.0), bodies);
  int32_t by = 0;
  EXPECT_NEAR(tmm::drop_assembly_point(index, tool, 0.0, 0.0, -5.0, &by), 3.0, 1e-12);
  EXPECT_EQ(by, 1);
  EXPECT_NEAR(tmm::drop_assembly_point(index, tool, 1.0, -0.5, -5.0, &by), 3.0, 1e-12);
  EXPECT_EQ(by, 1);
  // The cutter alone reaches the floor.
  EXPECT_NEAR(tmm::drop_point(index, Cutter(1.0, 1.0), 0.0, 0.0, -5.0), 0.0, 1e-12);
  // Far out on the plate the cutter sets it.
  EXPECT_NEAR(tmm::drop_assembly_point(index, tool, 15.0, 15.0, -5.0, &by), 10.0, 1e-12);
  EXPECT_EQ(by, tmm::kSetByCutter);
  check_against_reference(index, Cutter(1.0, 1.0), bodies, 0.0, -6.0, 6.0, 12, 10);
  // A raster over the pocket and its rim: the batch (height cells, tiles, walks) equals the point query.
  std::vector<double> xy;
  for (double y = -14; y <= 14; y += 0.4)
    for (double x = -14; x <= 14; x += 0.4) xy.insert(xy.end(), {x, y});
  const std::size_t n = xy.size() / 2;
  std::vector<double> z(n);
  std::vector<int32_t> set(n);
  tmm::drop_assembly_batch(index, tool, xy.data(), n, -5.0, z.data(), set.data(), tmm::BatchOptions{});
  int held = 0;
  for (std::size_t i = 0; i < n; ++i) {
    const double zp = tmm::drop_assembly_point(index, tool, xy[2 * i], xy[2 * i + 1], -5.0, &by);
    ASSERT_NEAR(zp, z[i], 1e-9) << i;
    EXPECT_EQ(by, set[i]) << i;
    // The holder flat on the plate: the batch's certificate (the last winner's edge under the flat bottom at
    // the cells' bound) gives the walk's very height.
    if (set[i] == 1) {
      ASSERT_EQ(zp, z[i]) << i;
    }
    held += set[i] == 1;
  }
  EXPECT_GT(held, 50);
}

// A needle 10 high on a plate: tool positions whose axis passes a top rim's width from it.
tmm::MeshIndex needle_on_plate() {
  tmm::Vertices V(7, 3);
  V << -20, -20, 0, 20, -20, 0, 20, 20, 0, -20, 20, 0, 0, 0, 10, 0.01, 0, 0, 0, 0.01, 0;
  tmm::Triangles F(4, 3);
  F << 0, 1, 2, 0, 2, 3, 4, 5, 6, 4, 6, 5;
  return tmm::MeshIndex(V, F);
}

// Where only a grown top rim reaches the needle: tip = 10 - (z_rim - sqrt(c^2 - (d - r_rim)^2)).
TEST(DropAssembly, TopRimsSetTheHeight) {
  const auto index = needle_on_plate();
  auto rim_tip = [](double d, double z_rim, double r_rim, double c) {
    return 10.0 - (z_rim - std::sqrt(c * c - (d - r_rim) * (d - r_rim)));
  };
  // A neck widening from 1.2 to 3 between 2.5 and 3.5 above the tip, clearance 0.5: its side's offset reaches
  // 3 + 0.5 cos(beta2) = 3.243 from the axis, its top rim's ball 3.5.
  const std::vector<ToolBody> neck = {{2.5, 3.5, 1.2, 3.0, 0.5}};
  const tmm::ToolAssembly tool(Cutter(1.0, 1.0), neck);
  for (double d : {3.3, 3.4, 3.45, 3.49}) {
    int32_t by = 0;
    EXPECT_NEAR(tmm::drop_assembly_point(index, tool, -d, 0.0, -5.0, &by), rim_tip(d, 3.5, 3.0, 0.5), 1e-9) << d;
    EXPECT_EQ(by, 0) << d;
  }
  check_points(index, Cutter(1.0, 1.0), neck, 0.0, ring(2.8, 3.6, 12));
  // A holder sitting on the neck, as wide as its top but with a smaller clearance, leaves the rim uncovered.
  const std::vector<ToolBody> held = {neck[0], {3.5, 30.0, 3.0, 3.0, 0.25}};
  int32_t by = 0;
  EXPECT_NEAR(tmm::drop_assembly_point(index, tmm::ToolAssembly(Cutter(1.0, 1.0), held), 0.0, 3.4, -5.0, &by),
              rim_tip(3.4, 3.5, 3.0, 0.5), 1e-9);
  EXPECT_EQ(by, 0);
  check_points(index, Cutter(1.0, 1.0), held, 0.0, ring(2.8, 3.6, 12));
  // A tapered cutter (top rim: radius 2 at 2 above the tip) with a clearance of 0.5: the taper's offset
  // reaches 2 + 0.5 cos(0.6) = 2.413, the rim's ball 2.5.
  const Cutter taper = Cutter::apt(2.0, 0.3, 2.0, 0.0, 0.6);
  const tmm::ToolAssembly grown(taper, {}, 0.5);
  for (double d : {2.42, 2.45, 2.49}) {
    EXPECT_NEAR(tmm::drop_assembly_point(index, grown, -d, 0.0, -5.0, &by), rim_tip(d, 2.0, 2.0, 0.5), 1e-9) << d;
    EXPECT_EQ(by, tmm::kSetByCutter) << d;
  }
  check_points(index, taper, {}, 0.5, ring(2.0, 2.6, 12));
}

void expect_refused(const std::vector<ToolBody>& bodies, const std::string& words, double cutter_clearance = 0.0,
                    const Cutter& cutter = Cutter(1.0, 1.0)) {
  try {
    tmm::ToolAssembly tool(cutter, bodies, cutter_clearance);
    ADD_FAILURE() << "not refused: " << words;
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find(words), std::string::npos) << e.what();
  }
}

TEST(DropAssembly, RefusesBadBodies) {
  const double nan = std::nan("");
  expect_refused({{5, 5, 1, 1, 0}}, "tool body 0 (z0 5, z1 5, r0 1, r1 1, clearance 0): z1 must be above z0");
  expect_refused({{2, 5, 1, 1, 0}, {6, 4, 1, 1, 0}}, "tool body 1");
  expect_refused({{2, 5, -1, 1, 0}}, "radii must be >= 0");
  expect_refused({{2, 5, 1, 1, -0.5}}, "clearance must be >= 0");
  expect_refused({{2, nan, 1, 1, 0}}, "outside the kernel's range");
  expect_refused({{2, 5, 1, INFINITY, 0}}, "outside the kernel's range");
  expect_refused({{-1, 5, 1, 1, 0}}, "z0 must be >= 0");
  expect_refused({{2, 5, 0, 0, 0}}, "positive radius or a positive clearance");
  expect_refused({{2, 6, 1, 1, 0}, {5, 9, 3, 3, 0}}, "not overlapping: z0 is below the previous body's z1 = 6");
  expect_refused({{5, 9, 3, 3, 0}, {2, 4, 1, 1, 0}}, "sorted from the tip up");
  expect_refused({}, "cutter clearance must be >= 0", -1.0);
  expect_refused({}, "cutter clearance must be >= 0", nan);
  expect_refused({}, "flat-bottomed cutter", 0.5, Cutter::apt(3, 0, 10, 0.5, 0));
  // A cone too flat for an APT profile is refused naming the body.
  expect_refused({{2, 2 + 1e-15, 1, 50, 0}}, "tool body 0");
  // Touching bodies are fine, and a V-bit without a cutter clearance.
  EXPECT_NO_THROW(tmm::ToolAssembly(Cutter::apt(3, 0, 10, 0.5, 0), {{2, 5, 1, 1, 0}, {5, 9, 3, 3, 1}}));
}

}  // namespace
