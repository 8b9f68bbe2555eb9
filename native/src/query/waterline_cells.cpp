// The waterline level's grid side: drop heights at the nodes (fine nodes sampled once), the adaptive cells
// (split where a feature could hide between the corners, then closed), and the exact crossing on an edge.
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

Point Level::crossing(Probe& pr, Point f, Point b, double cf, double cb) const {
  const double length = std::hypot(b.x - f.x, b.y - f.y);
  const double width = o_.bracket / length;  // in t
  auto at = [&](double t) { return Point{f.x + t * (b.x - f.x), f.y + t * (b.y - f.y), true}; };
  auto good = [&](double t) {
    const Point p = at(t);
    return !blocked(pr, p.x, p.y);
  };
  // Illinois regula falsi on z - h over [a, c] (a free, c blocked). Once the secant puts the root within the
  // bracket width of a new point, one predicate drop on the other side closes the bracket (h is smooth
  // almost everywhere: the usual case ends in a few drops). Steps that do not halve the bracket are
  // followed by a bisection: h can jump (a flat end mill reaching a vertical wall).
  double a = 0.0, c = 1.0, fa = std::min(cf, z_ - eval_floor_), fc = cb;
  int side = 0;
  for (int k = 0; k < kIllinoisSteps && c - a > width; ++k) {
    const double before = c - a;
    double m = (a * fc - c * fa) / (fc - fa);
    if (!(m > a && m < c)) m = 0.5 * (a + c);
    const Point p = at(m);
    const double fm = clearance(pr, p.x, p.y);
    const double slope = (fc - fa) / (c - a);  // < 0
    if (fm >= 0.0) {
      a = m;
      fa = fm;
      if (side == -1) fc *= 0.5;
      side = -1;
      if (fm < -slope * width && m + width < c && !good(m + width)) c = m + width;
    } else {
      c = m;
      fc = fm;
      if (side == 1) fa *= 0.5;
      side = 1;
      if (-fm < -slope * width && m - width > a && good(m - width)) a = m - width;
    }
    if (c - a > 0.5 * before && c - a > width) {
      const double mid = 0.5 * (a + c);
      const Point q = at(mid);
      const double fq = clearance(pr, q.x, q.y);
      if (fq >= 0.0) {
        a = mid;
        fa = fq;
      } else {
        c = mid;
        fc = fq;
      }
      side = 0;
    }
  }
  if (c - a > width) {
    const int steps = static_cast<int>(std::ceil(std::log2((c - a) / width)));
    a = bisect(a, c, steps, good).good;
  }
  return at(a);
}

double Level::height(std::size_t X, std::size_t Y, Nodes& nd) const {
  if (coarse_node(X, Y)) return g_.h[(Y / g_.k) * g_.NX + X / g_.k];
  if (fine_ring(X, Y)) return -kInf;
  const auto it = nd.fine.find(node_id(X, Y));
  if (it != nd.fine.end()) return it->second;
  return node_drop(nd.pr, fx(X), fy(Y));  // (not a node: not kept)
}

void Level::add_node(std::size_t X, std::size_t Y, Nodes& nd) const {
  if (coarse_node(X, Y)) return;
  const uint64_t id = node_id(X, Y);
  if (nd.fine.count(id)) return;
  nd.fine.emplace(id, fine_ring(X, Y) ? -kInf : node_drop(nd.pr, fx(X), fy(Y)));
  check_fine_nodes(nd.sampled ? ++*nd.sampled : nd.fine.size());
}

void Level::check_fine_nodes(std::size_t n) const {
  if (n > kMaxWaterlineFineNodes) {
    std::ostringstream msg;
    msg << "waterline minimum step samples more than " << kMaxWaterlineFineNodes << " fine nodes at level z "
        << z_ << " (" << refined_count_ << " cells refined " << g_.k << " times), over the kernel's limit; use "
        << "a larger minimum step or sample step";
    throw std::invalid_argument(msg.str());
  }
}

double Level::node_height(std::size_t X, std::size_t Y) const {
  if (coarse_node(X, Y)) return g_.h[(Y / g_.k) * g_.NX + X / g_.k];
  if (fine_ring(X, Y)) return -kInf;
  return fine_.at(node_id(X, Y));
}

