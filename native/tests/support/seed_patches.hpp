// The three bicubic Bezier patches of seed 001 (001_b332d458e7afeb48.txt, section 5.1, Table 1):
// P[i][j] = (50 i, 50 j, z_ij), row order P00 P01 .. P33. The shared seed_surfaces.json holds the convex
// and concave ones only, so the saddle is written out here (and all three, for one source in the tests).
#pragma once

#include <Eigen/Core>

#include <algorithm>
#include <cmath>
#include <memory>
#include <string>
#include <vector>

#include "tmm/surface/bezier.hpp"

namespace tmm_test {

inline std::shared_ptr<tmm::PatchSurface> seed_patch(const std::string& kind) {
  static const double convex[16] = {80, 90, 90, 80, 90, 105, 105, 90, 90, 105, 105, 90, 80, 90, 90, 80};
  static const double concave[16] = {80, 70, 70, 80, 70, 55, 55, 70, 70, 55, 55, 70, 80, 70, 70, 80};
  static const double saddle[16] = {80, 65, 90, 85, 80, 85, 90, 95, 100, 105, 95, 100, 90, 100, 100, 85};
  const double* z = kind == "convex" ? convex : kind == "concave" ? concave : saddle;
  std::vector<Eigen::Vector3d> net;
  for (int i = 0; i < 4; ++i)
    for (int j = 0; j < 4; ++j) net.emplace_back(50.0 * i, 50.0 * j, z[i * 4 + j]);
  return std::make_shared<tmm::PatchSurface>(tmm::BezierPatch(3, 3, net));
}

// Explicit bicubic Bernstein sum at (u, v) (independent of BezierPatch's evaluation).
inline Eigen::Vector3d bernstein_point(const tmm::BezierPatch& b, double u, double v) {
  const double bu[4] = {std::pow(1 - u, 3), 3 * u * (1 - u) * (1 - u), 3 * u * u * (1 - u), u * u * u};
  const double bv[4] = {std::pow(1 - v, 3), 3 * v * (1 - v) * (1 - v), 3 * v * v * (1 - v), v * v * v};
  Eigen::Vector3d s = Eigen::Vector3d::Zero();
  for (int i = 0; i < 4; ++i)
    for (int j = 0; j < 4; ++j) s += bu[i] * bv[j] * b.pole(i, j);
  return s;
}

// Signed distance to the round-insert tool (Ro, Ri) at (tip, axis) from the torus' definition: distance to
// the major circle minus Ri, and the body above the centre plane out to Ro + Ri (independent of
// tmm::tool_distance).
inline double round_insert_distance(double Ro, double Ri, const Eigen::Vector3d& tip, const Eigen::Vector3d& axis,
                                    const Eigen::Vector3d& x) {
  const Eigen::Vector3d d = x - (tip + Ri * axis);
  const double h = d.dot(axis);
  const double rho = (d - h * axis).norm();
  const double torus = std::sqrt((rho - Ro) * (rho - Ro) + h * h) - Ri;
  if (h >= 0 && rho <= Ro + Ri) return std::min(torus, -std::min(h, Ro + Ri - rho));
  return torus;
}

}  // namespace tmm_test
