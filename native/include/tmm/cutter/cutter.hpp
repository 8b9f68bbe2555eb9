// A convex cutter of revolution: the generalized APT cutter of seed 000 (section 3.5.2.2, Figure 3-14,
// eq. 3.34-3.42), described by its lower profile h(rho): the height of the cutting surface above the tool
// tip at distance rho from the axis (0 <= rho <= max_radius). From the axis outwards the profile is
//   a bottom cone  h = rho tan(beta1)                       (beta1 = 0: flat bottom),
//   a corner arc   centre (e, f), radius r                  (r = 0: sharp corner),
//   a taper side   at beta2 from the axis, up to (R, L_C)   (beta2 > 0 widening upwards; <= 0: the widest
//                                                            point of the arc ends the profile).
// h is convex and non-decreasing, which is all drop-cutter needs:
//   vertex contact: tip = v.z - h(rho)
//   facet contact:  the cutter point whose outward normal is -n: rho where h'(rho) = tan(slope)
//   edge contact:   the maximum of the concave function z_edge(u) - h(rho(u)) along the edge.
// Ball (r = R), flat (r = 0) and bull-nose (0 < r < R) with beta1 = beta2 = 0 keep closed-form fast paths.
#pragma once

#include <cmath>

namespace tmm {

// max/min that compile to one instruction (std::fmax/fmin are libm calls, for NaN semantics not needed here).
inline double maxd(double a, double b) { return a > b ? a : b; }
inline double mind(double a, double b) { return a < b ? a : b; }

enum class CutterKind { Flat, Ball, Bull, General };

class Cutter {
 public:
  // Ball, flat or bull-nose: radius R > 0, corner radius 0 <= r <= R. Throws std::invalid_argument.
  Cutter(double radius, double corner_radius);
  // The generalized APT cutter: R the radius at the cutting-edge height L_C, corner radius r, bottom angle
  // beta1 in [0, 90) degrees from the horizontal, taper angle beta2 in (-90, 90) degrees from the axis
  // (positive when the side widens upwards). Angles in radians. Throws std::invalid_argument naming the
  // impossible parameter.
  static Cutter apt(double radius, double corner_radius, double cutting_length, double beta1, double beta2);

  double radius() const { return R_; }              // R: radius at the cutting-edge height
  double corner_radius() const { return r_; }
  double cutting_length() const { return Lc_; }
  double beta1() const { return beta1_; }
  double beta2() const { return beta2_; }
  double max_radius() const { return rho_max_; }    // extent of the lower profile (the shadow radius)
  double flat_radius() const { return rho_a_; }     // end of the bottom cone/flat (start of the arc)
  double arc_centre_radius() const { return e_; }   // e
  double arc_centre_height() const { return f_; }   // f
  CutterKind kind() const { return kind_; }

  // h(rho), 0 <= rho <= max_radius().
  double height(double rho) const {
    if (rho <= rho_a_) return k1_ * rho;
    if (rho <= rho_b_) {
      const double t = rho - e_;
      return f_ - std::sqrt(maxd(r_ * r_ - t * t, 0.0));
    }
    return h_b_ + (rho - rho_b_) * k2_;
  }
  // h'(rho); +inf where the arc turns vertical.
  double slope(double rho) const {
    if (rho <= rho_a_) return k1_;
    if (rho <= rho_b_) {
      const double t = rho - e_;
      return t / std::sqrt(maxd(r_ * r_ - t * t, 0.0));
    }
    return k2_;
  }
  // h''(rho) (0 on the cone and taper).
  double curvature(double rho) const {
    if (rho <= rho_a_ || rho > rho_b_) return 0.0;
    const double t = rho - e_;
    const double q = maxd(r_ * r_ - t * t, 0.0);
    return r_ * r_ / (q * std::sqrt(q));
  }
  // Squared radius within which the profile stays below `lift`: h(rho) < lift exactly when
  // rho^2 < reach2(lift). Pruning compares squared distances with it: no square roots for the ball.
  double reach2(double lift) const {
    if (!(lift > 0.0)) return -1.0;
    if (lift >= h_max_) return INFINITY;
    if (lift <= k1_ * rho_a_) {  // on the bottom cone, or anywhere on a flat bottom
      if (k1_ == 0.0) return rho_a_ * rho_a_;
      const double rho = lift / k1_;
      return rho * rho;
    }
    if (lift <= h_b_) {  // on the arc: (rho - e)^2 = r^2 - (f - lift)^2
      const double q = r_ * r_ - (f_ - lift) * (f_ - lift);
      if (e_ == 0.0) return q;
      const double rho = e_ + std::sqrt(maxd(q, 0.0));
      return rho * rho;
    }
    const double rho = rho_b_ + (lift - h_b_) / k2_;  // on the taper
    return rho * rho;
  }

  // Distance from the axis of the point touching a plane whose unit normal has horizontal length nxy and
  // vertical component nz > 0 (the plane's slope is atan(nxy / nz)): where h' equals that slope.
  double facet_contact_radius(double nxy, double nz) const {
    if (nxy * k1_den_ <= k1_num_ * nz) return 0.0;           // no steeper than the bottom cone: the tip
    if (arc_ends_vertical_ || nxy * k2_den_ <= k2_num_ * nz)  // on the arc: rho = e + r sin(slope)
      return mind(e_ + r_ * nxy, rho_b_);
    return rho_max_;                                          // steeper than the taper: its top edge
  }

 private:
  Cutter() = default;
  void finish();

  double R_ = 0, r_ = 0, Lc_ = 0, beta1_ = 0, beta2_ = 0;
  double e_ = 0, f_ = 0;             // corner arc centre
  double k1_ = 0, k2_ = 0;           // slopes of the bottom cone and the taper (k2 = cot beta2)
  double k1_num_ = 0, k1_den_ = 1;   // tan(beta1) = sin / cos, compared without division
  double k2_num_ = 1, k2_den_ = 0;   // cot(beta2) = cos / sin
  double rho_a_ = 0, rho_b_ = 0, h_b_ = 0, rho_max_ = 0, h_max_ = 0;
  bool arc_ends_vertical_ = true;
  CutterKind kind_ = CutterKind::General;
};

}  // namespace tmm