Point Level::edge_crossing(Probe& pr, uint64_t edge) const {
  const std::size_t L = static_cast<std::size_t>(edge % kLengths);
  const bool vertical = (edge / kLengths) & 1u;
  const uint64_t node = edge / kLengths / 2;
  const std::size_t X = static_cast<std::size_t>(node % NXf()), Y = static_cast<std::size_t>(node / NXf());
  const std::size_t X2 = vertical ? X : X + L, Y2 = vertical ? Y + L : Y;
  const Point a{fx(X), fy(Y), true}, b{fx(X2), fy(Y2), true};
  // A ring node stands for "outside the bounds": the crossing is the bound itself, not a contact.
  if (fine_ring(X, Y)) return Point{b.x, b.y, false};
  if (fine_ring(X2, Y2)) return Point{a.x, a.y, false};
  const double ha = node_height(X, Y), hb = node_height(X2, Y2);
  if (ha > z_) return crossing(pr, b, a, z_ - hb, z_ - ha);
  return crossing(pr, a, b, z_ - ha, z_ - hb);
}

bool Level::may_block(double x0, double y0, double x1, double y1) const {
  bool any = false;
  index_.near_rect(x0, y0, x1, y1, cutter_.max_radius(), z_, [&](const IndexedTriangle& t, int32_t) {
    if (any) return;
    const double dx = std::max({t.xmin - x1, x0 - t.xmax, 0.0});
    const double dy = std::max({t.ymin - y1, y0 - t.ymax, 0.0});
    any = dx * dx + dy * dy < cutter_.reach2(t.zmax - z_);
  });
  return any;
}

bool Level::split_wanted(const Square& q, Nodes& nd) const {
  if (q.L < 2) return false;
  const double h[4] = {height(q.X, q.Y, nd), height(q.X + q.L, q.Y, nd), height(q.X + q.L, q.Y + q.L, nd),
                       height(q.X, q.Y + q.L, nd)};
  int blocked_corners = 0;
  for (double v : h) blocked_corners += v > z_;
  if (blocked_corners == 2 && (h[0] > z_) == (h[2] > z_)) return true;  // a saddle
  // A piece of the blocked region that reaches no corner comes from mesh points less than the cutter's lift
  // over the square above z, which hold the nearest corner above z minus that lift.
  const double side = static_cast<double>(q.L) / static_cast<double>(g_.k) * std::max(g_.dx, g_.dy);
  const double band = cutter_.height(std::min(side, cutter_.max_radius()));
  // Pockets have no such bound: the band above z is the lift of a ball of the cutter's radius over twice the
  // side (a flat's own lift is 0), a heuristic for dips between the corners (mount_rush.stl's 0.7 x 1.1 mm
  // pocket between 0.5 mm nodes needs the factor 2).
  const double r = std::min(2.0 * side, cutter_.max_radius()), R = cutter_.max_radius();
  const double pocket_band = std::max(band, R - std::sqrt(std::max(R * R - r * r, 0.0)));
  bool near = false;
  for (double v : h) near = near || (v <= z_ ? z_ - v < band : v - z_ < pocket_band);
  if (!near && q.L == g_.k && (blocked_corners == 0 || blocked_corners == 4)) {
    // The drop height bending between the grid nodes: its range inside the cell by the cubic through the
    // 4 x 4 nodes around it (no drops), for the smooth dips and crests the corners do not show. Only for cells
    // of one state: a cell the loop already crosses has a range about z whatever it hides.
    double lo = kInf, hi = -kInf;
    if (cubic_range(q.X / g_.k, q.Y / g_.k, z_ - band, z_ + pocket_band, lo, hi))
      near = lo < z_ + pocket_band && hi > z_ - band;
  }
  if (!near) return false;
  const double x0 = fx(q.X), y0 = fy(q.Y), x1 = fx(q.X + q.L), y1 = fy(q.Y + q.L);
  if (blocked_corners == 0) return may_block(x0, y0, x1, y1);
  // All blocked, a corner less than the lift above z: a free pocket could hide (no rule bounds it; this one
  // sees small dips near z), unless one triangle above z lies under the whole square (a plateau).
  if (blocked_corners == 4) return !under_one_triangle(x0, y0, x1, y1);
  return true;
}

