// The kernel's range of coordinates (kMaxCoordinate, tmm/util/constants.hpp), checked where input enters:
// a value outside it is refused with a message naming the argument, its value and the range, instead of
// overflowing later into wrong heights, NaN normals, out-of-range casts or unbounded work.
#pragma once

#include <cmath>
#include <cstddef>
#include <string>

#include "tmm/util/constants.hpp"

namespace tmm {

// Finite and |v| < kMaxCoordinate (false for NaN).
inline bool in_range(double v) { return std::fabs(v) < kMaxCoordinate; }

// "is outside the kernel's range: values must be finite with |value| < 1e+09 mm", for messages.
std::string out_of_range_text();

// Throws std::invalid_argument "<what> = <v> is outside the kernel's range: ... |value| < 1e+09 mm" unless
// in_range(v).
void require_in_range(double v, const std::string& what);

// A length that must also be >= 0 (radii, cutting lengths): in [0, kMaxCoordinate), named in the message.
void require_length(double v, const std::string& what);

// rows x cols values, row-major (points): the first one out of range is refused naming `what`, its row and
// the row's values.
void require_rows_in_range(const double* p, std::size_t rows, std::size_t cols, const std::string& what);

}  // namespace tmm
