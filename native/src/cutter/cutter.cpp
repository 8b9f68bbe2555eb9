#include "tmm/cutter/cutter.hpp"

#include <limits>
#include <sstream>
#include <stdexcept>

#include "tmm/util/range.hpp"

namespace tmm {

namespace {

[[noreturn]] void fail(const std::string& what, double value) {
  std::ostringstream msg;
  msg << what << ", got " << value;
  throw std::invalid_argument(msg.str());
}

}  // namespace

Cutter::Cutter(double radius, double corner_radius) {
  if (!(std::isfinite(radius) && radius > 0.0)) fail("cutter radius must be positive and finite", radius);
  if (!(std::isfinite(corner_radius) && corner_radius >= 0.0))
    fail("cutter corner radius must be zero or positive", corner_radius);
  require_length(radius, "cutter radius");
  if (corner_radius > radius * (1.0 + 1e-12)) {
    std::ostringstream msg;
    msg << "cutter corner radius " << corner_radius << " is larger than the cutter radius " << radius;
    throw std::invalid_argument(msg.str());
  }
  R_ = radius;
  r_ = std::fmin(corner_radius, radius);
  Lc_ = std::numeric_limits<double>::infinity();
  e_ = R_ - r_;
  f_ = r_;
  finish();
}

Cutter Cutter::apt(double radius, double corner_radius, double cutting_length, double beta1, double beta2) {
  if (!(std::isfinite(radius) && radius > 0.0)) fail("cutter radius must be positive and finite", radius);
  if (!(std::isfinite(corner_radius) && corner_radius >= 0.0))
    fail("cutter corner radius must be zero or positive", corner_radius);
  if (!(cutting_length > 0.0)) fail("cutting-edge height must be positive", cutting_length);
  require_length(radius, "cutter radius");
  if (std::isfinite(cutting_length)) require_length(cutting_length, "cutting-edge height");
  if (!(std::isfinite(beta1) && beta1 >= 0.0 && beta1 < M_PI / 2))
    fail("bottom angle beta1 must be in [0, 90) degrees", beta1 * 180 / M_PI);
  if (!(std::isfinite(beta2) && std::fabs(beta2) < M_PI / 2))
    fail("taper angle beta2 must be in (-90, 90) degrees", beta2 * 180 / M_PI);
  Cutter c;
  c.R_ = radius;
  c.r_ = corner_radius;
  c.Lc_ = cutting_length;
  c.beta1_ = beta1;
  c.beta2_ = beta2;
  const double t1 = std::tan(beta1), t2 = std::tan(beta2);
  if (std::isfinite(cutting_length)) {
    // Sharp corner (d/2, d/2 tan beta1) where the bottom line meets the side through (R, L_C): eq. 3.35.
    double half_d = (radius - cutting_length * t2) / (1.0 - t1 * t2);
    // 0 is a sharp point on the axis (a V-bit); below 0 the side would cross the axis.
    if (!(half_d >= -1e-12 * radius)) fail("the side and the bottom do not meet outside the axis: radius at the corner", half_d);
    half_d = std::fmax(half_d, 0.0);
    // Corner arc centre: r inside both lines. Bottom: X . (-sin b1, cos b1) = r;
    // side through the corner C: X . (-cos b2, sin b2) = C . (-cos b2, sin b2) + r.
    const double cx = half_d, cz = half_d * t1;
    const double a11 = -std::sin(beta1), a12 = std::cos(beta1), b1 = corner_radius;
    const double a21 = -std::cos(beta2), a22 = std::sin(beta2), b2 = cx * a21 + cz * a22 + corner_radius;
    const double det = a11 * a22 - a12 * a21;  // = cos(beta1 + beta2) > 0 for a convex corner
    if (!(det > 1e-12)) fail("bottom and taper angles leave no convex corner: beta1 + beta2 (deg)",
                             (beta1 + beta2) * 180 / M_PI);
    c.e_ = (b1 * a22 - a12 * b2) / det;
    c.f_ = (a11 * b2 - b1 * a21) / det;
  } else {
    if (beta2 != 0.0) fail("an endless cutting edge needs a zero taper angle (deg)", beta2 * 180 / M_PI);
    c.e_ = radius - corner_radius;
    c.f_ = corner_radius + (radius - corner_radius) * t1;  // not reached for beta1 != 0 without L_C
  }
  if (c.e_ < -1e-12 * radius) fail("corner radius too large for these angles: arc centre radius", c.e_);
  c.e_ = std::fmax(c.e_, 0.0);
  c.finish();
  if (std::isfinite(cutting_length) && c.h_b_ > cutting_length * (1 + 1e-12))
    fail("cutting-edge height is below the top of the corner arc", cutting_length);
  return c;
}

void Cutter::finish() {
  k1_num_ = std::sin(beta1_);
  k1_den_ = std::cos(beta1_);
  k1_ = k1_num_ / k1_den_;
  rho_a_ = e_ + r_ * std::sin(beta1_);  // tangent point of the arc with the bottom
  arc_ends_vertical_ = beta2_ <= 0.0;
  if (arc_ends_vertical_) {
    rho_b_ = e_ + r_;                    // the arc's widest point ends the lower profile
    k2_num_ = 1.0;
    k2_den_ = 0.0;
    k2_ = std::numeric_limits<double>::infinity();
  } else {
    rho_b_ = e_ + r_ * std::cos(beta2_);  // tangent point of the arc with the taper side
    k2_num_ = std::cos(beta2_);
    k2_den_ = std::sin(beta2_);
    k2_ = k2_num_ / k2_den_;
  }
  h_b_ = f_ - r_ * (arc_ends_vertical_ ? 0.0 : std::sin(beta2_));
  rho_max_ = arc_ends_vertical_ ? rho_b_ : R_;
  h_max_ = height(rho_max_);
  const bool plain = beta1_ == 0.0 && beta2_ == 0.0;
  if (!plain) {
    kind_ = CutterKind::General;
  } else if (r_ == 0.0) {
    kind_ = CutterKind::Flat;
  } else if (e_ <= 1e-12 * R_) {
    kind_ = CutterKind::Ball;
    e_ = 0.0;
  } else {
    kind_ = CutterKind::Bull;
  }
}

}  // namespace tmm
