// GJK (Gilbert, Johnson, Keerthi 1988) on D = T - S, T the triangle, S = K + [t0, cap] W: the origin is
// outside D exactly when the triangle misses every position of K over those travels. Each step takes the
// point w of D lowest along the current v (the closest point of the simplex to the origin); v . w > 0 is a
// separating plane (every point of D lies on its far side), which ends the search with a proof. Closest
// points on the simplex after Ericson, Real-Time Collision Detection, 5.1.5 (triangle) and 5.1.6 (tetrahedron).
#include "tmm/query/swept_clearance.hpp"

#include <Eigen/Geometry>

#include <cmath>

#include "tmm/query/drop_direction.hpp"

namespace tmm::direction_detail {

using Eigen::Vector3d;

namespace {

constexpr int kMaxSteps = 20;
constexpr double kSeparation = 1e-9;  // mm: a plane closer than this proves nothing

struct Simplex {
  Vector3d y[4] = {Vector3d::Zero(), Vector3d::Zero(), Vector3d::Zero(), Vector3d::Zero()};
  int n = 0;
};

// The closest point to the origin of the segment y0 y1; the simplex keeps the points that span it.
Vector3d closest_on_segment(Simplex& s) {
  const Vector3d a = s.y[0], ab = s.y[1] - a;
  const double den = ab.squaredNorm();
  const double t = den > 0 ? -a.dot(ab) / den : 0.0;
  if (t <= 0) {
    s.n = 1;
    return a;
  }
  if (t >= 1) {
    s.y[0] = s.y[1];
    s.n = 1;
    return s.y[0];
  }
  return a + t * ab;
}

// The same for the triangle y0 y1 y2 (Voronoi regions of the corners, then the edges, then the inside).
// false for a triangle too degenerate to tell.
bool closest_on_triangle(Simplex& s, Vector3d& v) {
  const Vector3d a = s.y[0], b = s.y[1], c = s.y[2];
  const Vector3d ab = b - a, ac = c - a;
  const double d1 = -ab.dot(a), d2 = -ac.dot(a);
  if (d1 <= 0 && d2 <= 0) {
    s.n = 1;
    v = a;
    return true;
  }
  const double d3 = -ab.dot(b), d4 = -ac.dot(b);
  if (d3 >= 0 && d4 <= d3) {
    s.y[0] = b;
    s.n = 1;
    v = b;
    return true;
  }
  const double vc = d1 * d4 - d3 * d2;
  if (vc <= 0 && d1 >= 0 && d3 <= 0) {
    s.n = 2;  // a, b
    v = a + (d1 / (d1 - d3)) * ab;
    return true;
  }
  const double d5 = -ab.dot(c), d6 = -ac.dot(c);
  if (d6 >= 0 && d5 <= d6) {
    s.y[0] = c;
    s.n = 1;
    v = c;
    return true;
  }
  const double vb = d5 * d2 - d1 * d6;
  if (vb <= 0 && d2 >= 0 && d6 <= 0) {
    s.y[1] = c;
    s.n = 2;  // a, c
    v = a + (d2 / (d2 - d6)) * ac;
    return true;
  }
  const double va = d3 * d6 - d5 * d4;
  if (va <= 0 && d4 - d3 >= 0 && d5 - d6 >= 0) {
    s.y[0] = b;
    s.y[1] = c;
    s.n = 2;  // b, c
    v = b + ((d4 - d3) / ((d4 - d3) + (d5 - d6))) * (c - b);
    return true;
  }
  const double sum = va + vb + vc;
  if (!(sum > 0)) return false;
  v = a + (vb / sum) * ab + (vc / sum) * ac;
  return true;
}

// The same for the tetrahedron y0..y3: the closest of its faces that have the origin strictly outside;
// false when none has (the origin inside, or a tetrahedron too flat to tell).
bool closest_on_tetrahedron(Simplex& s, Vector3d& v) {
  static constexpr int kFaces[4][4] = {{0, 1, 2, 3}, {0, 1, 3, 2}, {0, 2, 3, 1}, {1, 2, 3, 0}};
  double best = INFINITY;
  Simplex best_face;
  for (const auto& f : kFaces) {
    const Vector3d& a = s.y[f[0]];
    const Vector3d n = (s.y[f[1]] - a).cross(s.y[f[2]] - a);
    if (!(n.dot(-a) * n.dot(s.y[f[3]] - a) < 0)) continue;
    Simplex face;
    face.y[0] = a;
    face.y[1] = s.y[f[1]];
    face.y[2] = s.y[f[2]];
    face.n = 3;
    Vector3d p;
    if (!closest_on_triangle(face, p)) continue;
    if (p.squaredNorm() < best) {
      best = p.squaredNorm();
      best_face = face;
      v = p;
    }
  }
  if (!(best < INFINITY)) return false;
  s = best_face;
  return true;
}

// The point of D lowest along d: the triangle's corner lowest along d minus S's point highest along it
// (inlined: GJK's inner step).
[[gnu::always_inline]] inline Vector3d lowest_along(const Cutter& c, const Vector3d& q0, const Vector3d& q1,
                                                    const Vector3d& q2, const Vector3d& W, double t0, double cap,
                                                    const Vector3d& d) {
  const double a0 = d.dot(q0), a1 = d.dot(q1), a2 = d.dot(q2);
  const Vector3d& q = a0 <= a1 ? (a0 <= a2 ? q0 : q2) : (a1 <= a2 ? q1 : q2);
  return q - support(c, d).point - (d.dot(W) >= 0 ? cap : t0) * W;
}

bool sweep_valid(const Cutter& c, double t0, double cap) {
  return std::isfinite(t0) && std::isfinite(cap) && t0 <= cap && std::isfinite(c.cutting_length());
}

}  // namespace

bool plane_clears(const Cutter& c, const Vector3d& q0, const Vector3d& q1, const Vector3d& q2, const Vector3d& W,
                  double t0, double cap, const Vector3d& v) {
  if (!sweep_valid(c, t0, cap) || !(v.squaredNorm() > 0)) return false;
  return v.dot(lowest_along(c, q0, q1, q2, W, t0, cap, v)) > kSeparation * v.norm();
}

bool triangle_clear(const Cutter& c, const Vector3d& q0, const Vector3d& q1, const Vector3d& q2,
                    const Vector3d& W, double t0, double cap, Vector3d* plane) {
  if (!sweep_valid(c, t0, cap)) return false;
  auto lowest = [&](const Vector3d& d) { return lowest_along(c, q0, q1, q2, W, t0, cap, d); };
  Simplex s;
  // From the plane that last separated the triangle from a nearby start, where there is one (the search
  // then starts near its answer), else from the motion's direction.
  Vector3d v = lowest(plane && plane->squaredNorm() > 0 ? *plane : W);
  s.y[0] = v;
  s.n = 1;
  for (int step = 0; step < kMaxSteps; ++step) {
    const double vv = v.squaredNorm();
    if (!(vv > kSeparation * kSeparation)) return false;  // touching, or nearly
    const Vector3d w = lowest(v);
    const double vw = v.dot(w);
    if (vw > kSeparation * std::sqrt(vv)) {  // D lies beyond the plane v . x = v . w > 0
      if (plane) *plane = v;
      return true;
    }
    if (vv - vw <= 1e-12 * vv) return false;             // no progress: as close as it gets, not separated
    s.y[s.n++] = w;
    bool ok = true;
    if (s.n == 2) v = closest_on_segment(s);
    else if (s.n == 3) ok = closest_on_triangle(s, v);
    else ok = closest_on_tetrahedron(s, v);
    if (!ok) return false;
  }
  return false;
}

}  // namespace tmm::direction_detail
