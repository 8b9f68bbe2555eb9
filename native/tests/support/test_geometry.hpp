// Small geometric predicates the kernel tests' independent references share.
#pragma once

#include <Eigen/Core>

namespace tmm_test {

// Whether (x, y) lies in the XY projection of the triangle a b c (either winding, edges included).
inline bool inside_xy(double x, double y, const Eigen::Vector3d& a, const Eigen::Vector3d& b,
                      const Eigen::Vector3d& c) {
  auto cross = [](double ux, double uy, double vx, double vy) { return ux * vy - uy * vx; };
  const double w0 = cross(b.x() - x, b.y() - y, c.x() - x, c.y() - y);
  const double w1 = cross(c.x() - x, c.y() - y, a.x() - x, a.y() - y);
  const double w2 = cross(a.x() - x, a.y() - y, b.x() - x, b.y() - y);
  return (w0 >= 0 && w1 >= 0 && w2 >= 0) || (w0 <= 0 && w1 <= 0 && w2 <= 0);
}

}  // namespace tmm_test
