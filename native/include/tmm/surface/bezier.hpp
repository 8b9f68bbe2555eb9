// Tensor-product Bezier patches of any degree, and faces made of several patches (a B-spline face split
// into its Bezier pieces by knot insertion). Exact: nothing is tessellated.
//
//   S(u, v) = sum_ij B_i^p(u) B_j^q(v) P_ij,  0 <= u, v <= 1 on a patch.
//
// A PatchSurface is a grid of nu x nv patches over breakpoints U_0 < ... < U_nu, V_0 < ... < V_nv (the
// B-spline's distinct knots): patch (i, j) covers [U_i, U_i+1] x [V_j, V_j+1] and is evaluated at
// u = (U - U_i) / (U_i+1 - U_i). Derivatives are with respect to the global (U, V), so they are continuous
// across the seams wherever the B-spline is C1.
#pragma once

#include <Eigen/Core>

#include <optional>
#include <utility>
#include <vector>

namespace tmm {

using Eigen::Vector2d;
using Eigen::Vector3d;

constexpr int kMaxBezierDegree = 30;

// S and its first and second partial derivatives at one parameter pair.
struct SurfacePoint {
  Vector3d S, Su, Sv, Suu, Suv, Svv;
  // Unit normal Su x Sv (zero vector where the patch is degenerate).
  Vector3d normal() const;
};

struct Box3 {
  Vector3d lo{Vector3d::Constant(1e300)};
  Vector3d hi{Vector3d::Constant(-1e300)};
  void extend(const Vector3d& p) {
    lo = lo.cwiseMin(p);
    hi = hi.cwiseMax(p);
  }
  void extend(const Box3& b) {
    lo = lo.cwiseMin(b.lo);
    hi = hi.cwiseMax(b.hi);
  }
  bool empty() const { return lo.x() > hi.x(); }
};

class BezierPatch {
 public:
  // Control net of degree p x q: (p+1)(q+1) poles, row-major (pole (i, j) at i*(q+1) + j).
  // Throws std::invalid_argument on a wrong count, a degree above kMaxBezierDegree or a non-finite pole.
  BezierPatch(int p, int q, std::vector<Vector3d> poles);

  int degree_u() const { return p_; }
  int degree_v() const { return q_; }
  const Vector3d& pole(int i, int j) const { return poles_[static_cast<std::size_t>(i * (q_ + 1) + j)]; }
  const std::vector<Vector3d>& poles() const { return poles_; }

  Vector3d point(double u, double v) const;
  // S with first and second derivatives (order 1: the second ones are left zero).
  SurfacePoint eval(double u, double v, int order = 2) const;
  // Bounding box of the control net: it holds the patch (convex hull property).
  const Box3& bounds() const { return box_; }

  // The piece over [u0, u1] x [v0, v1], reparametrised to the unit square (de Casteljau, exact). The
  // interval may reach outside [0, 1]: that part is the polynomial's continuation (extrapolation).
  BezierPatch sub(double u0, double u1, double v0, double v1) const;
  // x -> R x + t applied to the poles (exact for a polynomial patch).
  BezierPatch transformed(const Eigen::Matrix3d& R, const Vector3d& t) const;

 private:
  int p_, q_;
  std::vector<Vector3d> poles_;
  Box3 box_;
};

// First hit of a ray origin + s * dir (s >= 0) with a surface.
struct RayHit {
  double s;     // distance along dir (dir is normalised by the caller's choice: s is in dir's units)
  Vector2d uv;  // global parameters
};

class PatchSurface {
 public:
  // patches: nu * nv patches, row-major over (i in u, j in v): patch (i, j) at i*nv + j.
  // bu: nu + 1 increasing breakpoints in u, bv: nv + 1 in v.
  PatchSurface(std::vector<BezierPatch> patches, int nu, int nv, std::vector<double> bu,
               std::vector<double> bv);
  // One patch over [0, 1]^2.
  explicit PatchSurface(BezierPatch patch);

  int nu() const { return nu_; }
  int nv() const { return nv_; }
  int patch_count() const { return nu_ * nv_; }
  const BezierPatch& patch(int i, int j) const { return patches_[static_cast<std::size_t>(i * nv_ + j)]; }
  const std::vector<BezierPatch>& patches() const { return patches_; }
  const std::vector<double>& breaks_u() const { return bu_; }
  const std::vector<double>& breaks_v() const { return bv_; }
  double umin() const { return bu_.front(); }
  double umax() const { return bu_.back(); }
  double vmin() const { return bv_.front(); }
  double vmax() const { return bv_.back(); }
  Vector2d lo() const { return {umin(), vmin()}; }
  Vector2d hi() const { return {umax(), vmax()}; }

  // Global parameters (clamped to the domain); derivatives with respect to U, V.
  SurfacePoint eval(double U, double V, int order = 2) const;
  Vector3d point(double U, double V) const;
  // Patch index holding (U, V) (the lower one on a seam) and the local parameters.
  int locate(double U, double V, double* u, double* v) const;

  const Box3& bounds() const { return box_; }

  PatchSurface transformed(const Eigen::Matrix3d& R, const Vector3d& t) const;

  // The face continued past its four boundary curves by about `distance` (model units, >= 0) measured on
  // the surface: each boundary patch is replaced by its polynomial continuation (BezierPatch::sub over an
  // interval reaching outside [0, 1]; the natural extension of the polynomial, C-infinity across the old
  // boundary), and the outer breakpoints move out so that the global parameters of the original face are
  // unchanged: over the old domain the extended face is the same surface. The parameter reach of a side
  // is distance / (smallest speed |dS/du| along that boundary), at most half the boundary patch (a
  // polynomial far outside its domain can fold). distance = 0 returns a copy.
  PatchSurface extended(double distance) const;

  // First intersection with the ray origin + s dir, s >= 0 (dir need not be unit). Patches and then
  // sub-patches are culled by their control-hull boxes (slab test) and visited nearest first; on a leaf
  // (1/16 of a patch per direction, or a flat enough net) Newton's method solves S(u, v) = o + s d in
  // (u, v, s). A hit is accepted when |S - (o + s d)| <= 1e-9 * (1 + |S|) and (u, v) lies in the leaf
  // (widened by 1e-9). Tangential grazing hits may be missed; a hit is never invented.
  std::optional<RayHit> ray_hit(const Vector3d& origin, const Vector3d& dir) const;
  // Newton only, from a starting guess (no culling): fast when consecutive rays are close. Returns a hit
  // only if converged inside the domain; it may not be the first one along the ray.
  std::optional<RayHit> ray_hit_newton(const Vector3d& origin, const Vector3d& dir, Vector2d guess) const;

 private:
  std::vector<BezierPatch> patches_;
  int nu_, nv_;
  std::vector<double> bu_, bv_;
  Box3 box_;
};

}  // namespace tmm
