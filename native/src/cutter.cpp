#include "tmm/cutter.hpp"

#include <sstream>
#include <stdexcept>

namespace tmm {

Cutter::Cutter(double radius, double corner_radius) : R_(radius), r_(corner_radius) {
  if (!(std::isfinite(radius) && radius > 0.0)) {
    std::ostringstream msg;
    msg << "cutter radius must be positive and finite, got " << radius;
    throw std::invalid_argument(msg.str());
  }
  if (!(std::isfinite(corner_radius) && corner_radius >= 0.0)) {
    std::ostringstream msg;
    msg << "cutter corner radius must be zero or positive, got " << corner_radius;
    throw std::invalid_argument(msg.str());
  }
  if (corner_radius > radius * (1.0 + 1e-12)) {
    std::ostringstream msg;
    msg << "cutter corner radius " << corner_radius << " is larger than the cutter radius " << radius;
    throw std::invalid_argument(msg.str());
  }
  if (r_ > R_) r_ = R_;
  a_ = R_ - r_;
  if (r_ == 0.0) {
    kind_ = CutterKind::Flat;
  } else if (a_ <= 1e-12 * R_) {
    kind_ = CutterKind::Ball;
    a_ = 0.0;
  } else {
    kind_ = CutterKind::Bull;
  }
}

}  // namespace tmm
