// Constants the whole kernel shares.
#pragma once

#include <limits>

namespace tmm {

constexpr double kInf = std::numeric_limits<double>::infinity();
constexpr double kPi = 3.14159265358979323846;

}  // namespace tmm
