// A tilted solid's candidate list (AlongCutter::gather, drop_listed) against its walk (AlongCutter::drop, itself
// checked against every triangle in test_drop_direction.cpp): a list keeps only the triangles whose XY' box
// meets the solid's shadow (the disc about the axis's midpoint and the strip across the lean about the tip),
// so thin fins about the shadow of a wide rounded cylinder (a holder) tilted 15 degrees, many of them met near
// its edge, must give every start of a tile the walk's travel and triangle.
#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <cmath>
#include <random>
#include <vector>

#include "tmm/query/drop_direction.hpp"

namespace {

using Eigen::Vector3d;
using tmm::AlongCutter;
using tmm::Cutter;

// Tiles of starts 100 apart (index frame, tips at z' = 0) over a plate at z' = -80, each with `fins` upright
// slivers (along Z', 0.3 wide along the lean) standing about one of its starts: beside the lean, across it
// 25.8 to 27.3 from that tip, or about the rim of the holder's shadow (within -2 to +1 %), so that the holder
// (27 from the axis) meets some and misses others.
struct Scene {
  tmm::Vertices V;
  tmm::Triangles F;
  std::vector<std::vector<Vector3d>> tiles;  // the starts, model frame
};

Scene fins_about_the_shadow(const Eigen::Matrix3d& Q, const Vector3d& a, int fins, unsigned seed) {
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> jitter(-4, 4), side(25.8, 27.3), along(-5, 20), top(-40, -15),
      turn(0, 2 * M_PI), scale(0.98, 1.01);
  const double az = std::fabs(a.z()), S = 62 * a.head<2>().norm();  // the holder's shadow's stretch, length
  const Eigen::Vector2d lean = a.head<2>().normalized(), across(-lean.y(), lean.x());
  const int grid = 6, tiles = grid * grid;
  Scene sc;
  sc.V.resize(4 + 3 * fins * tiles, 3);
  sc.F.resize(2 + fins * tiles, 3);
  const double e = 100.0 * grid;
  for (int k = 0; k < 4; ++k)
    sc.V.row(k) = (Q.transpose() * Vector3d(k == 1 || k == 2 ? e : -e, k >= 2 ? e : -e, -80)).transpose();
  sc.F.row(0) << 0, 1, 2;
  sc.F.row(1) << 0, 2, 3;
  int v = 4, f = 2;
  for (int i = 0; i < tiles; ++i) {
    const Eigen::Vector2d c(100.0 * (i % grid) - 250, 100.0 * (i / grid) - 250);
    std::vector<Eigen::Vector2d> tips;
    sc.tiles.emplace_back();
    for (int j = 0; j < 6; ++j) {
      tips.emplace_back(c.x() + jitter(rng), c.y() + jitter(rng));
      sc.tiles.back().push_back(Q.transpose() * Vector3d(tips.back().x(), tips.back().y(), 0.0));
    }
    for (int k = 0; k < fins; ++k, v += 3, ++f) {
      // Beside the lean, or about the shadow's rim (its ends: half ellipses R by R |a.z|, the segment apart).
      const double th = turn(rng), rad = 27 * scale(rng);
      const Eigen::Vector2d off = k % 2 ? Eigen::Vector2d((k % 4 == 1 ? 1 : -1) * side(rng), along(rng))
                                        : Eigen::Vector2d(rad * std::sin(th), rad * az * std::cos(th) + (std::cos(th) > 0 ? S : 0));
      const Eigen::Vector2d p = tips[k % tips.size()] + off.x() * across + off.y() * lean;
      const Eigen::Vector2d q = p + 0.3 * lean, m = p + 0.15 * lean;
      sc.V.row(v) = (Q.transpose() * Vector3d(p.x(), p.y(), -80)).transpose();
      sc.V.row(v + 1) = (Q.transpose() * Vector3d(q.x(), q.y(), -80)).transpose();
      sc.V.row(v + 2) = (Q.transpose() * Vector3d(m.x(), m.y(), top(rng))).transpose();
      sc.F.row(f) << v, v + 1, v + 2;
    }
  }
  return sc;
}

TEST(DropListed, ListsEqualTheWalkAtTheShadowsEdge) {
  const Vector3d dir = Vector3d(0.1, -0.05, -1).normalized();
  const Vector3d axis = (Eigen::AngleAxisd(15 * M_PI / 180, Vector3d(0.3, 1, 0).normalized()) * -dir).normalized();
  tmm::Vertices P(3, 3);  // one triangle: the index's frame, in which the fins are placed
  P << 0, 0, 0, 1, 0, 0, 0, 1, 0;
  tmm::Triangles T(1, 3);
  T << 0, 1, 2;
  const Eigen::Matrix3d Q = tmm::DirectionalIndex(P, T, dir).rotation();
  const Scene sc = fins_about_the_shadow(Q, Q * axis, 8, 11);
  const tmm::DirectionalIndex index(sc.V, sc.F, dir);
  const Cutter holder = Cutter::apt(27, 2, 62, 0, 0);  // r25 grown by 2, 60 long (as the benchmark's holder)
  const AlongCutter solid(index, holder, axis, true);
  const auto& tris = index.index().triangles();
  int fins = 0;
  AlongCutter::Candidates cands;
  for (const std::vector<Vector3d>& starts : sc.tiles) {
    const std::vector<double> caps(starts.size(), 75.0);
    ASSERT_TRUE(solid.gather(starts.data(), caps.data(), starts.size(), cands, 100000));
    for (const Vector3d& s : starts) {
      int32_t walked = -1, listed = -1;
      const double tw = solid.drop(s, 75.0, nullptr, &walked);
      const double tl = solid.drop_listed(s, 75.0, cands, nullptr, &listed);
      ASSERT_NEAR(tl, tw, 1e-9);
      // Ties may go to either triangle: the list's must touch there too.
      if (listed != walked) {
        ASSERT_NEAR(solid.drop_on(s, 75.0, listed), tw, 1e-9);
      }
      fins += tw < 75.0 && tris[walked].zmax > -79.0;
    }
  }
  EXPECT_GT(fins, 150);  // the holder's side or rim stops it on a fin at most starts
}

}  // namespace