bool Level::cubic_range(std::size_t I, std::size_t J, double below, double above, double& lo, double& hi) const {
  if (I < 2 || J < 2 || I + 3 >= g_.NX || J + 3 >= g_.NY) return false;  // the ring or its neighbours
  // Every value of the cubic is a weighted sum of the 16 nodes, the weights summing to 1 and their absolute
  // values to at most 1.25^2 (a Catmull-Rom weight pair is -t(1 - t)^2 / 2, -t^2 (1 - t) / 2): it lies
  // within 1.5625 half-ranges of the nodes' mid-range (1.6 and 1e-9 mm for the rounding). Most cells are
  // far from the band (the plate, the top of a part): no samples.
  double n_lo = kInf, n_hi = -kInf;
  for (std::size_t r = J - 1; r <= J + 2; ++r)
    for (std::size_t c = I - 1; c <= I + 2; ++c) {
      n_lo = std::min(n_lo, g_.h[r * g_.NX + c]);
      n_hi = std::max(n_hi, g_.h[r * g_.NX + c]);
    }
  const double mid = 0.5 * (n_lo + n_hi), reach = 0.8 * (n_hi - n_lo) + 1e-9;
  if (mid + reach <= below || mid - reach >= above) {
    lo = mid - reach;
    hi = mid + reach;
    return true;
  }
  auto cr = [](const double* p, double t) {  // Catmull-Rom between p[1] and p[2]
    return 0.5 * (2.0 * p[1] + (p[2] - p[0]) * t + (2.0 * p[0] - 5.0 * p[1] + 4.0 * p[2] - p[3]) * t * t +
                  (3.0 * (p[1] - p[2]) + p[3] - p[0]) * t * t * t);
  };
  for (double ty : {0.25, 0.5, 0.75}) {
    for (double tx : {0.25, 0.5, 0.75}) {
      double col[4];
      for (int r = 0; r < 4; ++r) col[r] = cr(&g_.h[(J - 1 + r) * g_.NX + I - 1], tx);
      const double v = cr(col, ty);
      lo = std::min(lo, v);
      hi = std::max(hi, v);
    }
  }
  return std::isfinite(lo) && std::isfinite(hi);
}

bool Level::under_one_triangle(double x0, double y0, double x1, double y1) const {
  bool found = false;
  index_.near_rect(x0, y0, x1, y1, 0.0, z_, [&](const IndexedTriangle& t, int32_t) {
    if (found || !(t.xmin <= x0 && t.xmax >= x1 && t.ymin <= y0 && t.ymax >= y1)) return;
    if (!(std::min({t.p[0][2], t.p[1][2], t.p[2][2]}) > z_)) return;
    auto inside = [&](double x, double y) {  // in the triangle's XY projection (either orientation)
      double s[3];
      for (int e = 0; e < 3; ++e) {
        const double* a = t.p[e];
        const double* b = t.p[(e + 1) % 3];
        s[e] = (b[0] - a[0]) * (y - a[1]) - (b[1] - a[1]) * (x - a[0]);
      }
      return (s[0] >= 0 && s[1] >= 0 && s[2] >= 0) || (s[0] <= 0 && s[1] <= 0 && s[2] <= 0);
    };
    found = inside(x0, y0) && inside(x1, y0) && inside(x1, y1) && inside(x0, y1);
  });
  return found;
}

void Level::split(std::vector<Square>& tree, std::size_t i, Nodes& nd) const {
  const Square q = tree[i];
  const std::size_t h = q.L / 2;
  for (std::size_t b = 0; b <= 2; ++b)
    for (std::size_t a = 0; a <= 2; ++a) add_node(q.X + a * h, q.Y + b * h, nd);
  tree[i] = Square{q.X, q.Y, h};
  tree.push_back(Square{q.X + h, q.Y, h});
  tree.push_back(Square{q.X + h, q.Y + h, h});
  tree.push_back(Square{q.X, q.Y + h, h});
}

bool Level::neighbour_refined(std::size_t I, std::size_t J) const {
  const std::size_t CX = g_.NX - 1, CY = g_.NY - 1;
  return (I > 0 && cell_refined(I - 1, J)) || (I + 1 < CX && cell_refined(I + 1, J)) ||
         (J > 0 && cell_refined(I, J - 1)) || (J + 1 < CY && cell_refined(I, J + 1));
}

void Level::boundary(const Square& q, bool scan, std::vector<std::array<std::size_t, 2>>& nodes) const {
  nodes.clear();
  const std::size_t X = q.X, Y = q.Y, L = q.L;
  const bool inner = scan && L > 1;
  nodes.push_back({X, Y});
  if (inner)
    for (std::size_t a = 1; a < L; ++a)
      if (has_node(X + a, Y)) nodes.push_back({X + a, Y});
  nodes.push_back({X + L, Y});
  if (inner)
    for (std::size_t b = 1; b < L; ++b)
      if (has_node(X + L, Y + b)) nodes.push_back({X + L, Y + b});
  nodes.push_back({X + L, Y + L});
  if (inner)
    for (std::size_t a = L - 1; a >= 1; --a)
      if (has_node(X + a, Y + L)) nodes.push_back({X + a, Y + L});
  nodes.push_back({X, Y + L});
  if (inner)
    for (std::size_t b = L - 1; b >= 1; --b)
      if (has_node(X, Y + b)) nodes.push_back({X, Y + b});
}

int Level::changes(const std::vector<std::array<std::size_t, 2>>& nodes) {
  int n = 0;
  for (std::size_t i = 0, m = nodes.size(); i < m; ++i) {
    const auto& p = nodes[i];
    const auto& r = nodes[(i + 1) % m];
    n += state(p[0], p[1]) != state(r[0], r[1]);
  }
  return n;
}

