#include "tmm/mesh_index.hpp"

#include <Eigen/Geometry>

#include <algorithm>
#include <cmath>
#include <sstream>
#include <stdexcept>

namespace tmm {

namespace {
constexpr int32_t kLeafSize = 4;
}

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
    cx[t] = (std::min({a.x(), b.x(), c.x()}) + std::max({a.x(), b.x(), c.x()})) * 0.5;
    cy[t] = (std::min({a.y(), b.y(), c.y()}) + std::max({a.y(), b.y(), c.y()})) * 0.5;
  }
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
      for (int k = 0; k < 3; ++k) {
        node.xmin = std::min(node.xmin, t.p[k][0]);
        node.xmax = std::max(node.xmax, t.p[k][0]);
        node.ymin = std::min(node.ymin, t.p[k][1]);
        node.ymax = std::max(node.ymax, t.p[k][1]);
      }
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
