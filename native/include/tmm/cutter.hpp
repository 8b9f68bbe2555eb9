// A convex cutter of revolution, described by its lower profile h(rho): the height of the cutting surface
// above the tool tip at distance rho from the axis (0 <= rho <= radius). Drop-cutter needs nothing else:
//   vertex contact: tip = v.z - h(rho)
//   facet contact:  the cutter point whose outward normal is -n (rho where h'(rho) = |n_xy| / n_z)
//   edge contact:   the maximum of the concave function z_edge(u) - h(rho(u)) along the edge.
// Ball (r = R), flat (r = 0) and bull-nose (0 < r < R) are the corner-radius family of seed 000's
// generalized APT cutter; the cone and taper regions extend this class later (same profile interface).
#pragma once

#include <cmath>

namespace tmm {

enum class CutterKind { Flat, Ball, Bull };

class Cutter {
 public:
  // radius R > 0, corner radius 0 <= r <= R; throws std::invalid_argument otherwise.
  Cutter(double radius, double corner_radius);

  double radius() const { return R_; }
  double corner_radius() const { return r_; }
  // Radius of the flat bottom (the torus' ring radius): R - r.
  double flat_radius() const { return a_; }
  CutterKind kind() const { return kind_; }

  // h(rho): height of the cutting surface above the tip at distance rho from the axis (rho <= R).
  double height(double rho) const {
    if (rho <= a_) return 0.0;
    const double t = rho - a_;
    return r_ - std::sqrt(std::fmax(r_ * r_ - t * t, 0.0));
  }
  // h'(rho); +inf at the rim of a ball or bull-nose.
  double slope(double rho) const {
    if (rho <= a_) return 0.0;
    const double t = rho - a_;
    return t / std::sqrt(std::fmax(r_ * r_ - t * t, 0.0));
  }
  // h''(rho) (0 on the flat bottom).
  double curvature(double rho) const {
    if (rho <= a_) return 0.0;
    const double t = rho - a_;
    const double q = std::fmax(r_ * r_ - t * t, 0.0);
    return r_ * r_ / (q * std::sqrt(q));
  }
  // Distance from the axis of the point touching a plane whose unit normal has horizontal length nxy
  // (nxy = sin of the plane's slope): h'(rho) = tan(slope). For the flat cutter, the rim.
  double facet_contact_radius(double nxy) const { return a_ + r_ * nxy; }

 private:
  double R_;
  double r_;
  double a_;
  CutterKind kind_;
};

}  // namespace tmm
