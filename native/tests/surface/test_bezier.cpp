// Bezier patches and patch surfaces against independent formulas:
//  - evaluation vs the explicit Bernstein sum with binomials and std::pow,
//  - derivatives vs central finite differences,
//  - subdivision exactness (sub-patch == reparametrised original), multi-patch faces across the seams,
//  - ray hits: on the ray and on the surface, the first one.
#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <cmath>
#include <random>

#include "tmm/surface/bezier.hpp"

namespace {

using Eigen::Vector3d;
using tmm::BezierPatch;
using tmm::PatchSurface;

double binom(int n, int k) {
  double r = 1.0;
  for (int i = 1; i <= k; ++i) r = r * (n - k + i) / i;
  return r;
}

Vector3d explicit_point(const BezierPatch& b, double u, double v) {
  Vector3d s = Vector3d::Zero();
  const int p = b.degree_u(), q = b.degree_v();
  for (int i = 0; i <= p; ++i)
    for (int j = 0; j <= q; ++j)
      s += binom(p, i) * std::pow(u, i) * std::pow(1 - u, p - i) * binom(q, j) * std::pow(v, j) *
           std::pow(1 - v, q - j) * b.pole(i, j);
  return s;
}

BezierPatch random_patch(int p, int q, unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> U(-1.0, 1.0);
  std::vector<Vector3d> net;
  for (int i = 0; i <= p; ++i)
    for (int j = 0; j <= q; ++j) net.emplace_back(10.0 * i + U(rng), 10.0 * j + U(rng), 5.0 * U(rng));
  return BezierPatch(p, q, net);
}

// Seed 001 table 1: x = 50 i, y = 50 j.
BezierPatch seed_patch(bool convex) {
  const double cz[16] = {80, 90, 90, 80, 90, 105, 105, 90, 90, 105, 105, 90, 80, 90, 90, 80};
  const double vz[16] = {80, 70, 70, 80, 70, 55, 55, 70, 70, 55, 55, 70, 80, 70, 70, 80};
  std::vector<Vector3d> net;
  for (int i = 0; i < 4; ++i)
    for (int j = 0; j < 4; ++j) net.emplace_back(50.0 * i, 50.0 * j, (convex ? cz : vz)[i * 4 + j]);
  return BezierPatch(3, 3, net);
}

TEST(Bezier, EvaluationMatchesExplicitBernsteinSum) {
  for (auto [p, q] : {std::pair{3, 3}, {1, 1}, {2, 5}, {0, 3}, {7, 2}, {12, 9}}) {
    const BezierPatch b = random_patch(p, q, 7u * p + q);
    for (double u : {0.0, 0.13, 0.5, 0.77, 1.0})
      for (double v : {0.0, 0.31, 0.62, 1.0}) {
        const Vector3d ref = explicit_point(b, u, v);
        EXPECT_LT((b.point(u, v) - ref).norm(), 1e-11) << p << "x" << q << " at " << u << "," << v;
        EXPECT_LT((b.eval(u, v).S - ref).norm(), 1e-11);
      }
  }
}

TEST(Bezier, DerivativesMatchFiniteDifferences) {
  const double h = 1e-5;
  for (auto [p, q] : {std::pair{3, 3}, {2, 4}, {5, 1}}) {
    const BezierPatch b = random_patch(p, q, 11u + p);
    for (double u : {0.2, 0.5, 0.9})
      for (double v : {0.1, 0.45, 0.8}) {
        const auto sp = b.eval(u, v);
        const Vector3d Su = (explicit_point(b, u + h, v) - explicit_point(b, u - h, v)) / (2 * h);
        const Vector3d Sv = (explicit_point(b, u, v + h) - explicit_point(b, u, v - h)) / (2 * h);
        const auto e1 = b.eval(u + h, v), e0 = b.eval(u - h, v), f1 = b.eval(u, v + h), f0 = b.eval(u, v - h);
        EXPECT_LT((sp.Su - Su).norm(), 1e-6 * (1 + Su.norm()));
        EXPECT_LT((sp.Sv - Sv).norm(), 1e-6 * (1 + Sv.norm()));
        EXPECT_LT((sp.Suu - (e1.Su - e0.Su) / (2 * h)).norm(), 1e-5 * (1 + sp.Suu.norm()));
        EXPECT_LT((sp.Suv - (f1.Su - f0.Su) / (2 * h)).norm(), 1e-5 * (1 + sp.Suv.norm()));
        EXPECT_LT((sp.Svv - (f1.Sv - f0.Sv) / (2 * h)).norm(), 1e-5 * (1 + sp.Svv.norm()));
      }
  }
}

TEST(Bezier, SubdivisionIsExactAndBoundsHoldThePatch) {
  const BezierPatch b = random_patch(3, 4, 5);
  const double u0 = 0.2, u1 = 0.65, v0 = 0.1, v1 = 0.9;
  const BezierPatch s = b.sub(u0, u1, v0, v1);
  for (double a : {0.0, 0.3, 0.7, 1.0})
    for (double c : {0.0, 0.25, 1.0}) {
      const Vector3d ref = explicit_point(b, u0 + a * (u1 - u0), v0 + c * (v1 - v0));
      EXPECT_LT((s.point(a, c) - ref).norm(), 1e-11);
    }
  for (double a = 0; a <= 1.0; a += 0.05)
    for (double c = 0; c <= 1.0; c += 0.05) {
      const Vector3d p = b.point(a, c);
      EXPECT_TRUE((p.array() >= b.bounds().lo.array() - 1e-12).all() && (p.array() <= b.bounds().hi.array() + 1e-12).all());
    }
}

TEST(Bezier, SubdivisionExtrapolatesOutsideTheUnitSquare) {
  // Intervals reaching past 0 or 1 (or lying wholly outside) give the polynomial's continuation: the
  // explicit Bernstein sum evaluated at parameters outside [0, 1].
  const BezierPatch b = random_patch(3, 4, 11);
  const double iv[][2] = {{-0.3, 1.2}, {-0.5, -0.1}, {1.1, 1.6}, {0.9, 1.4}, {-0.2, 0.4}, {0.3, 0.8}};
  for (const auto& I : iv) {
    for (const auto& J : iv) {
      const BezierPatch s = b.sub(I[0], I[1], J[0], J[1]);
      for (double a : {0.0, 0.3, 0.7, 1.0})
        for (double c : {0.0, 0.45, 1.0}) {
          const Vector3d ref = explicit_point(b, I[0] + a * (I[1] - I[0]), J[0] + c * (J[1] - J[0]));
          EXPECT_LT((s.point(a, c) - ref).norm(), 1e-9 * (1.0 + ref.norm()))
              << "[" << I[0] << ", " << I[1] << "] x [" << J[0] << ", " << J[1] << "] at " << a << ", " << c;
        }
    }
  }
}

TEST(Bezier, ExtendedFaceKeepsTheFaceAndContinuesItsPolynomial) {
  // The seed's concave patch (x = 150 u, y = 150 v) cut into 2 x 2 pieces, extended by 12.7 mm: over the old
  // domain the same surface (derivatives too), outside it the polynomial's continuation, reaching between
  // 12.7 / |dS/du|max and 12.7 / 150 mm in x (the speed across the boundary is at least 150).
  const BezierPatch b = seed_patch(false);
  const std::vector<double> bu = {0.0, 0.4, 1.0}, bv = {0.0, 0.55, 1.0};
  std::vector<BezierPatch> pieces;
  for (int i = 0; i < 2; ++i)
    for (int j = 0; j < 2; ++j) pieces.push_back(b.sub(bu[i], bu[i + 1], bv[j], bv[j + 1]));
  const PatchSurface face(pieces, 2, 2, bu, bv);
  const PatchSurface ext = face.extended(12.7);
  EXPECT_EQ(ext.patch_count(), 4);
  for (double lo : {-ext.umin(), -ext.vmin(), ext.umax() - 1.0, ext.vmax() - 1.0}) {
    EXPECT_LE(lo * 150.0, 12.7 + 1e-9);
    EXPECT_GE(lo * 150.0, 12.7 * 150.0 / std::hypot(150.0, 45.0));
  }
  EXPECT_NEAR(ext.breaks_u()[1], 0.4, 1e-15);  // inner breakpoints unchanged
  EXPECT_NEAR(ext.breaks_v()[1], 0.55, 1e-15);
  for (double U : {0.0, 0.13, 0.4, 0.77, 1.0})
    for (double V : {0.0, 0.3, 0.55, 1.0}) {
      const auto a = ext.eval(U, V), r = b.eval(U, V);
      EXPECT_LT((a.S - r.S).norm(), 1e-10);
      EXPECT_LT((a.Su - r.Su).norm(), 1e-8);
      EXPECT_LT((a.Svv - r.Svv).norm(), 1e-6);
    }
  for (double U : {ext.umin(), -0.05, 0.5, 1.04, ext.umax()})
    for (double V : {ext.vmin(), -0.02, 0.5, ext.vmax()}) {
      const Vector3d r = explicit_point(b, U, V);
      EXPECT_LT((ext.point(U, V) - r).norm(), 1e-9 * (1.0 + r.norm())) << U << ", " << V;
    }
  // The concave bowl keeps rising past its rim x = 0 (the boundary curve is no longer the highest line).
  EXPECT_GT(ext.point(ext.umin(), 0.18).z(), face.point(0.0, 0.18).z() + 1.0);
  EXPECT_EQ(face.extended(0.0).umin(), 0.0);
  EXPECT_THROW(face.extended(-1.0), std::invalid_argument);
}

TEST(Bezier, MultiPatchSurfaceIsSeamlessAcrossItsPieces) {
  // One patch cut into 3 x 2 pieces with non-uniform breakpoints: the face must be the same surface,
  // derivatives included (C-infinity across every seam).
  const BezierPatch b = random_patch(3, 3, 9);
  const std::vector<double> bu = {0.0, 0.25, 0.6, 1.0}, bv = {0.0, 0.7, 1.0};
  std::vector<BezierPatch> pieces;
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 2; ++j) pieces.push_back(b.sub(bu[i], bu[i + 1], bv[j], bv[j + 1]));
  const PatchSurface face(pieces, 3, 2, bu, bv);
  EXPECT_EQ(face.patch_count(), 6);
  for (double U : {0.0, 0.1, 0.25, 0.2500000001, 0.6, 0.61, 1.0})
    for (double V : {0.0, 0.7, 0.69999, 0.9, 1.0}) {
      const auto a = face.eval(U, V), r = b.eval(U, V);
      EXPECT_LT((a.S - r.S).norm(), 1e-10);
      EXPECT_LT((a.Su - r.Su).norm(), 1e-8);
      EXPECT_LT((a.Sv - r.Sv).norm(), 1e-8);
      EXPECT_LT((a.Suu - r.Suu).norm(), 1e-6);
      EXPECT_LT((a.Suv - r.Suv).norm(), 1e-6);
      EXPECT_LT((a.Svv - r.Svv).norm(), 1e-6);
    }
}

