#include "tmm/mesh_index.hpp"

#include <Eigen/Geometry>

#include <algorithm>
#include <cmath>
#include <sstream>
#include <stdexcept>

namespace tmm {

namespace {

constexpr int32_t kLeafSize = 8;

// Sets IndexedTriangle::owned_edges: edge (a, b) of triangle t is owned by t unless a lower-numbered
// triangle also has both a and b. Triangles around each vertex in compressed rows: O(m * valence).
void mark_owned_edges(const Eigen::Ref<const Triangles>& F, Eigen::Index nv, std::vector<IndexedTriangle>& tris) {
  const Eigen::Index nt = F.rows();
  std::vector<int32_t> start(static_cast<std::size_t>(nv) + 1, 0);
  for (Eigen::Index t = 0; t < nt; ++t)
    for (int k = 0; k < 3; ++k) ++start[F(t, k) + 1];
  for (Eigen::Index v = 0; v < nv; ++v) start[v + 1] += start[v];
  std::vector<int32_t> fill(start.begin(), start.end() - 1), around(static_cast<std::size_t>(3 * nt));
  for (Eigen::Index t = 0; t < nt; ++t)
    for (int k = 0; k < 3; ++k) around[fill[F(t, k)]++] = static_cast<int32_t>(t);  // ascending t per vertex
  for (Eigen::Index t = 0; t < nt; ++t) {
    uint8_t owned = 0;
    for (int k = 0; k < 3; ++k) {
      const int32_t a = F(t, k), b = F(t, (k + 1) % 3);
      bool earlier = false;
      for (int32_t i = start[a]; i < start[a + 1] && around[i] < t; ++i) {
        const int32_t u = around[i];
        if (F(u, 0) == b || F(u, 1) == b || F(u, 2) == b) {
          earlier = true;
          break;
        }
      }
      if (!earlier) owned |= static_cast<uint8_t>(1u << k);
    }
    tris[static_cast<std::size_t>(t)].owned_edges = owned;
  }
}

}  // namespace

MeshIndex::MeshIndex(const Eigen::Ref<const Vertices>& V, const Eigen::Ref<const Triangles>& F) {
  const Eigen::Index nv = V.rows(), nt = F.rows();
  if (nt == 0) throw std::invalid_argument("the mesh has no triangles");
  if (nt > (int64_t{1} << 30)) throw std::invalid_argument("the mesh has too many triangles");
  for (Eigen::Index i = 0; i < nv; ++i) {
    if (!V.row(i).allFinite()) {
      std::ostringstream msg;
      msg << "vertex " << i << " has a non-finite coordinate";
      throw std::invalid_argument(msg.str());
    }
  }
  std::vector<IndexedTriangle> src(static_cast<std::size_t>(nt));
  std::vector<double> cx(src.size()), cy(src.size());
  zmin_ = V.col(2).minCoeff();
  for (Eigen::Index t = 0; t < nt; ++t) {
    IndexedTriangle& tri = src[t];
    for (int k = 0; k < 3; ++k) {
      const int32_t vi = F(t, k);
      if (vi < 0 || vi >= nv) {
        std::ostringstream msg;
        msg << "triangle " << t << " refers to vertex " << vi << ", outside 0.." << nv - 1;
        throw std::invalid_argument(msg.str());
      }
      for (int j = 0; j < 3; ++j) tri.p[k][j] = V(vi, j);
    }
    const Eigen::Vector3d a(tri.p[0]), b(tri.p[1]), c(tri.p[2]);
    Eigen::Vector3d n = (b - a).cross(c - a);
    const double len = n.norm();
    n = len > 0 ? Eigen::Vector3d(n / len) : Eigen::Vector3d::Zero();
    if (n.z() < 0) n = -n;  // drop-cutter sees the top side of every facet
    for (int j = 0; j < 3; ++j) tri.n[j] = n[j];
    tri.zmax = std::max({a.z(), b.z(), c.z()});
    tri.xmin = std::min({a.x(), b.x(), c.x()});
    tri.xmax = std::max({a.x(), b.x(), c.x()});
    tri.ymin = std::min({a.y(), b.y(), c.y()});
    tri.ymax = std::max({a.y(), b.y(), c.y()});
    cx[t] = (std::min({a.x(), b.x(), c.x()}) + std::max({a.x(), b.x(), c.x()})) * 0.5;
    cy[t] = (std::min({a.y(), b.y(), c.y()}) + std::max({a.y(), b.y(), c.y()})) * 0.5;
  }
  mark_owned_edges(F, nv, src);
  std::vector<int32_t> order(src.size());
  for (std::size_t i = 0; i < order.size(); ++i) order[i] = static_cast<int32_t>(i);
  nodes_.reserve(2 * (src.size() / kLeafSize + 1));
  tris_.reserve(src.size());
  nodes_.emplace_back();
  build(0, 0, static_cast<int32_t>(order.size()), order, cx, cy, src);
}

// Builds the subtree of order[begin, end) into nodes_[self]. Children are allocated as a pair
// (first, first + 1), so an inner node needs one index. Median split on the longer side of the centroid
// bounds keeps the tree balanced on regular grids as on scans.
void MeshIndex::build(int32_t self, int32_t begin, int32_t end, std::vector<int32_t>& order,
                      const std::vector<double>& cx, const std::vector<double>& cy,
                      const std::vector<IndexedTriangle>& src) {
  if (end - begin <= kLeafSize) {
    BvhNode node{INFINITY, INFINITY, -INFINITY, -INFINITY, -INFINITY, static_cast<int32_t>(tris_.size()),
                 end - begin};
    for (int32_t i = begin; i < end; ++i) {
      const IndexedTriangle& t = src[order[i]];
      node.xmin = std::min(node.xmin, t.xmin);
      node.xmax = std::max(node.xmax, t.xmax);
      node.ymin = std::min(node.ymin, t.ymin);
      node.ymax = std::max(node.ymax, t.ymax);
      node.zmax = std::max(node.zmax, t.zmax);
      tris_.push_back(t);
    }
    nodes_[self] = node;
    return;
  }
  double bx0 = INFINITY, bx1 = -INFINITY, by0 = INFINITY, by1 = -INFINITY;
  for (int32_t i = begin; i < end; ++i) {
    bx0 = std::min(bx0, cx[order[i]]);
    bx1 = std::max(bx1, cx[order[i]]);
    by0 = std::min(by0, cy[order[i]]);
    by1 = std::max(by1, cy[order[i]]);
  }
  const std::vector<double>& key = (bx1 - bx0 >= by1 - by0) ? cx : cy;
  const int32_t mid = begin + (end - begin) / 2;
  std::nth_element(order.begin() + begin, order.begin() + mid, order.begin() + end,
                   [&key](int32_t a, int32_t b) { return key[a] < key[b]; });
  const int32_t left = static_cast<int32_t>(nodes_.size());
  nodes_.resize(nodes_.size() + 2);
  build(left, begin, mid, order, cx, cy, src);
  build(left + 1, mid, end, order, cx, cy, src);
  const BvhNode& l = nodes_[left];
  const BvhNode& r = nodes_[left + 1];
  nodes_[self] = BvhNode{std::min(l.xmin, r.xmin), std::min(l.ymin, r.ymin), std::max(l.xmax, r.xmax),
                         std::max(l.ymax, r.ymax), std::max(l.zmax, r.zmax), left, 0};
}

}  // namespace tmm
