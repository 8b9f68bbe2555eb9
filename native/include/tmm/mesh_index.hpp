// A bounding volume hierarchy over the XY bounds of a mesh's triangles, each node carrying the highest Z
// below it. A drop-cutter query visits nodes under the cutter's shadow in order of decreasing height and
// skips every node no higher than the best contact found so far: the tip of a cutter touching a triangle
// is never above the triangle's highest point, so such nodes cannot raise the cutter.
#pragma once

#include <cstdint>
#include <vector>

#include <Eigen/Core>

#include "tmm/mesh.hpp"

namespace tmm {

// A triangle with what every query needs, stored in leaf order for locality.
struct IndexedTriangle {
  double p[3][3];   // corners
  double n[3];      // unit normal (0 if degenerate)
  double zmax;      // highest corner
};

struct BvhNode {
  double xmin, ymin, xmax, ymax;  // XY bounds of the triangles below
  double zmax;                    // highest point below
  int32_t first;                  // leaf: first triangle; inner: index of the left child (right = first + 1)
  int32_t count;                  // leaf: number of triangles; inner: 0
};

class MeshIndex {
 public:
  // Throws std::invalid_argument on out-of-range indices, non-finite coordinates or an empty mesh.
  MeshIndex(const Eigen::Ref<const Vertices>& V, const Eigen::Ref<const Triangles>& F);

  std::size_t triangle_count() const { return tris_.size(); }
  const std::vector<IndexedTriangle>& triangles() const { return tris_; }
  const std::vector<BvhNode>& nodes() const { return nodes_; }
  std::size_t memory_bytes() const {
    return tris_.capacity() * sizeof(IndexedTriangle) + nodes_.capacity() * sizeof(BvhNode);
  }
  double zmin() const { return zmin_; }
  double zmax() const { return nodes_.empty() ? zmin_ : nodes_[0].zmax; }

  // Calls visit(triangle) for every triangle whose XY bounds come within `radius` of (x, y) and whose
  // zmax exceeds `floor` at the time it is reached; `floor` may rise during the walk (visit raises it).
  template <class Visit>
  void walk(double x, double y, double radius, const double& floor, Visit&& visit) const;

 private:
  void build(int32_t self, int32_t begin, int32_t end, std::vector<int32_t>& order,
             const std::vector<double>& cx, const std::vector<double>& cy,
             const std::vector<IndexedTriangle>& src);

  std::vector<IndexedTriangle> tris_;
  std::vector<BvhNode> nodes_;
  double zmin_ = 0.0;
};

template <class Visit>
void MeshIndex::walk(double x, double y, double radius, const double& floor, Visit&& visit) const {
  const double r2 = radius * radius;
  int32_t stack[128];
  int top = 0;
  stack[top++] = 0;
  while (top > 0) {
    const BvhNode& node = nodes_[stack[--top]];
    if (node.zmax <= floor) continue;
    const double dx = std::fmax(std::fmax(node.xmin - x, x - node.xmax), 0.0);
    const double dy = std::fmax(std::fmax(node.ymin - y, y - node.ymax), 0.0);
    if (dx * dx + dy * dy > r2) continue;
    if (node.count > 0) {
      for (int32_t i = node.first, e = node.first + node.count; i < e; ++i) {
        if (tris_[i].zmax > floor) visit(tris_[i]);
      }
    } else {
      const int32_t l = node.first, r = node.first + 1;
      // Higher child last so it is popped first: its contacts prune more of the other.
      if (nodes_[l].zmax > nodes_[r].zmax) {
        stack[top++] = r;
        stack[top++] = l;
      } else {
        stack[top++] = l;
        stack[top++] = r;
      }
    }
  }
}

}  // namespace tmm
