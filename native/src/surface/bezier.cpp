#include "tmm/surface/bezier.hpp"

#include <Eigen/Dense>

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <sstream>
#include <stdexcept>
#include <string>

#include "tmm/util/range.hpp"

namespace tmm {

namespace {

using Basis = std::array<double, kMaxBezierDegree + 1>;

// Bernstein values of degree n at t and their first and second derivatives (zero where n < order).
// The triangle recurrence B^k_j = (1 - t) B^(k-1)_j + t B^(k-1)_(j-1) is stable for all t in [0, 1];
// degrees n-1 and n-2 are kept on the way for the derivatives.
void bernstein(int n, double t, int order, double* b, double* db, double* ddb) {
  // b holds the degree-k basis as k grows; degrees n-1 and n-2 are copied out on the way (n+1 entries
  // at most, no full-size array traffic: this runs twice per surface evaluation).
  double prev1[kMaxBezierDegree + 1], prev2[kMaxBezierDegree + 1];
  b[0] = 1.0;
  if (n == 2) prev2[0] = 1.0;
  if (n == 1) prev1[0] = 1.0;
  const double s = 1.0 - t;
  for (int k = 1; k <= n; ++k) {
    double carry = 0.0;
    for (int j = 0; j < k; ++j) {
      const double c = b[j];
      b[j] = s * c + carry;
      carry = t * c;
    }
    b[k] = carry;
    if (k == n - 2 && order >= 2) std::copy(b, b + k + 1, prev2);
    if (k == n - 1 && order >= 1) std::copy(b, b + k + 1, prev1);
  }
  if (order >= 1) {
    for (int i = 0; i <= n; ++i) {
      const double lo = (n >= 1 && i >= 1) ? prev1[i - 1] : 0.0;
      const double hi = (n >= 1 && i <= n - 1) ? prev1[i] : 0.0;
      db[i] = n * (lo - hi);
    }
  }
  if (order >= 2) {
    for (int i = 0; i <= n; ++i) {
      if (n < 2) {
        ddb[i] = 0.0;
        continue;
      }
      const double a = (i >= 2) ? prev2[i - 2] : 0.0;
      const double m = (i >= 1 && i - 1 <= n - 2) ? prev2[i - 1] : 0.0;
      const double c = (i <= n - 2) ? prev2[i] : 0.0;
      ddb[i] = n * (n - 1) * (a - 2.0 * m + c);
    }
  }
}

// Control points of the piece [a, b] of a Bezier curve, in place: de Casteljau at b (the piece [0, b]),
// then at a / b of that (its piece [a / b, 1]). The polynomial identity holds for any a < b, also outside
// [0, 1]: a piece reaching past the ends is the curve's polynomial continuation (extrapolation). When b is
// near 0 (a piece left of 0) the order is swapped: [a, 1] first, then [0, (b - a) / (1 - a)] of that.
void sub_curve(std::vector<Vector3d>& c, double a, double b) {
  const int n = static_cast<int>(c.size()) - 1;
  if (n == 0) return;
  auto left = [&](double t) {  // piece [0, t]: first point of each column
    std::vector<Vector3d> w = c;
    for (int k = 1; k <= n; ++k) {
      for (int j = 0; j <= n - k; ++j) w[j] = (1.0 - t) * w[j] + t * w[j + 1];
      c[k] = w[0];
    }
  };
  auto right = [&](double t) {  // piece [t, 1]: last point of each column
    std::vector<Vector3d> w = c;
    for (int k = 1; k <= n; ++k) {
      for (int j = 0; j <= n - k; ++j) w[j] = (1.0 - t) * w[j] + t * w[j + 1];
      c[n - k] = w[n - k];
    }
  };
  if (std::abs(b) >= std::abs(1.0 - a)) {
    if (b != 1.0) left(b);
    if (a != 0.0) right(a / b);
  } else {
    if (a != 0.0) right(a);
    if (b != 1.0) left((b - a) / (1.0 - a));
  }
}

bool finite(const Vector3d& p) { return std::isfinite(p.x()) && std::isfinite(p.y()) && std::isfinite(p.z()); }

// Entry distance of the ray into the box (slab test), or +inf if it misses (s >= 0 only).
double ray_box(const Vector3d& o, const Vector3d& inv_d, const Box3& b, double pad) {
  double t0 = 0.0, t1 = std::numeric_limits<double>::infinity();
  for (int k = 0; k < 3; ++k) {
    const double lo = b.lo[k] - pad, hi = b.hi[k] + pad;
    if (std::isinf(inv_d[k])) {
      if (o[k] < lo || o[k] > hi) return std::numeric_limits<double>::infinity();
      continue;
    }
    double ta = (lo - o[k]) * inv_d[k], tb = (hi - o[k]) * inv_d[k];
    if (ta > tb) std::swap(ta, tb);
    t0 = std::max(t0, ta);
    t1 = std::min(t1, tb);
    if (t0 > t1) return std::numeric_limits<double>::infinity();
  }
  return t0;
}

}  // namespace

Vector3d SurfacePoint::normal() const {
  const Vector3d n = Su.cross(Sv);
  const double len = n.norm();
  return len > 0.0 ? Vector3d(n / len) : Vector3d::Zero();
}

BezierPatch::BezierPatch(int p, int q, std::vector<Vector3d> poles) : p_(p), q_(q), poles_(std::move(poles)) {
  if (p < 0 || q < 0 || p > kMaxBezierDegree || q > kMaxBezierDegree) {
    std::ostringstream msg;
    msg << "Bezier degree " << p << " x " << q << " outside 0.." << kMaxBezierDegree;
    throw std::invalid_argument(msg.str());
  }
  if (poles_.size() != static_cast<std::size_t>((p + 1) * (q + 1))) {
    std::ostringstream msg;
    msg << "Bezier patch of degree " << p << " x " << q << " needs " << (p + 1) * (q + 1) << " poles, got "
        << poles_.size();
    throw std::invalid_argument(msg.str());
  }
  for (std::size_t k = 0; k < poles_.size(); ++k) {
    const Vector3d& c = poles_[k];
    if (!finite(c)) throw std::invalid_argument("Bezier patch has a non-finite pole");
    for (int i = 0; i < 3; ++i)
      if (!in_range(c[i])) require_in_range(c[i], "Bezier pole " + std::to_string(k) + " coordinate " + "xyz"[i]);
    box_.extend(c);
  }
}

Vector3d BezierPatch::point(double u, double v) const {
  Basis bu, bv;
  bernstein(p_, u, 0, bu.data(), nullptr, nullptr);
  bernstein(q_, v, 0, bv.data(), nullptr, nullptr);
  Vector3d s = Vector3d::Zero();
  for (int i = 0; i <= p_; ++i) {
    Vector3d row = Vector3d::Zero();
    const Vector3d* r = &poles_[static_cast<std::size_t>(i * (q_ + 1))];
    for (int j = 0; j <= q_; ++j) row += bv[j] * r[j];
    s += bu[i] * row;
  }
  return s;
}

SurfacePoint BezierPatch::eval(double u, double v, int order) const {
  Basis bu, dbu, ddbu, bv, dbv, ddbv;
  bernstein(p_, u, order, bu.data(), dbu.data(), ddbu.data());
  bernstein(q_, v, order, bv.data(), dbv.data(), ddbv.data());
  SurfacePoint sp;
  sp.S = sp.Su = sp.Sv = sp.Suu = sp.Suv = sp.Svv = Vector3d::Zero();
  for (int i = 0; i <= p_; ++i) {
    Vector3d r0 = Vector3d::Zero(), r1 = Vector3d::Zero(), r2 = Vector3d::Zero();
    const Vector3d* r = &poles_[static_cast<std::size_t>(i * (q_ + 1))];
    for (int j = 0; j <= q_; ++j) {
      r0 += bv[j] * r[j];
      if (order >= 1) r1 += dbv[j] * r[j];
      if (order >= 2) r2 += ddbv[j] * r[j];
    }
    sp.S += bu[i] * r0;
    if (order >= 1) {
      sp.Su += dbu[i] * r0;
      sp.Sv += bu[i] * r1;
    }
    if (order >= 2) {
      sp.Suu += ddbu[i] * r0;
      sp.Suv += dbu[i] * r1;
      sp.Svv += bu[i] * r2;
    }
  }
  return sp;
}

BezierPatch BezierPatch::sub(double u0, double u1, double v0, double v1) const {
  std::vector<Vector3d> net = poles_;
  const int nr = p_ + 1, nc = q_ + 1;
  std::vector<Vector3d> c;
  if (!(v0 == 0.0 && v1 == 1.0)) {
    for (int i = 0; i < nr; ++i) {
      c.assign(net.begin() + i * nc, net.begin() + (i + 1) * nc);
      sub_curve(c, v0, v1);
      std::copy(c.begin(), c.end(), net.begin() + i * nc);
    }
  }
  if (!(u0 == 0.0 && u1 == 1.0)) {
    c.resize(static_cast<std::size_t>(nr));
    for (int j = 0; j < nc; ++j) {
      for (int i = 0; i < nr; ++i) c[static_cast<std::size_t>(i)] = net[static_cast<std::size_t>(i * nc + j)];
      sub_curve(c, u0, u1);
      for (int i = 0; i < nr; ++i) net[static_cast<std::size_t>(i * nc + j)] = c[static_cast<std::size_t>(i)];
    }
  }
  return BezierPatch(p_, q_, std::move(net));
}

BezierPatch BezierPatch::transformed(const Eigen::Matrix3d& R, const Vector3d& t) const {
  std::vector<Vector3d> net(poles_.size());
  for (std::size_t k = 0; k < net.size(); ++k) net[k] = R * poles_[k] + t;
  return BezierPatch(p_, q_, std::move(net));
}

PatchSurface::PatchSurface(std::vector<BezierPatch> patches, int nu, int nv, std::vector<double> bu,
                           std::vector<double> bv)
    : patches_(std::move(patches)), nu_(nu), nv_(nv), bu_(std::move(bu)), bv_(std::move(bv)) {
  if (nu < 1 || nv < 1 || patches_.size() != static_cast<std::size_t>(nu) * static_cast<std::size_t>(nv)) {
    std::ostringstream msg;
    msg << "surface of " << nu << " x " << nv << " patches given " << patches_.size() << " patches";
    throw std::invalid_argument(msg.str());
  }
  if (bu_.size() != static_cast<std::size_t>(nu + 1) || bv_.size() != static_cast<std::size_t>(nv + 1)) {
    throw std::invalid_argument("surface breakpoints: need nu + 1 values in u and nv + 1 in v");
  }
  for (std::size_t k = 0; k < bu_.size(); ++k) require_in_range(bu_[k], "surface breakpoint u[" + std::to_string(k) + "]");
  for (std::size_t k = 0; k < bv_.size(); ++k) require_in_range(bv_[k], "surface breakpoint v[" + std::to_string(k) + "]");
  for (std::size_t k = 1; k < bu_.size(); ++k)
    if (!(bu_[k] > bu_[k - 1])) throw std::invalid_argument("surface breakpoints in u must increase");
  for (std::size_t k = 1; k < bv_.size(); ++k)
    if (!(bv_[k] > bv_[k - 1])) throw std::invalid_argument("surface breakpoints in v must increase");
  for (const auto& p : patches_) box_.extend(p.bounds());
}

PatchSurface::PatchSurface(BezierPatch patch)
    : PatchSurface(std::vector<BezierPatch>{std::move(patch)}, 1, 1, {0.0, 1.0}, {0.0, 1.0}) {}

int PatchSurface::locate(double U, double V, double* u, double* v) const {
  U = std::clamp(U, umin(), umax());
  V = std::clamp(V, vmin(), vmax());
  int i = static_cast<int>(std::upper_bound(bu_.begin(), bu_.end(), U) - bu_.begin()) - 1;
  int j = static_cast<int>(std::upper_bound(bv_.begin(), bv_.end(), V) - bv_.begin()) - 1;
  i = std::clamp(i, 0, nu_ - 1);
  j = std::clamp(j, 0, nv_ - 1);
  *u = (U - bu_[i]) / (bu_[i + 1] - bu_[i]);
  *v = (V - bv_[j]) / (bv_[j + 1] - bv_[j]);
  return i * nv_ + j;
}

SurfacePoint PatchSurface::eval(double U, double V, int order) const {
  double u, v;
  const int k = locate(U, V, &u, &v);
  const int i = k / nv_, j = k % nv_;
  SurfacePoint sp = patches_[static_cast<std::size_t>(k)].eval(u, v, order);
  const double su = 1.0 / (bu_[i + 1] - bu_[i]), sv = 1.0 / (bv_[j + 1] - bv_[j]);
  sp.Su *= su;
  sp.Sv *= sv;
  sp.Suu *= su * su;
  sp.Suv *= su * sv;
  sp.Svv *= sv * sv;
  return sp;
}

Vector3d PatchSurface::point(double U, double V) const {
  double u, v;
  const int k = locate(U, V, &u, &v);
  return patches_[static_cast<std::size_t>(k)].point(u, v);
}

PatchSurface PatchSurface::extended(double distance) const {
  if (!(distance >= 0.0) || !std::isfinite(distance)) throw std::invalid_argument("extension distance must be >= 0");
  if (distance == 0.0) return *this;
  // Local parameter reach of each side: distance over the smallest speed across the boundary (sampled).
  constexpr int kSamples = 33;
  constexpr double kMaxReach = 0.5;
  auto reach = [&](bool along_u, bool high) {
    double speed = std::numeric_limits<double>::infinity();
    const int n = along_u ? nv_ : nu_;
    for (int k = 0; k < n; ++k) {
      const BezierPatch& p = along_u ? patch(high ? nu_ - 1 : 0, k) : patch(k, high ? nv_ - 1 : 0);
      for (int s = 0; s < kSamples; ++s) {
        const double t = static_cast<double>(s) / (kSamples - 1);
        const SurfacePoint sp = along_u ? p.eval(high ? 1.0 : 0.0, t, 1) : p.eval(t, high ? 1.0 : 0.0, 1);
        speed = std::min(speed, (along_u ? sp.Su : sp.Sv).norm());
      }
    }
    return speed > 0.0 ? std::min(distance / speed, kMaxReach) : kMaxReach;
  };
  const double ulo = reach(true, false), uhi = reach(true, true), vlo = reach(false, false), vhi = reach(false, true);
  std::vector<BezierPatch> out;
  out.reserve(patches_.size());
  for (int i = 0; i < nu_; ++i) {
    for (int j = 0; j < nv_; ++j) {
      const double u0 = i == 0 ? -ulo : 0.0, u1 = i == nu_ - 1 ? 1.0 + uhi : 1.0;
      const double v0 = j == 0 ? -vlo : 0.0, v1 = j == nv_ - 1 ? 1.0 + vhi : 1.0;
      out.push_back(patch(i, j).sub(u0, u1, v0, v1));
    }
  }
  std::vector<double> bu = bu_, bv = bv_;
  bu.front() -= ulo * (bu_[1] - bu_[0]);
  bu.back() += uhi * (bu_[nu_] - bu_[nu_ - 1]);
  bv.front() -= vlo * (bv_[1] - bv_[0]);
  bv.back() += vhi * (bv_[nv_] - bv_[nv_ - 1]);
  return PatchSurface(std::move(out), nu_, nv_, std::move(bu), std::move(bv));
}

PatchSurface PatchSurface::transformed(const Eigen::Matrix3d& R, const Vector3d& t) const {
  std::vector<BezierPatch> out;
  out.reserve(patches_.size());
  for (const auto& p : patches_) out.push_back(p.transformed(R, t));
  return PatchSurface(std::move(out), nu_, nv_, bu_, bv_);
}

namespace {

// Newton for S(u, v) = o + s d on one patch, local parameters; true if converged inside [0, 1]^2.
bool newton_ray(const BezierPatch& patch, const Vector3d& o, const Vector3d& d, double& u, double& v,
                double& s) {
  for (int it = 0; it < 30; ++it) {
    const SurfacePoint sp = patch.eval(u, v, 1);
    const Vector3d F = sp.S - o - s * d;
    const double scale = 1.0 + sp.S.cwiseAbs().maxCoeff();
    Eigen::Matrix3d J;
    J.col(0) = sp.Su;
    J.col(1) = sp.Sv;
    J.col(2) = -d;
    const Eigen::PartialPivLU<Eigen::Matrix3d> lu(J);
    if (std::abs(lu.determinant()) < 1e-300) return false;
    const Vector3d step = lu.solve(F);
    u -= step[0];
    v -= step[1];
    s -= step[2];
    if (!std::isfinite(u) || !std::isfinite(v) || u < -0.5 || u > 1.5 || v < -0.5 || v > 1.5) return false;
    if (F.norm() <= 1e-10 * scale && step.head<2>().norm() < 1e-12) break;
    if (it == 29) {
      const Vector3d G = patch.point(u, v) - o - s * d;
      if (G.norm() > 1e-9 * scale) return false;
    }
  }
  const Vector3d G = patch.point(u, v) - o - s * d;
  const double scale = 1.0 + o.cwiseAbs().maxCoeff() + std::abs(s) * d.norm();
  const double tol = 1e-9;
  return G.norm() <= 1e-9 * scale && u >= -tol && u <= 1.0 + tol && v >= -tol && v <= 1.0 + tol;
}

}  // namespace

std::optional<RayHit> PatchSurface::ray_hit(const Vector3d& origin, const Vector3d& dir) const {
  const Vector3d inv(1.0 / dir.x(), 1.0 / dir.y(), 1.0 / dir.z());
  const double pad = 1e-9 * (1.0 + box_.hi.cwiseAbs().maxCoeff() + box_.lo.cwiseAbs().maxCoeff());
  double best = std::numeric_limits<double>::infinity();
  RayHit hit{0.0, Vector2d::Zero()};
  struct Node {
    BezierPatch net;
    double u0, u1, v0, v1;
    int depth;
    double entry;
  };
  for (int k = 0; k < patch_count(); ++k) {
    const BezierPatch& patch = patches_[static_cast<std::size_t>(k)];
    const double e = ray_box(origin, inv, patch.bounds(), pad);
    if (!(e < best)) continue;
    std::vector<Node> stack;
    stack.push_back({patch, 0.0, 1.0, 0.0, 1.0, 0, e});
    while (!stack.empty()) {
      Node n = std::move(stack.back());
      stack.pop_back();
      if (!(n.entry < best)) continue;
      const Vector3d ext = n.net.bounds().hi - n.net.bounds().lo;
      const bool leaf = n.depth >= 4 || ext.maxCoeff() <= 1e-6 * (1.0 + ext.norm());
      if (leaf) {
        double u = 0.5 * (n.u0 + n.u1), v = 0.5 * (n.v0 + n.v1);
        double s = n.entry;
        if (newton_ray(patch, origin, dir, u, v, s) && s >= -1e-12 && s < best) {
          best = std::max(s, 0.0);
          const int i = k / nv_, j = k % nv_;
          hit.s = best;
          hit.uv = Vector2d(bu_[i] + u * (bu_[i + 1] - bu_[i]), bv_[j] + v * (bv_[j + 1] - bv_[j]));
        }
        continue;
      }
      // Four children, pushed farthest first so the nearest is searched first.
      std::vector<Node> kids;
      kids.reserve(4);
      for (int a = 0; a < 2; ++a) {
        for (int b = 0; b < 2; ++b) {
          BezierPatch child = n.net.sub(0.5 * a, 0.5 * (a + 1), 0.5 * b, 0.5 * (b + 1));
          const double ce = ray_box(origin, inv, child.bounds(), pad);
          if (!(ce < best)) continue;
          const double um = 0.5 * (n.u0 + n.u1), vm = 0.5 * (n.v0 + n.v1);
          kids.push_back(Node{std::move(child), a ? um : n.u0, a ? n.u1 : um, b ? vm : n.v0, b ? n.v1 : vm,
                              n.depth + 1, ce});
        }
      }
      std::sort(kids.begin(), kids.end(), [](const Node& x, const Node& y) { return x.entry > y.entry; });
      for (auto& kid : kids) stack.push_back(std::move(kid));
    }
  }
  if (std::isinf(best)) return std::nullopt;
  return hit;
}

std::optional<RayHit> PatchSurface::ray_hit_newton(const Vector3d& origin, const Vector3d& dir,
                                                   Vector2d guess) const {
  double u, v;
  const int k = locate(guess.x(), guess.y(), &u, &v);
  double s = 0.0;
  {
    const Vector3d p = patches_[static_cast<std::size_t>(k)].point(u, v);
    s = (p - origin).dot(dir) / dir.squaredNorm();
  }
  if (!newton_ray(patches_[static_cast<std::size_t>(k)], origin, dir, u, v, s) || s < 0.0) return std::nullopt;
  const int i = k / nv_, j = k % nv_;
  return RayHit{s, Vector2d(bu_[i] + u * (bu_[i + 1] - bu_[i]), bv_[j] + v * (bv_[j + 1] - bv_[j]))};
}

}  // namespace tmm