TEST(Bezier, VerticalRayHitsLieOnRayAndSurface) {
  const PatchSurface face(seed_patch(true));
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> X(0.0, 150.0);
  for (int k = 0; k < 200; ++k) {
    const Vector3d o(X(rng), X(rng), 200.0);
    const auto hit = face.ray_hit(o, Vector3d(0, 0, -1));
    ASSERT_TRUE(hit.has_value());
    // x = 150 u, y = 150 v exactly on this patch (uniform x, y poles: linear precision).
    EXPECT_NEAR(hit->uv.x(), o.x() / 150.0, 1e-9);
    EXPECT_NEAR(hit->uv.y(), o.y() / 150.0, 1e-9);
    const Vector3d p = explicit_point(face.patch(0, 0), hit->uv.x(), hit->uv.y());
    EXPECT_NEAR(o.z() - hit->s, p.z(), 1e-8);
  }
  EXPECT_FALSE(face.ray_hit(Vector3d(-5, 10, 200), Vector3d(0, 0, -1)).has_value());
  EXPECT_FALSE(face.ray_hit(Vector3d(50, 50, 0), Vector3d(0, 0, -1)).has_value());  // below, going down
}

TEST(Bezier, ObliqueRayFindsTheFirstHit) {
  // A ray through the concave bowl crosses it twice; the first crossing must be returned.
  const PatchSurface face(seed_patch(false));
  const Vector3d o(-10.0, 75.0, 80.0), d = Vector3d(1.0, 0.0, -0.3).normalized();
  const auto hit = face.ray_hit(o, d);
  ASSERT_TRUE(hit.has_value());
  const Vector3d p = face.point(hit->uv.x(), hit->uv.y());
  EXPECT_LT((p - (o + hit->s * d)).norm(), 1e-8);
  EXPECT_LT(p.x(), 75.0);  // the entry into the bowl, not the exit
  // March along the ray up to the hit: never below the surface before it (the bowl is a height field).
  for (double s = 0; s < hit->s - 1e-6; s += 0.01) {
    const Vector3d r = o + s * d;
    if (r.x() < 0 || r.x() > 150) continue;
    const double z = face.point(r.x() / 150.0, r.y() / 150.0).z();
    ASSERT_GT(r.z(), z - 1e-9) << "crossed the surface at s = " << s << " before the hit at " << hit->s;
  }
}

TEST(Bezier, TransformedPatchIsTheMovedSurface) {
  const BezierPatch b = random_patch(3, 2, 4);
  const Eigen::Matrix3d R = Eigen::AngleAxisd(0.4, Vector3d(1, 2, 3).normalized()).toRotationMatrix();
  const Vector3d t(1, -2, 3);
  const BezierPatch m = b.transformed(R, t);
  for (double u : {0.0, 0.4, 1.0})
    for (double v : {0.2, 0.9}) EXPECT_LT((m.point(u, v) - (R * b.point(u, v) + t)).norm(), 1e-12);
}

TEST(Bezier, RejectsBadInput) {
  EXPECT_THROW(BezierPatch(3, 3, std::vector<Vector3d>(15)), std::invalid_argument);
  EXPECT_THROW(BezierPatch(-1, 3, {}), std::invalid_argument);
  std::vector<Vector3d> net(4, Vector3d::Zero());
  net[2].x() = std::nan("");
  EXPECT_THROW(BezierPatch(1, 1, net), std::invalid_argument);
  EXPECT_THROW(PatchSurface({random_patch(1, 1, 1)}, 1, 1, {0.0, 0.0}, {0.0, 1.0}), std::invalid_argument);
}

}  // namespace
