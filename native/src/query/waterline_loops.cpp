// The waterline level's loop side: marching squares over the cells, the segments chained into loops, their
// exact crossings, and the chords refined where the exact loop strays from them.
#include "waterline_level.hpp"

#include <algorithm>
#include <array>
#include <atomic>
#include <cmath>
#include <limits>
#include <sstream>
#include <stdexcept>
#include <thread>
#include <utility>
#include <unordered_map>

#include "tmm/util/bracket_1d.hpp"
#include "tmm/util/range.hpp"

namespace tmm {
namespace waterline_detail {

void Level::march(const Square& q, const std::vector<std::array<std::size_t, 2>>& nodes) {
  const std::size_t m = nodes.size();
  // Boundary segment i: nodes i -> i + 1; its key from its lower end.
  auto seg = [&](std::size_t i) {
    const auto& p = nodes[i];
    const auto& r = nodes[(i + 1) % m];
    const bool vertical = p[0] == r[0];
    const std::size_t X = std::min(p[0], r[0]), Y = std::min(p[1], r[1]);
    return key(X, Y, vertical, vertical ? std::max(p[1], r[1]) - Y : std::max(p[0], r[0]) - X);
  };
  std::vector<std::size_t> change;  // boundary segments with a change, counter-clockwise
  std::vector<bool> out;            // blocked -> free (a segment's start) or free -> blocked
  for (std::size_t i = 0; i < m; ++i) {
    const bool a = state(nodes[i][0], nodes[i][1]), b = state(nodes[(i + 1) % m][0], nodes[(i + 1) % m][1]);
    if (a == b) continue;
    change.push_back(i);
    out.push_back(a);
  }
  const std::size_t n = change.size();
  if (n == 0) return;
  // Two changes: one segment. More (a saddle): the centre decides whether the blocked stretches join (each
  // start goes to the next change counter-clockwise) or not (to the previous one).
  bool centre_blocked = true;
  if (n > 2) {
    const double c = 0.5 * static_cast<double>(q.L);
    centre_blocked = blocked(main_, fx(q.X) + c * g_.dx / static_cast<double>(g_.k),
                             fy(q.Y) + c * g_.dy / static_cast<double>(g_.k));
  }
  for (std::size_t j = 0; j < n; ++j) {
    if (!out[j]) continue;
    const std::size_t to = centre_blocked ? (j + 1) % n : (j + n - 1) % n;
    next_.emplace(seg(change[j]), seg(change[to]));
    starts_.push_back(seg(change[j]));
  }
}

bool Level::off_chord(Probe& pr, const Point& p, const Point& q, double t, Point& c) const {
  const double dx = q.x - p.x, dy = q.y - p.y, length = std::hypot(dx, dy);
  const double nx = -dy / length, ny = dx / length;  // left normal: the blocked side
  const Point m{p.x + t * dx, p.y + t * dy, true};
  const bool m_blocked = blocked(pr, m.x, m.y);
  // The boundary lies towards the free side of m (right if m is blocked, left if free).
  const double sign = m_blocked ? -1.0 : 1.0;
  return walk(pr, m, m_blocked, sign * nx, sign * ny, length, c);
}

bool Level::walk(Probe& pr, const Point& m, bool m_blocked, double ux, double uy, double length, Point& c) const {
  auto along = [&](double s) { return Point{m.x + s * ux, m.y + s * uy, true}; };
  const double probe = 0.75 * o_.chord_tol;
  // Past the chord's length the search goes on in steps of that length (at least the finest square) up to a
  // grid step: a spike of the loop (the tip of a narrow free crack or of a blocked sliver, a notch between two
  // discs of a flat end mill) runs that far from its chord between the nodes of the squares.
  const double step = std::max(length, std::max(g_.dx, g_.dy) / static_cast<double>(g_.k));
  const double reach = std::max(length, std::max(g_.dx, g_.dy));
  double s_in = 0.0, s_out = probe;
  Point out_pt = along(s_out);
  while (blocked(pr, out_pt.x, out_pt.y) == m_blocked) {
    s_in = s_out;
    s_out = s_out < length ? 2.0 * s_out : s_out + step;
    if (s_out > reach) return false;  // no boundary within reach: leave the chord
    out_pt = along(s_out);
  }
  if (s_in == 0.0) return false;  // the exact loop is within the probe distance here
  const Point in_pt = along(s_in);
  const Point& f = m_blocked ? out_pt : in_pt;
  const Point& b = m_blocked ? in_pt : out_pt;
  const double cf = clearance(pr, f.x, f.y), cb = clearance(pr, b.x, b.y);
  c = cb < 0.0 ? crossing(pr, f, b, cf, cb) : f;  // (cb >= 0 cannot be: b is blocked)
  const double slack = 1e-9;
  return c.x >= o_.xmin - slack && c.x <= o_.xmax + slack && c.y >= o_.ymin - slack && c.y <= o_.ymax + slack;
}

void Level::refine(Probe& pr, const Point& u, const Point& p, const Point& q, const Point& w, int depth,
                   std::vector<Point>& out) const {
  const double length = std::hypot(q.x - p.x, q.y - p.y);
  if (depth >= o_.max_depth || length < o_.min_segment) return;
  auto split_at = [&](const Point& c) {
    refine(pr, u, p, c, q, depth + 1, out);
    out.push_back(c);
    refine(pr, p, c, q, w, depth + 1, out);
  };
  // The midpoint, then the quarters (on a faceted mesh the loop's curvature changes along a chord, so its
  // farthest point need not lie at the middle), each at 3/4 chord_tol: where the loop bends one way between p
  // and q, its distance from the chord is at most 4/3 of the largest of its distances at these three points
  // (a concave function through five points: the secants extended). (The middle alone at chord_tol / 2 bounds
  // a loop bending one way as well, but not one that bends both ways: 1.16 chord_tol on the relief test.)
  Point c;
  for (double t : {0.5, 0.25, 0.75})
    if (off_chord(pr, p, q, t, c)) return split_at(c);
  // The loop turning back by more than a right angle over the chord (arriving at p against the way it leaves
  // q): the tip of a spike, a crack or a notch may lie beyond the chord's ends, where no perpendicular through
  // it reaches. It is searched from the middle along the way the loop points there (the two directions' mean).
  const double ia = std::hypot(p.x - u.x, p.y - u.y), ob = std::hypot(w.x - q.x, w.y - q.y);
  if (!(ia > 0.0 && ob > 0.0)) return;
  const double ix = (p.x - u.x) / ia, iy = (p.y - u.y) / ia, ox = (w.x - q.x) / ob, oy = (w.y - q.y) / ob;
  if (ix * ox + iy * oy >= 0.0) return;
  const double dx = ix - ox, dy = iy - oy, dl = std::hypot(dx, dy);
  const Point m{0.5 * (p.x + q.x), 0.5 * (p.y + q.y), true};
  // A crossing there beyond the probe distance is inserted even when it lies beside the chord (on a crack's
  // side): the chords from it reach across towards the tip, and their own walks go on.
  if (walk(pr, m, blocked(pr, m.x, m.y), dx / dl, dy / dl, length, c)) split_at(c);
}

void Level::march_cells() {
  const std::size_t NX = g_.NX, NY = g_.NY, k = g_.k;
  std::vector<std::array<std::size_t, 2>> nodes;
  for (std::size_t J = 0; J + 1 < NY; ++J) {
    const bool row_refined = !row_refined_.empty() && row_refined_[J] > 0;
    const bool near_refined = row_refined || (J > 0 && row_refined_.size() && row_refined_[J - 1] > 0) ||
                              (J + 2 < NY && row_refined_.size() && row_refined_[J + 1] > 0);
    if (!near_refined && (z_ >= g_.row_hi[J] || z_ < g_.row_lo[J])) continue;  // all free or all blocked
    for (std::size_t I = 0; I + 1 < NX; ++I) {
      if (cell_refined(I, J)) {
        for (const Square& q : trees_[tree_of_[J * (NX - 1) + I]]) {
          boundary(q, true, nodes);
          march(q, nodes);
        }
        continue;
      }
      const bool c[4] = {g_.h[J * NX + I] > z_, g_.h[J * NX + I + 1] > z_, g_.h[(J + 1) * NX + I + 1] > z_,
                         g_.h[(J + 1) * NX + I] > z_};
      // Next to a refined cell the boundary may change state between the corners (at most twice: closure).
      const bool scan = k > 1 && neighbour_refined(I, J);
      const int n = c[0] + c[1] + c[2] + c[3];
      if (!scan && (n == 0 || n == 4)) continue;
      const Square q{I * k, J * k, k};
      boundary(q, scan, nodes);
      march(q, nodes);
    }
  }
}

std::vector<std::vector<uint64_t>> Level::chain_edges() const {
  std::vector<std::vector<uint64_t>> chains;
  std::unordered_map<uint64_t, bool> done;
  done.reserve(starts_.size());
  for (uint64_t first : starts_) {
    if (done.count(first)) continue;
    std::vector<uint64_t> chain;
    for (uint64_t e = first;;) {
      done.emplace(e, true);
      chain.push_back(e);
      e = next_.at(e);
      if (e == first) break;
    }
    chains.push_back(std::move(chain));
  }
  return chains;
}

std::vector<std::vector<Point>> Level::loop_points(const std::vector<std::vector<uint64_t>>& chains,
                                                   const BatchOptions& batch) {
  std::size_t total = 0;
  for (const auto& chain : chains) total += chain.size();
  std::vector<uint64_t> edges;
  edges.reserve(total);
  for (const auto& chain : chains) edges.insert(edges.end(), chain.begin(), chain.end());
  std::vector<Point> crossings(total);
  std::atomic<std::size_t> worker_drops{0};
  parallel_chunks(total, kWorkChunk, batch, [&](std::size_t begin, std::size_t end) {
    Probe pr;
    for (std::size_t i = begin; i < end; ++i) crossings[i] = edge_crossing(pr, edges[i]);
    worker_drops += pr.drops;
  });
  worker_drops_ += worker_drops.load();
  std::vector<std::vector<Point>> loops_pts;
  std::size_t at = 0;
  for (const auto& chain : chains) {
    std::vector<Point> pts;
    for (std::size_t i = 0; i < chain.size(); ++i) {
      const Point& p = crossings[at + i];
      if (pts.empty() || p.x != pts.back().x || p.y != pts.back().y) pts.push_back(p);
      else pts.back().contact = pts.back().contact && p.contact;
    }
    at += chain.size();
    while (pts.size() > 1 && pts.front().x == pts.back().x && pts.front().y == pts.back().y) {
      pts.front().contact = pts.front().contact && pts.back().contact;
      pts.pop_back();
    }
    if (pts.size() < 3) continue;  // a degenerate loop (a blocked node touching the bounds' corner only)
    loops_pts.push_back(std::move(pts));
  }
  return loops_pts;
}

std::vector<std::vector<Point>> Level::refine_chords(const std::vector<std::vector<Point>>& loops_pts,
                                                     const BatchOptions& batch) {
  // Chords: (loop, point) pairs; each refined into its own list of inserted points.
  std::vector<std::pair<std::size_t, std::size_t>> chords;
  for (std::size_t l = 0; l < loops_pts.size(); ++l)
    for (std::size_t i = 0; i < loops_pts[l].size(); ++i) chords.emplace_back(l, i);
  std::vector<std::vector<Point>> inserted(chords.size());
  std::atomic<std::size_t> worker_drops{0};
  parallel_chunks(chords.size(), kWorkChunk, batch, [&](std::size_t begin, std::size_t end) {
    Probe pr;
    for (std::size_t c = begin; c < end; ++c) {
      const auto& pts = loops_pts[chords[c].first];
      const std::size_t i = chords[c].second;
      const std::size_t n = pts.size();
      const Point& p = pts[i];
      const Point& q = pts[(i + 1) % n];
      if (p.contact && q.contact) refine(pr, pts[(i + n - 1) % n], p, q, pts[(i + 2) % n], 0, inserted[c]);
    }
    worker_drops += pr.drops;
  });
  worker_drops_ += worker_drops.load();
  return inserted;
}

std::vector<WaterlineLoop> Level::assemble(const std::vector<std::vector<Point>>& loops_pts,
                                           const std::vector<std::vector<Point>>& inserted) const {
  std::vector<WaterlineLoop> result;
  std::size_t c = 0;
  for (const auto& pts : loops_pts) {
    WaterlineLoop loop;
    loop.z = z_;
    auto add = [&](const Point& q) {
      loop.xy.push_back(q.x);
      loop.xy.push_back(q.y);
      loop.contact.push_back(q.contact ? 1 : 0);
    };
    for (const Point& p : pts) {
      add(p);
      for (const Point& q : inserted[c]) add(q);
      ++c;
    }
    result.push_back(std::move(loop));
  }
  return result;
}

std::vector<WaterlineLoop> Level::loops() {
  if (g_.k > 1) refine_cells();
  march_cells();
  // The loops' edges in order, then their exact crossings and their chords' refinement, each item on its
  // own (fixed chunks: the same points for any thread count; batch_ may cancel within the level).
  const std::vector<std::vector<uint64_t>> chains = chain_edges();
  // Progress: the crossings the first half of the level, the chords the second.
  BatchOptions first_half{batch_.threads, {}, batch_.within}, second_half{batch_.threads, {}, batch_.within};
  if (batch_.progress) {
    first_half.progress = [&](double f) { return batch_.progress(0.5 * f); };
    second_half.progress = [&](double f) { return batch_.progress(0.5 + 0.5 * f); };
  }
  const std::vector<std::vector<Point>> loops_pts = loop_points(chains, first_half);
  const std::vector<std::vector<Point>> inserted = refine_chords(loops_pts, second_half);
  return assemble(loops_pts, inserted);
}

}  // namespace waterline_detail
}  // namespace tmm
