#include "tmm/util/range.hpp"

#include <sstream>
#include <stdexcept>

namespace tmm {

namespace {

constexpr const char* kRange = "is outside the kernel's range: values must be finite with |value| < ";

}  // namespace

std::string out_of_range_text() {
  std::ostringstream msg;
  msg << kRange << kMaxCoordinate << " mm";
  return msg.str();
}

void require_in_range(double v, const std::string& what) {
  if (in_range(v)) return;
  std::ostringstream msg;
  msg << what << " = " << v << " " << kRange << kMaxCoordinate << " mm";
  throw std::invalid_argument(msg.str());
}

void require_length(double v, const std::string& what) {
  if (v >= 0.0 && v < kMaxCoordinate) return;
  std::ostringstream msg;
  msg << what << " = " << v << " is outside the kernel's range: lengths must be in [0, " << kMaxCoordinate
      << ") mm";
  throw std::invalid_argument(msg.str());
}

void require_rows_in_range(const double* p, std::size_t rows, std::size_t cols, const std::string& what) {
  for (std::size_t r = 0; r < rows; ++r) {
    const double* row = p + r * cols;
    for (std::size_t c = 0; c < cols; ++c) {
      if (in_range(row[c])) continue;
      std::ostringstream msg;
      msg << what << " row " << r << " (";
      for (std::size_t k = 0; k < cols; ++k) msg << (k ? ", " : "") << row[k];
      msg << ") " << kRange << kMaxCoordinate << " mm";
      throw std::invalid_argument(msg.str());
    }
  }
}

}  // namespace tmm
