// Small meshes the kernel tests share.
#pragma once

#include <Eigen/Core>

#include <cmath>
#include <cstddef>
#include <cstring>
#include <random>
#include <utility>
#include <vector>

#include "tmm/mesh/mesh_index.hpp"

namespace tmm_test {

// Field by field: an IndexedTriangle's padding after its edge bits is never written, so bytes may differ.
inline bool same_triangles(const std::vector<tmm::IndexedTriangle>& a, const std::vector<tmm::IndexedTriangle>& b) {
  if (a.size() != b.size()) return false;
  constexpr std::size_t kValues = offsetof(tmm::IndexedTriangle, owned_edges);  // the doubles before the bits
  for (std::size_t i = 0; i < a.size(); ++i) {
    if (std::memcmp(&a[i], &b[i], kValues) != 0 || a[i].owned_edges != b[i].owned_edges) return false;
  }
  return true;
}

// The index over the single triangle a b c.
inline tmm::MeshIndex one_triangle(const Eigen::Vector3d& a, const Eigen::Vector3d& b, const Eigen::Vector3d& c) {
  tmm::Vertices V(3, 3);
  V.row(0) = a.transpose();
  V.row(1) = b.transpose();
  V.row(2) = c.transpose();
  tmm::Triangles F(1, 3);
  F << 0, 1, 2;
  return tmm::MeshIndex(V, F);
}

// A bumpy random mesh: n x n unit cells, vertices jittered by up to 0.3 in X, Y and Z over the wave
// z = 3 sin(x / wx) cos(y / wy).
inline std::pair<tmm::Vertices, tmm::Triangles> bumpy_grid(int n, double wx, double wy, std::mt19937_64& rng) {
  tmm::Vertices V((n + 1) * (n + 1), 3);
  std::uniform_real_distribution<double> jitter(-0.3, 0.3);
  for (int i = 0; i <= n; ++i)
    for (int j = 0; j <= n; ++j) {
      const double x = i + jitter(rng), y = j + jitter(rng);
      V.row(i * (n + 1) + j) << x, y, 3 * std::sin(x / wx) * std::cos(y / wy) + jitter(rng);
    }
  tmm::Triangles F(2 * n * n, 3);
  int t = 0;
  for (int i = 0; i < n; ++i)
    for (int j = 0; j < n; ++j) {
      const int v = i * (n + 1) + j;
      F.row(t++) << v, v + n + 1, v + 1;
      F.row(t++) << v + 1, v + n + 1, v + n + 2;
    }
  return {V, F};
}

// A grid mesh of z(x, y) over [x0, x1] x [y0, y1], nx x ny cells, two triangles each.
template <class F>
tmm::MeshIndex grid_mesh(F z, double x0, double y0, double x1, double y1, int nx, int ny) {
  tmm::Vertices V((nx + 1) * (ny + 1), 3);
  for (int j = 0; j <= ny; ++j)
    for (int i = 0; i <= nx; ++i) {
      const double x = x0 + (x1 - x0) * i / nx, y = y0 + (y1 - y0) * j / ny;
      V.row(j * (nx + 1) + i) << x, y, z(x, y);
    }
  tmm::Triangles T(2 * nx * ny, 3);
  for (int j = 0; j < ny; ++j)
    for (int i = 0; i < nx; ++i) {
      const int a = j * (nx + 1) + i, b = a + 1, c = a + nx + 1, d = c + 1;
      T.row(2 * (j * nx + i)) << a, b, d;
      T.row(2 * (j * nx + i) + 1) << a, d, c;
    }
  return tmm::MeshIndex(V, T);
}

}  // namespace tmm_test
