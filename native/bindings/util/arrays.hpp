// Checked conversions of numpy arrays the kernel takes, done before any cast so that nothing is wrapped or
// truncated silently.
#pragma once

#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>

#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <limits>
#include <sstream>
#include <stdexcept>
#include <string>
#include <type_traits>
#include <vector>

#include "tmm/mesh/mesh.hpp"
#include "tmm/util/range.hpp"

namespace tmm_bindings {

using Arr = pybind11::array_t<double, pybind11::array::c_style | pybind11::array::forcecast>;

// a, checked to have shape (n, cols).
template <class A>
const A& check_points(const A& a, pybind11::ssize_t cols, const char* what) {
  if (a.ndim() != 2 || a.shape(1) != cols) {
    std::ostringstream msg;
    msg << what << " must have shape (n, " << cols << "), got ";
    if (a.ndim() == 2) {
      msg << "(" << a.shape(0) << ", " << a.shape(1) << ")";
    } else {
      msg << "ndim " << a.ndim();
    }
    throw std::invalid_argument(msg.str());
  }
  return a;
}

// Every value of a checked (n, cols) array within the kernel's range (tmm/util/range.hpp), refused naming
// `what`, the row and its values.
template <class A>
void check_range(const A& a, const char* what) {
  const auto cols = a.ndim() == 2 ? static_cast<std::size_t>(a.shape(1)) : std::size_t{1};
  tmm::require_rows_in_range(a.data(), static_cast<std::size_t>(a.size()) / std::max<std::size_t>(cols, 1), cols,
                             what);
}

// A new (n, 3) float64 array.
inline pybind11::array_t<double> rows3(std::size_t n) {
  return pybind11::array_t<double>({static_cast<pybind11::ssize_t>(n), pybind11::ssize_t{3}});
}

// An (m, 3) integer array of vertex indices (any integer dtype) as the kernel's int32 triangles. A value
// outside int32 is refused (ValueError naming the triangle, the value and the range) before the cast that
// would wrap it; the kernel refuses negative indices and indices beyond the vertices itself. Non-integer
// arrays are refused (TypeError).
inline tmm::Triangles triangles_from(const pybind11::handle& obj) {
  namespace py = pybind11;
  const py::array a = py::array::ensure(obj);
  if (!a) throw py::type_error("triangles must be an (m, 3) array of integer vertex indices");
  const char kind = a.dtype().kind();
  if (kind != 'i' && kind != 'u')
    throw py::type_error("triangles must be an integer array (vertex indices), got dtype " +
                         std::string(py::str(a.dtype())));
  if (a.ndim() != 2 || a.shape(1) != 3) {
    std::ostringstream msg;
    msg << "triangles must have shape (m, 3), got ndim " << a.ndim();
    if (a.ndim() == 2) msg << " and " << a.shape(1) << " columns";
    throw std::invalid_argument(msg.str());
  }
  tmm::Triangles F(a.shape(0), 3);
  if (kind == 'i' && a.itemsize() == sizeof(std::int32_t)) {  // every value fits: one copy, no checks (the
    // widening copy below takes a noticeable pause before a big mesh's kernel call can report progress)
    const py::array_t<std::int32_t, py::array::c_style | py::array::forcecast> typed(a);
    std::copy_n(typed.data(), F.size(), F.data());
    return F;
  }
  auto fill = [&](auto typed) {
    using T = typename decltype(typed)::value_type;
    constexpr T lo = std::numeric_limits<T>::min() < 0 ? static_cast<T>(std::numeric_limits<std::int32_t>::min()) : T{0};
    constexpr T hi = static_cast<T>(std::numeric_limits<std::int32_t>::max());
    const auto r = typed.template unchecked<2>();
    for (py::ssize_t t = 0; t < r.shape(0); ++t) {
      for (py::ssize_t k = 0; k < 3; ++k) {
        const T v = r(t, k);
        if (v < lo || v > hi) {
          std::ostringstream msg;
          msg << "triangle " << t << " refers to vertex " << v << ", which does not fit a 32-bit index: vertex "
              << "indices must be in [0, " << std::numeric_limits<std::int32_t>::max() << "]";
          throw std::invalid_argument(msg.str());
        }
        F(t, k) = static_cast<std::int32_t>(v);
      }
    }
  };
  if (kind == 'u') fill(py::array_t<std::uint64_t, py::array::forcecast>(a));
  else fill(py::array_t<std::int64_t, py::array::forcecast>(a));
  return F;
}

// A 1-d numpy array holding a copy of v (kernel results).
template <class T>
pybind11::array_t<T> to_array(const std::vector<T>& v) {
  pybind11::array_t<T> a(static_cast<pybind11::ssize_t>(v.size()));
  std::copy(v.begin(), v.end(), a.mutable_data());
  return a;
}

}  // namespace tmm_bindings
