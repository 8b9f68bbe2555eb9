// Small meshes the kernel tests share.
#pragma once

#include <Eigen/Core>

#include "tmm/mesh/mesh_index.hpp"

namespace tmm_test {

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
