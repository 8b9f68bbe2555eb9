// The walk of the rotated index for a convex solid moving along -Z' (drop_direction.hpp's mesh query), shared by
// the cutter solid (AlongCutter) and a whole grown tool body (drop_assembly_direction.cpp); its bounds:
// direction_detail::UnderBounds.
#pragma once

#include <algorithm>
#include <cmath>
#include <limits>
#include <vector>

#include "tmm/mesh/mesh_index.hpp"

namespace tmm::direction_detail {

// Best-first walk of the index's hierarchy for a solid whose lowest point is `floor` high at best: visits the
// triangles whose XY' bounds come within `radius` of (x, y) and whose highest point, lowered by
// rise(d, x0, x1, y0, y1, enough) (d: the box's XY' distance from (x, y), [x0, x1] x [y0, y1] the box less
// (x, y); it may stop at `enough`, which prunes the box), is above `floor`; `floor` may rise during the walk.
// Written over nodes() and triangles() rather than MeshIndex::walk, whose pruning is tied to the -Z profile.
template <class Rise, class Visit>
void walk_lowest(const MeshIndex& mi, double x, double y, double radius, const double& floor, Rise&& rise,
                 Visit&& visit) {
  constexpr double kInf = std::numeric_limits<double>::infinity();
  const auto& nodes = mi.nodes();
  const auto& tris = mi.triangles();
  const double r2 = radius * radius;
  auto bound = [&](double xmin, double ymin, double xmax, double ymax, double zmax) {
    const double dx = std::max(std::max(xmin - x, x - xmax), 0.0);
    const double dy = std::max(std::max(ymin - y, y - ymax), 0.0);
    const double d2 = dx * dx + dy * dy;
    if (d2 > r2 || zmax <= floor) return -kInf;
    return zmax - rise(std::sqrt(d2), xmin - x, xmax - x, ymin - y, ymax - y, zmax - floor);
  };
  struct Entry {
    int32_t node;
    double bound;
  };
  std::vector<Entry> stack;  // depth-first: at most ~2 entries per level
  stack.reserve(128);
  stack.push_back({0, kInf});
  while (!stack.empty()) {
    const Entry e = stack.back();
    stack.pop_back();
    if (e.bound <= floor) continue;
    const BvhNode& node = nodes[e.node];
    if (node.count > 0) {
      for (int32_t i = node.first, end = node.first + node.count; i < end; ++i) {
        const IndexedTriangle& t = tris[i];
        if (t.zmax <= floor) continue;
        const double b = bound(std::min({t.p[0][0], t.p[1][0], t.p[2][0]}), std::min({t.p[0][1], t.p[1][1], t.p[2][1]}),
                               std::max({t.p[0][0], t.p[1][0], t.p[2][0]}), std::max({t.p[0][1], t.p[1][1], t.p[2][1]}),
                               t.zmax);
        if (b > floor) visit(t, i);
      }
    } else {
      const BvhNode& l = nodes[node.first];
      const BvhNode& r = nodes[node.first + 1];
      const double bl = bound(l.xmin, l.ymin, l.xmax, l.ymax, l.zmax);
      const double br = bound(r.xmin, r.ymin, r.xmax, r.ymax, r.zmax);
      // The more promising child last, so it is popped first: its contacts prune more of the other.
      if (bl > br) {
        if (br > floor) stack.push_back({node.first + 1, br});
        if (bl > floor) stack.push_back({node.first, bl});
      } else {
        if (bl > floor) stack.push_back({node.first, bl});
        if (br > floor) stack.push_back({node.first + 1, br});
      }
    }
  }
}

}  // namespace tmm::direction_detail