void Level::refine_cells() {
  const std::size_t NX = g_.NX, CX = NX - 1, CY = g_.NY - 1, k = g_.k;
  tree_of_.assign(CX * CY, -1);
  row_refined_.assign(CY, 0);
  auto make_tree = [&](std::size_t I, std::size_t J) {
    tree_of_[J * CX + I] = static_cast<int32_t>(trees_.size());
    trees_.push_back({Square{I * k, J * k, k}});
    tree_cell_.push_back(J * CX + I);
    ++row_refined_[J];
    ++refined_count_;
    return trees_.size() - 1;
  };
  const double band = cutter_.height(std::min(std::max(g_.dx, g_.dy), cutter_.max_radius()));
  std::vector<std::size_t> cells;  // the cells of the rows within the band, in scan order
  for (std::size_t J = 0; J < CY; ++J) {
    if (z_ - band >= g_.row_hi[J]) continue;  // all free, farther below z than the band
    if (z_ + band <= g_.row_lo[J]) continue;  // all blocked, farther above z than the band
    for (std::size_t I = 0; I < CX; ++I) cells.push_back(J * CX + I);
  }
  // Each cell's squares split while a feature could hide in them, depth first, cells in parallel (fixed
  // chunks, each sampling its own fine nodes: a node on a side shared by two chunks is sampled twice, to the
  // same height), then the trees taken in scan order: the same trees and nodes as one after the other.
  const std::size_t chunk = 16;
  std::vector<std::vector<Square>> grown(cells.size());
  std::vector<std::unordered_map<uint64_t, double>> chunk_fine((cells.size() + chunk - 1) / chunk);
  std::atomic<std::size_t> drops{0}, sampled{0};
  // Cancel (and Ctrl-C) within this phase too; its progress stays at the level's start.
  BatchOptions refine{batch_.threads, {}, batch_.within};
  if (batch_.progress) refine.progress = [&](double) { return batch_.progress(0.0); };
  parallel_chunks(cells.size(), chunk, refine, [&](std::size_t begin, std::size_t end) {
    Probe pr;
    Nodes nd{pr, chunk_fine[begin / chunk], &sampled};
    for (std::size_t c = begin; c < end; ++c) {
      const Square cell{cells[c] % CX * k, cells[c] / CX * k, k};
      if (!split_wanted(cell, nd)) continue;
      std::vector<Square>& tree = grown[c];
      tree.push_back(cell);
      split(tree, 0, nd);
      for (std::size_t i = 0; i < tree.size();) {
        if (split_wanted(tree[i], nd)) split(tree, i, nd);
        else ++i;
      }
    }
    drops += pr.drops;
  });
  worker_drops_ += drops.load();
  for (auto& fine : chunk_fine) {
    fine_.insert(fine.begin(), fine.end());
    fine = {};
  }
  check_fine_nodes(fine_.size());
  for (std::size_t c = 0; c < cells.size(); ++c) {
    if (grown[c].empty()) continue;
    trees_[make_tree(cells[c] % CX, cells[c] / CX)] = std::move(grown[c]);
  }
  // Closure: a square whose boundary (with its smaller neighbours' nodes) changes state more than twice is
  // split, so that every square's loop piece is one segment and both sides of a boundary segment agree.
  std::vector<std::array<std::size_t, 2>> nodes;
  for (bool changed = true; changed;) {
    changed = false;
    for (std::size_t t = 0; t < trees_.size(); ++t)
      for (std::size_t i = 0; i < trees_[t].size();) {
        const Square q = trees_[t][i];
        boundary(q, true, nodes);
        if (q.L > 1 && changes(nodes) > 2) {
          split(t, i);
          changed = true;
        } else {
          ++i;
        }
      }
    const std::size_t trees = trees_.size();
    for (std::size_t t = 0; t < trees; ++t) {
      const std::size_t I0 = tree_cell_[t] % CX, J0 = tree_cell_[t] / CX;
      const std::size_t around[4][2] = {{I0 - 1, J0}, {I0 + 1, J0}, {I0, J0 - 1}, {I0, J0 + 1}};
      for (const auto& c : around) {
        const std::size_t I = c[0], J = c[1];
        if (I >= CX || J >= CY || cell_refined(I, J)) continue;  // (I0 - 1 wraps past CX at 0)
        boundary(Square{I * k, J * k, k}, true, nodes);
        if (changes(nodes) <= 2) continue;
        split(make_tree(I, J), 0);
        changed = true;
      }
    }
  }
}
}  // namespace waterline_detail
}  // namespace tmm
