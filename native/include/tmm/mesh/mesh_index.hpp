// A bounding volume hierarchy over the XY bounds of a mesh's triangles, each node carrying the highest Z
// below it. A drop-cutter query visits nodes under the cutter's shadow in order of decreasing height and
// skips every node no higher than the best contact found so far: the tip of a cutter touching a triangle
// is never above the triangle's highest point, so such nodes cannot raise the cutter.
#pragma once

#include <atomic>
#include <cmath>
#include <cstdint>
#include <functional>
#include <limits>
#include <type_traits>
#include <vector>

#include <Eigen/Core>

#include "tmm/cutter/cutter.hpp"
#include "tmm/mesh/mesh.hpp"

namespace tmm {

// A triangle with what every query needs, stored in leaf order for locality.
struct IndexedTriangle {
  double p[3][3];                 // corners
  double n[3];                    // unit normal (0 if degenerate)
  double zmax;                    // highest corner
  double xmin, ymin, xmax, ymax;  // XY bounds
  // Bit k set: this triangle solves edge k (corner k to k + 1). An edge shared by several triangles is
  // solved by the lowest-numbered one only. Skipping it in the others is safe under pruning: every
  // triangle holding the edge bounds it (the edge lies in its box and below its zmax), so when the owner
  // is pruned the edge cannot raise the cutter either.
  uint8_t owned_edges;
};

struct BvhNode {
  double xmin, ymin, xmax, ymax;  // XY bounds of the triangles below
  double zmax;                    // highest point below
  int32_t first;                  // leaf: first triangle; inner: index of the left child (right = first + 1)
  int32_t count;                  // leaf: number of triangles; inner: 0
};

class MeshIndex {
 public:
  // threads: at most this many threads build the tree (0: default_threads(); subtrees of more than
  // kParallelBuild triangles are split between threads, so small meshes build on one). The tree does not
  // depend on it. Throws std::invalid_argument on out-of-range indices, non-finite coordinates, an empty
  // mesh or threads < 0. progress(fraction) is called now and then from the calling thread
  // (tmm::SerialProgress: every 20 ms, and 1.0 at the end); false cancels: throws tmm::Cancelled (a mesh of
  // ten million triangles takes seconds).
  MeshIndex(const Eigen::Ref<const Vertices>& V, const Eigen::Ref<const Triangles>& F, int threads = 0,
            const std::function<bool(double)>& progress = {});
  static constexpr int32_t kParallelBuild = 100000;
  // The number of threads the build ran on.
  int build_threads() const { return build_threads_; }

  std::size_t triangle_count() const { return tris_.size(); }
  const std::vector<IndexedTriangle>& triangles() const { return tris_; }
  const std::vector<BvhNode>& nodes() const { return nodes_; }
  std::size_t memory_bytes() const {
    return tris_.capacity() * sizeof(IndexedTriangle) + nodes_.capacity() * sizeof(BvhNode);
  }
  double zmin() const { return zmin_; }
  double zmax() const { return nodes_.empty() ? zmin_ : nodes_[0].zmax; }

  // Visits, best-first, the triangles whose XY bounds come within the cutter's radius of (x, y) and could hold the
  // cutter above `floor`; `floor` may rise during the walk (visit raises it). A box at XY distance d whose
  // highest point is zmax can only hold the tip above floor if h(d) < zmax - floor, i.e.
  // d^2 < reach2(zmax - floor) (see Cutter::reach2): every point of it is at least d from the axis and h
  // increases. visit(triangle, position) gets the triangle's position in triangles().
  template <class Visit>
  void walk(double x, double y, const Cutter& cutter, const double& floor, Visit&& visit) const;

  // Visits the triangles whose XY bounds come within `radius` of the rectangle [x0, x1] x [y0, y1] and whose
  // highest point is above `floor`: every triangle a cutter of that radius centred in the rectangle can
  // rest on. visit(triangle, position) as for walk; a visit returning bool stops the walk with false.
  template <class Visit>
  void near_rect(double x0, double y0, double x1, double y1, double radius, double floor, Visit&& visit) const;

 private:
  struct BuildState;  // what the build's threads share (mesh_index.cpp)
  void build(int32_t self, int32_t below, int32_t begin, int32_t end, int threads, BuildState& state, bool reports);
  static int32_t descendants(int32_t triangles);

  std::vector<IndexedTriangle> tris_;
  std::vector<BvhNode> nodes_;
  double zmin_ = 0.0;
  int build_threads_ = 1;
};

template <class Visit>
void MeshIndex::walk(double x, double y, const Cutter& cutter, const double& floor, Visit&& visit) const {
  const double r2 = cutter.max_radius() * cutter.max_radius();
  auto may_hold = [&](double xmin, double ymin, double xmax, double ymax, double zmax) {
    const double dx = maxd(maxd(xmin - x, x - xmax), 0.0);
    const double dy = maxd(maxd(ymin - y, y - ymax), 0.0);
    const double d2 = dx * dx + dy * dy;
    return d2 <= r2 && d2 < cutter.reach2(zmax - floor);
  };
  int32_t stack[128];
  int top = 0;
  stack[top++] = 0;
  while (top > 0) {
    const BvhNode& node = nodes_[stack[--top]];
    if (!may_hold(node.xmin, node.ymin, node.xmax, node.ymax, node.zmax)) continue;
    if (node.count > 0) {
      for (int32_t i = node.first, end = node.first + node.count; i < end; ++i) {
        const IndexedTriangle& t = tris_[i];
        if (may_hold(t.xmin, t.ymin, t.xmax, t.ymax, t.zmax)) visit(t, i);
      }
    } else {
      // The higher child last, so it is popped first: its contacts prune more of the other.
      const int32_t l = node.first, r = node.first + 1;
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

template <class Visit>
void MeshIndex::near_rect(double x0, double y0, double x1, double y1, double radius, double floor,
                          Visit&& visit) const {
  const double r2 = radius * radius;
  auto near = [&](double xmin, double ymin, double xmax, double ymax, double zmax) {
    const double dx = maxd(maxd(xmin - x1, x0 - xmax), 0.0);
    const double dy = maxd(maxd(ymin - y1, y0 - ymax), 0.0);
    return dx * dx + dy * dy <= r2 && zmax > floor;
  };
  int32_t stack[128];
  int top = 0;
  stack[top++] = 0;
  while (top > 0) {
    const BvhNode& node = nodes_[stack[--top]];
    if (!near(node.xmin, node.ymin, node.xmax, node.ymax, node.zmax)) continue;
    if (node.count > 0) {
      for (int32_t i = node.first, end = node.first + node.count; i < end; ++i) {
        const IndexedTriangle& t = tris_[i];
        if (!near(t.xmin, t.ymin, t.xmax, t.ymax, t.zmax)) continue;
        if constexpr (std::is_same_v<decltype(visit(t, i)), bool>) {
          if (!visit(t, i)) return;  // the visitor has seen enough
        } else {
          visit(t, i);
        }
      }
    } else {
      stack[top++] = node.first + 1;
      stack[top++] = node.first;
    }
  }
}

}  // namespace tmm
