#include "tmm/mesh/mesh_index.hpp"

#include <Eigen/Geometry>

#include <algorithm>
#include <cmath>
#include <memory>
#include <sstream>
#include <string>
#include <stdexcept>
#include <thread>

#include "tmm/util/parallel.hpp"

namespace tmm {

namespace {

constexpr int32_t kLeafSize = 8;

// Spreads the 16 bits of v over the even bits of a 32-bit word.
uint32_t spread_bits(uint32_t v) {
  v = (v | (v << 8)) & 0x00FF00FFu;
  v = (v | (v << 4)) & 0x0F0F0F0Fu;
  v = (v | (v << 2)) & 0x33333333u;
  v = (v | (v << 1)) & 0x55555555u;
  return v;
}

// Triangle indices in Z-order (Morton order) of their XY box centres, by an LSD radix sort: O(m). Median
// splits of this order give a balanced tree of compact boxes without sorting at every level.
// Progress: six passes over the triangles in progress's current part.
std::vector<int32_t> morton_order(const std::vector<double>& cx, const std::vector<double>& cy,
                                  SerialProgress& progress) {
  const std::size_t m = cx.size();
  double x0 = INFINITY, x1 = -INFINITY, y0 = INFINITY, y1 = -INFINITY;
  for (std::size_t i = 0; i < m; ++i) {
    progress.tick(i, 6 * m);
    x0 = std::min(x0, cx[i]);
    x1 = std::max(x1, cx[i]);
    y0 = std::min(y0, cy[i]);
    y1 = std::max(y1, cy[i]);
  }
  const double span = std::max({x1 - x0, y1 - y0, 1e-300});
  const double scale = 65535.0 / span;  // one square grid, so X and Y keep their proportions
  std::vector<uint32_t> key(m), key_tmp(m);
  std::vector<int32_t> order(m), order_tmp(m);
  for (std::size_t i = 0; i < m; ++i) {
    progress.tick(m + i, 6 * m);
    const auto qx = static_cast<uint32_t>((cx[i] - x0) * scale);
    const auto qy = static_cast<uint32_t>((cy[i] - y0) * scale);
    key[i] = spread_bits(qx) | (spread_bits(qy) << 1);
    order[i] = static_cast<int32_t>(i);
  }
  std::vector<std::size_t> count(1u << 16);
  for (int shift = 0; shift < 32; shift += 16) {
    const std::size_t pass = (2 + shift / 8) * m;  // items of the passes before this one
    std::fill(count.begin(), count.end(), 0);
    for (std::size_t i = 0; i < m; ++i) {
      progress.tick(pass + i, 6 * m);
      ++count[(key[i] >> shift) & 0xFFFF];
    }
    std::size_t sum = 0;
    for (auto& c : count) {
      const std::size_t c0 = c;
      c = sum;
      sum += c0;
    }
    for (std::size_t i = 0; i < m; ++i) {
      progress.tick(pass + m + i, 6 * m);
      const std::size_t slot = count[(key[i] >> shift) & 0xFFFF]++;
      key_tmp[slot] = key[i];
      order_tmp[slot] = order[i];
    }
    key.swap(key_tmp);
    order.swap(order_tmp);
  }
  return order;
}

// IndexedTriangle::owned_edges per triangle: edge (a, b) of triangle t is owned by t unless a lower-numbered
// triangle also has both a and b. Triangles around each vertex in compressed rows: O(m * valence).
// Progress: three passes over the triangles (the last one is half of the time) in progress's current part.
std::vector<uint8_t> owned_edges(const Eigen::Ref<const Triangles>& F, Eigen::Index nv, SerialProgress& progress) {
  const Eigen::Index nt = F.rows();
  const auto items = static_cast<std::size_t>(4 * nt);
  std::vector<uint8_t> result(static_cast<std::size_t>(nt));
  std::vector<int32_t> start(static_cast<std::size_t>(nv) + 1, 0);
  for (Eigen::Index t = 0; t < nt; ++t) {
    progress.tick(static_cast<std::size_t>(t), items);
    for (int k = 0; k < 3; ++k) ++start[F(t, k) + 1];
  }
  for (Eigen::Index v = 0; v < nv; ++v) start[v + 1] += start[v];
  std::vector<int32_t> fill(start.begin(), start.end() - 1);
  // Not zero-filled first: the pass below writes every entry, and its reports cover the page faults.
  const std::unique_ptr<int32_t[]> around(new int32_t[static_cast<std::size_t>(3 * nt)]);
  for (Eigen::Index t = 0; t < nt; ++t) {
    progress.tick(static_cast<std::size_t>(nt + t), items);
    for (int k = 0; k < 3; ++k) around[fill[F(t, k)]++] = static_cast<int32_t>(t);  // ascending t per vertex
  }
  for (Eigen::Index t = 0; t < nt; ++t) {
    progress.tick(static_cast<std::size_t>(2 * nt + 2 * t), items);
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
    result[static_cast<std::size_t>(t)] = owned;
  }
  return result;
}

// The XY box centres of the triangles, in progress's current part; throws naming the first triangle with
// an index outside [0, nv).
void box_centres(const Eigen::Ref<const Vertices>& V, const Eigen::Ref<const Triangles>& F,
                 std::vector<double>& cx, std::vector<double>& cy, SerialProgress& progress) {
  const Eigen::Index nv = V.rows(), nt = F.rows();
  cx.reserve(static_cast<std::size_t>(nt));  // appended: pages are first touched as the loop reports
  cy.reserve(cx.capacity());
  for (Eigen::Index t = 0; t < nt; ++t) {
    progress.tick(static_cast<std::size_t>(t), static_cast<std::size_t>(nt));
    double x0 = INFINITY, x1 = -INFINITY, y0 = INFINITY, y1 = -INFINITY;
    for (int k = 0; k < 3; ++k) {
      const int32_t vi = F(t, k);
      if (vi < 0 || vi >= nv) {
        std::ostringstream msg;
        msg << "triangle " << t << " refers to vertex " << vi << ", outside 0.." << nv - 1;
        throw std::invalid_argument(msg.str());
      }
      x0 = std::min(x0, V(vi, 0));
      x1 = std::max(x1, V(vi, 0));
      y0 = std::min(y0, V(vi, 1));
      y1 = std::max(y1, V(vi, 1));
    }
    cx.push_back(0.5 * (x0 + x1));
    cy.push_back(0.5 * (y0 + y1));
  }
}

// Triangle order[i] as the query needs it, facing up (drop-cutter sees the top side of every facet).
IndexedTriangle indexed_triangle(const Eigen::Ref<const Vertices>& V, const Eigen::Ref<const Triangles>& F,
                                 int32_t t, uint8_t owned) {
  IndexedTriangle tri;
  for (int k = 0; k < 3; ++k)
    for (int j = 0; j < 3; ++j) tri.p[k][j] = V(F(t, k), j);
  const Eigen::Vector3d a(tri.p[0]), b(tri.p[1]), c(tri.p[2]);
  Eigen::Vector3d n = (b - a).cross(c - a);
  const double len = n.norm();
  n = len > 0 ? Eigen::Vector3d(n / len) : Eigen::Vector3d::Zero();
  if (n.z() < 0) n = -n;
  for (int j = 0; j < 3; ++j) tri.n[j] = n[j];
  tri.zmax = std::max({a.z(), b.z(), c.z()});
  tri.xmin = std::min({a.x(), b.x(), c.x()});
  tri.xmax = std::max({a.x(), b.x(), c.x()});
  tri.ymin = std::min({a.y(), b.y(), c.y()});
  tri.ymax = std::max({a.y(), b.y(), c.y()});
  tri.owned_edges = owned;
  return tri;
}

}  // namespace

// The calling thread reports the leaves it builds; when its callback cancels (or throws) the other threads
// see `stop` and leave their subtrees at their next leaf, so the join that unwinds the build is quick.
struct MeshIndex::BuildState {
  SerialProgress& progress;
  int32_t count;  // triangles
  std::atomic<int> used{1};
  std::atomic<bool> stop{false};
};

MeshIndex::MeshIndex(const Eigen::Ref<const Vertices>& V, const Eigen::Ref<const Triangles>& F, int threads,
                     const std::function<bool(double)>& progress) {
  const Eigen::Index nv = V.rows(), nt = F.rows();
  if (threads < 0) throw std::invalid_argument("threads must be >= 0 (0: the default, TMM_THREADS or all hardware threads), got " + std::to_string(threads));
  if (nt == 0) throw std::invalid_argument("the mesh has no triangles");
  if (nt > (int64_t{1} << 30)) throw std::invalid_argument("the mesh has too many triangles");
  SerialProgress reporter(progress);
  reporter.part(0.0, 0.02);
  for (Eigen::Index i = 0; i < nv; ++i) {
    reporter.tick(static_cast<std::size_t>(i), static_cast<std::size_t>(nv));
    if (!V.row(i).allFinite()) {
      std::ostringstream msg;
      msg << "vertex " << i << " has a non-finite coordinate";
      throw std::invalid_argument(msg.str());
    }
  }
  require_vertices_in_range(V);
  // Parts by their measured share of the time.
  std::vector<double> cx, cy;
  reporter.part(0.02, 0.1);
  box_centres(V, F, cx, cy, reporter);
  zmin_ = V.col(2).minCoeff();
  reporter.part(0.1, 0.45);
  const std::vector<uint8_t> owned = owned_edges(F, nv, reporter);
  reporter.part(0.45, 0.65);
  const std::vector<int32_t> order = morton_order(cx, cy, reporter);
  // Triangles written straight into leaf order: position i holds triangle order[i]. Appended rather than
  // resized first, so the gigabyte of a huge mesh is not zeroed in one step that cannot report.
  reporter.part(0.65, 0.85);
  tris_.reserve(order.size());
  for (std::size_t i = 0; i < order.size(); ++i) {
    reporter.tick(i, order.size());
    tris_.push_back(indexed_triangle(V, F, order[i], owned[static_cast<std::size_t>(order[i])]));
  }
  const int32_t count = static_cast<int32_t>(order.size());
  // Zeroed a block at a time: the nodes of a huge mesh are a hundred MB, a pause of their own.
  reporter.part(0.85, 0.87);
  const auto node_count = static_cast<std::size_t>(1 + descendants(count));
  nodes_.reserve(node_count);
  for (std::size_t n = 0; n < node_count; n = nodes_.size()) {
    reporter.step(n, node_count);
    nodes_.resize(std::min(node_count, n + (std::size_t(1) << 18)));
  }
  if (threads == 0) threads = default_threads();
  reporter.part(0.87, 1.0);
  BuildState state{reporter, count};
  build(0, 1, 0, count, threads, state, true);
  build_threads_ = state.used.load();
  reporter.finish();
}

// Nodes below a subtree of n triangles: the median split fixes the tree's shape, so every subtree's node
// range is known before it is built and subtrees can be built in parallel.
int32_t MeshIndex::descendants(int32_t n) {
  if (n <= kLeafSize) return 0;
  const int32_t l = n / 2;
  return 2 + descendants(l) + descendants(n - l);
}

// Builds the subtree of tris_[begin, end) into nodes_[self], its descendants into nodes_ from `below` on:
// the children pair (below, below + 1), then the left child's descendants, then the right child's. Leaves
// hold tris_[begin, end). Median splits of the Morton order keep the tree balanced on regular grids as on
// scans. Large subtrees build their two halves on two threads (`threads` > 1).
void MeshIndex::build(int32_t self, int32_t below, int32_t begin, int32_t end, int threads, BuildState& state,
                      bool reports) {
  if (end - begin <= kLeafSize) {
    if (reports) {
      try {
        state.progress.tick(static_cast<std::size_t>(begin), static_cast<std::size_t>(state.count));
      } catch (...) {
        state.stop.store(true);
        throw;
      }
    } else if (state.stop.load(std::memory_order_relaxed)) {
      return;  // the tree is thrown away
    }
    BvhNode node{INFINITY, INFINITY, -INFINITY, -INFINITY, -INFINITY, begin, end - begin};
    for (int32_t i = begin; i < end; ++i) {
      const IndexedTriangle& t = tris_[i];
      node.xmin = std::min(node.xmin, t.xmin);
      node.xmax = std::max(node.xmax, t.xmax);
      node.ymin = std::min(node.ymin, t.ymin);
      node.ymax = std::max(node.ymax, t.ymax);
      node.zmax = std::max(node.zmax, t.zmax);
    }
    nodes_[self] = node;
    return;
  }
  const int32_t mid = begin + (end - begin) / 2;  // `order` is in Morton order: halves are compact
  const int32_t left = below, right = below + 1;
  const int32_t left_below = below + 2, right_below = left_below + descendants(mid - begin);
  if (threads > 1 && end - begin > kParallelBuild) {
    ++state.used;
    // Joined on every exit, an exception from this thread's half included.
    struct Joined {
      std::thread t;
      ~Joined() { t.join(); }
    } other{std::thread([&] { build(right, right_below, mid, end, threads / 2, state, false); })};
    build(left, left_below, begin, mid, threads - threads / 2, state, reports);
  } else {
    build(left, left_below, begin, mid, 1, state, reports);
    build(right, right_below, mid, end, 1, state, reports);
  }
  const BvhNode& l = nodes_[left];
  const BvhNode& r = nodes_[right];
  nodes_[self] = BvhNode{std::min(l.xmin, r.xmin), std::min(l.ymin, r.ymin), std::max(l.xmax, r.xmax),
                         std::max(l.ymax, r.ymax), std::max(l.zmax, r.zmax), left, 0};
}

}  // namespace tmm
