// Constants the whole kernel shares.
#pragma once

#include <limits>

namespace tmm {

constexpr double kInf = std::numeric_limits<double>::infinity();
constexpr double kPi = 3.14159265358979323846;

// mm: every coordinate, height and length the kernel takes (meshes, nets, query points, floors, tool
// positions, tool radii) is finite with |value| < kMaxCoordinate (tmm/util/range.hpp checks it at the entry
// points). Squares of differences (1e18) and the sweep's quartic terms (1e36) stay far from overflow, and a
// double still resolves 1.2e-7 mm at 1e9 mm.
constexpr double kMaxCoordinate = 1e9;

}  // namespace tmm
