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

}  // namespace tmm_test
