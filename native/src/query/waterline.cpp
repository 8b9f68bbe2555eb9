#include "tmm/query/waterline.hpp"

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

#include "tmm/query/drop_cutter.hpp"
#include "tmm/util/bracket_1d.hpp"
#include "tmm/util/range.hpp"

namespace tmm {

double WaterlineLoop::area() const {
  const std::size_t n = size();
  double a = 0;
  for (std::size_t i = 0, j = n - 1; i < n; j = i++) a += xy[2 * j] * xy[2 * i + 1] - xy[2 * i] * xy[2 * j + 1];
  return 0.5 * a;
}

namespace {

constexpr int kIllinoisSteps = 16;  // then bisection: h can jump (a flat end mill at a vertical wall)
// The level's drop tiles (DropTiles) are this many cutter radii wide: their lists hold the triangles within a
// radius of the tile, so smaller tiles scan fewer candidates per drop but gather more lists (0.25-1.5
// measured on sphere_on_plate.stl: 0.5 the fewest instructions).
constexpr double kTileFactor = 0.5;

void check_options(const WaterlineOptions& o) {
  auto fail = [](const char* what, double v, const char* allowed) {
    std::ostringstream msg;
    msg << "waterline " << what << " must be " << allowed << ", got " << v;
    throw std::invalid_argument(msg.str());
  };
  for (double v : {o.xmin, o.ymin, o.xmax, o.ymax})
    if (!std::isfinite(v)) fail("bounds", v, "finite");
  require_in_range(o.xmin, "waterline bounds xmin");
  require_in_range(o.ymin, "waterline bounds ymin");
  require_in_range(o.xmax, "waterline bounds xmax");
  require_in_range(o.ymax, "waterline bounds ymax");
  if (!(o.xmax > o.xmin)) fail("bounds xmax", o.xmax, "> xmin");
  if (!(o.ymax > o.ymin)) fail("bounds ymax", o.ymax, "> ymin");
  if (!(o.sample_step > 0 && std::isfinite(o.sample_step))) fail("sample step", o.sample_step, "> 0 (mm)");
  if (!(o.chord_tol > 0 && std::isfinite(o.chord_tol))) fail("chord tolerance", o.chord_tol, "> 0 (mm)");
  if (!(o.bracket > 0 && o.bracket < 0.5 * o.chord_tol)) fail("bracket", o.bracket, "in (0, chord tolerance / 2)");
  if (!(o.min_segment > 0 && std::isfinite(o.min_segment))) fail("minimum segment", o.min_segment, "> 0 (mm)");
  if (o.max_depth < 0 || o.max_depth > 64) fail("maximum depth", o.max_depth, "in [0, 64]");
  if (!(o.min_step >= 0 && std::isfinite(o.min_step))) fail("minimum step", o.min_step, ">= 0 (mm; 0: no refinement)");
  if (o.min_step > 0 && !(o.min_step >= o.sample_step / 256.0))
    fail("minimum step", o.min_step, ">= sample step / 256 (mm)");
}

std::size_t nodes_along(double width, double step) {
  const double cells = std::ceil(width / step - 1e-9);
  if (!(cells < 1e9)) return std::numeric_limits<std::size_t>::max();
  return std::max<std::size_t>(2, static_cast<std::size_t>(cells) + 1);
}

struct Point {
  double x, y;
  bool contact;
};

// The shared grid of drop heights, padded by one ring of free nodes (height -inf).
struct Grid {
  std::size_t NX = 0, NY = 0;  // padded node counts
  double x0 = 0, y0 = 0;       // position of padded node (1, 1), the bounds' corner
  double dx = 0, dy = 0;
  std::vector<double> h;       // NX * NY heights
  std::vector<double> row_lo, row_hi;  // per cell row J: lowest and highest height of rows J and J + 1
  // Adaptive grid: cells refined are split down to a lattice k times finer (k = 1: no refinement).
  std::size_t k = 1;

  double x(std::size_t I) const { return x0 + (static_cast<double>(I) - 1.0) * dx; }
  double y(std::size_t J) const { return y0 + (static_cast<double>(J) - 1.0) * dy; }
  bool ring(std::size_t I, std::size_t J) const { return I == 0 || J == 0 || I + 1 == NX || J + 1 == NY; }
};

// How far above a level the Illinois search keeps drop heights exact (the span it brackets below z); higher
// ones are capped there (the drop stops at the first contact above).
double height_margin(const Cutter& cutter, const Grid& g) {
  return 2.0 * std::max({cutter.max_radius(), g.dx, g.dy}) + cutter.height(cutter.max_radius());
}

// How far above the highest level the grid's heights are exact, higher ones capped there: above every band of
// split_wanted (the lift h(side) <= h(2 side), the pocket band <= max(that, 2 side), the sagitta of a chord 2
// side long at most that long), so every split decision but the cubic's sees the same.
double grid_margin(const Cutter& cutter, const Grid& g) {
  const double side = std::max(g.dx, g.dy);
  return 2.0 * side + cutter.height(std::min(2.0 * side, cutter.max_radius()));
}

// One level: marching squares, exact crossings, loops, refinement. Drops from one thread, with hints.
class Level {
 public:
  // batch: the threads (and progress, cancel) of the crossings and chords within this level.
  Level(const MeshIndex& index, const Cutter& cutter, const Grid& grid, const WaterlineOptions& o, double z,
        const BatchOptions& batch)
      : index_(index), cutter_(cutter), g_(grid), o_(o), batch_(batch), z_(z),
        eval_floor_(z - 2.0 * std::max({cutter.max_radius(), grid.dx, grid.dy})),
        eval_ceiling_(z + height_margin(cutter, grid)), node_margin_(grid_margin(cutter, grid)),
        // The level's drops lie within the bounds or a grid step beyond (a walk past a chord can go a little
        // farther: drop_point then), none with a floor below the lowest of the three above.
        tiles_(index, cutter, o.xmin - grid.dx, o.ymin - grid.dy, o.xmax + grid.dx, o.ymax + grid.dy,
               kTileFactor * cutter.max_radius(), std::min(eval_floor_, z - node_margin_)) {}

  std::vector<WaterlineLoop> loops();
  std::size_t drops() const { return main_.drops + worker_drops_; }
  std::size_t refined_cells() const { return refined_count_; }

 private:
  // Drops go through a probe, one per thread: its count and its hint, the last triangle that held the tool
  // (kept across free drops, which have none: the next blocked test then mostly ends at that triangle).
  struct Probe {
    int32_t hint = -1;
    std::size_t drops = 0;
  };
  // The height with the floor and ceiling of drop_point, from the level's tiles.
  double drop(Probe& pr, double x, double y, double floor, double ceiling) const {
    ++pr.drops;
    int32_t winner = pr.hint;
    const double h = tiles_.drop(x, y, floor, &winner, ceiling);
    if (winner >= 0) pr.hint = winner;
    return h;
  }
  // (The drop stops at the first contact above z: only the state is asked.)
  bool blocked(Probe& pr, double x, double y) const { return drop(pr, x, y, z_, z_) > z_; }
  // z - h, h clamped to a floor below z (Illinois needs finite values where nothing is under the tool) and to
  // a ceiling above it (the drop stops at the first contact above; every band test stays below it).
  double clearance(Probe& pr, double x, double y) const {
    return z_ - std::min(drop(pr, x, y, eval_floor_, eval_ceiling_), eval_ceiling_);
  }
  // A fine node's height, exact within grid_margin of z and clamped to that window (every split band lies
  // inside it; Illinois takes any clamped value): the drop prunes and stops early outside it.
  double node_drop(Probe& pr, double x, double y) const {
    const double cap = z_ + node_margin_;
    return std::min(drop(pr, x, y, z_ - node_margin_, cap), cap);
  }
  // Where fine nodes are sampled: the level's own (fine_, main_) or, while cells grow in parallel, a chunk's.
  struct Nodes {
    Probe& pr;
    std::unordered_map<uint64_t, double>& fine;
    std::atomic<std::size_t>* sampled = nullptr;  // in parallel: the nodes all chunks sampled (the limit)
  };
  // The boundary on the segment from a free point f (clearance cf >= 0) to a blocked point b (cb < 0): the
  // free end of a bracket narrower than o_.bracket.
  Point crossing(Probe& pr, Point f, Point b, double cf, double cb) const;
  Point edge_crossing(Probe& pr, uint64_t edge) const;
  double node_height(std::size_t X, std::size_t Y) const;  // at a node of the level (fine nodes sampled)

  // The lattice k = g_.k times finer than the grid (k = 1: the grid). Node (X, Y) lies at grid (X / k, Y / k).
  // A square (X, Y, L): lower-left node and side in lattice steps; a coarse cell is a square of side k.
  // Edge keys: the boundary segment from node (X, Y) along X (vertical = 0) or Y, L steps long, between two
  // consecutive nodes of the squares on both sides (so both see the same key).
  struct Square {
    std::size_t X, Y, L;
  };
  static constexpr uint64_t kLengths = 512;  // L <= 256
  uint64_t NXf() const { return static_cast<uint64_t>((g_.NX - 1) * g_.k + 1); }
  uint64_t node_id(std::size_t X, std::size_t Y) const { return static_cast<uint64_t>(Y) * NXf() + X; }
  uint64_t key(std::size_t X, std::size_t Y, bool vertical, std::size_t L) const {
    return (node_id(X, Y) * 2 + (vertical ? 1 : 0)) * kLengths + L;
  }
  double fx(std::size_t X) const { return g_.x0 + (static_cast<double>(X) / static_cast<double>(g_.k) - 1.0) * g_.dx; }
  double fy(std::size_t Y) const { return g_.y0 + (static_cast<double>(Y) / static_cast<double>(g_.k) - 1.0) * g_.dy; }
  bool fine_ring(std::size_t X, std::size_t Y) const {
    const std::size_t k = g_.k;
    return X < k || Y < k || X > (g_.NX - 2) * k || Y > (g_.NY - 2) * k;
  }
  bool coarse_node(std::size_t X, std::size_t Y) const { return X % g_.k == 0 && Y % g_.k == 0; }
  // A node is a corner of some square of the level: every grid node, and the fine nodes of refined cells.
  bool has_node(std::size_t X, std::size_t Y) const { return coarse_node(X, Y) || fine_.count(node_id(X, Y)); }
  double height(std::size_t X, std::size_t Y, Nodes& nd) const;  // drop height at a node (ring nodes -inf)
  double height(std::size_t X, std::size_t Y) {
    Nodes nd{main_, fine_};
    return height(X, Y, nd);
  }
  void add_node(std::size_t X, std::size_t Y, Nodes& nd) const;  // samples a fine node, once
  bool state(std::size_t X, std::size_t Y) { return height(X, Y) > z_; }
  // Whether a triangle can hold the tool above z somewhere over the rectangle (the drop's own pruning).
  bool may_block(double x0, double y0, double x1, double y1) const;
  // The range of the cubic through the grid's 4 x 4 nodes around cell (I, J), sampled inside the cell, or a
  // bound of it that lies wholly outside (below, above) (then the samples are not needed); false next to the
  // ring.
  bool cubic_range(std::size_t I, std::size_t J, double below, double above, double& lo, double& hi) const;
  // Whether one triangle above z lies under the whole rectangle (then every position in it is blocked).
  bool under_one_triangle(double x0, double y0, double x1, double y1) const;
  // Whether a square could hide a feature between its corners (docs/waterline.md, "Adaptive grid").
  bool split_wanted(const Square& q, Nodes& nd) const;
  // Replaces leaf i of cell tree t by its four quarters (appended after it in order).
  void split(std::vector<Square>& tree, std::size_t i, Nodes& nd) const;
  void split(std::size_t t, std::size_t i) {
    Nodes nd{main_, fine_};
    split(trees_[t], i, nd);
  }
  void check_fine_nodes(std::size_t n) const;  // throws above kMaxWaterlineFineNodes
  void refine_cells();
  // The nodes on a square's boundary, counter-clockwise from its lower-left corner: its corners and, with
  // `scan`, the nodes of smaller neighbouring squares on its sides.
  void boundary(const Square& q, bool scan, std::vector<std::array<std::size_t, 2>>& nodes) const;
  int changes(const std::vector<std::array<std::size_t, 2>>& nodes);
  // Marching squares on one square (its boundary nodes): segments from each blocked -> free boundary segment
  // to a free -> blocked one; with four or more, the centre decides which pair (a saddle).
  void march(const Square& q, const std::vector<std::array<std::size_t, 2>>& nodes);
  bool neighbour_refined(std::size_t I, std::size_t J) const;
  bool cell_refined(std::size_t I, std::size_t J) const {
    return !tree_of_.empty() && tree_of_[J * (g_.NX - 1) + I] >= 0;
  }
  // Whether the exact loop crosses the perpendicular through p + t (q - p) farther than 3/4 chord_tol from the
  // chord (within reach, inside the bounds); c: that crossing.
  bool off_chord(Probe& pr, const Point& p, const Point& q, double t, Point& c) const;
  // The first change of state along m + s (ux, uy), sampled at s = 3/4 chord_tol, then doubling up to
  // `length`, then in steps of `length` (at least the finest square) up to a grid step: whether it lies beyond
  // the first sample (within reach, inside the bounds); c: its exact crossing.
  bool walk(Probe& pr, const Point& m, bool m_blocked, double ux, double uy, double length, Point& c) const;
  // Refines chord p -> q; u and w: the loop's points before p and after q (the directions it arrives and leaves).
  void refine(Probe& pr, const Point& u, const Point& p, const Point& q, const Point& w, int depth,
              std::vector<Point>& out) const;

  const MeshIndex& index_;
  const Cutter& cutter_;
  const Grid& g_;
  const WaterlineOptions& o_;
  const BatchOptions& batch_;
  const double z_, eval_floor_, eval_ceiling_, node_margin_;
  const DropTiles tiles_;  // the level's drops: tiles of the triangles above its lowest floor
  Probe main_;                   // the marching's drops (this thread)
  std::size_t worker_drops_ = 0;  // the crossings' and chords' drops (parallel within the level)
  std::unordered_map<uint64_t, double> fine_;   // drop heights of the fine nodes (not grid nodes)
  std::vector<int32_t> tree_of_;                 // per coarse cell: its tree in trees_, -1 if not refined
  std::vector<std::vector<Square>> trees_;       // the leaves of each refined cell
  std::vector<std::size_t> tree_cell_;           // the cell of each tree
  std::vector<std::size_t> row_refined_;         // refined cells per cell row
  std::size_t refined_count_ = 0;
  std::unordered_map<uint64_t, uint64_t> next_;  // marching segments, blocked on the left: edge -> edge
  std::vector<uint64_t> starts_;                 // their start edges in scan order (the loops' order)
};

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

std::vector<WaterlineLoop> Level::loops() {
  const std::size_t NX = g_.NX, NY = g_.NY, k = g_.k;
  if (k > 1) refine_cells();
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
  const auto& next = next_;
  const auto& starts = starts_;
  // The loops' edges in order, then their exact crossings and their chords' refinement, each item on its
  // own (fixed chunks: the same points for any thread count; batch_ may cancel within the level).
  std::vector<std::vector<uint64_t>> chains;
  std::unordered_map<uint64_t, bool> done;
  done.reserve(starts.size());
  std::size_t total = 0;
  for (uint64_t first : starts) {
    if (done.count(first)) continue;
    std::vector<uint64_t> chain;
    for (uint64_t e = first;;) {
      done.emplace(e, true);
      chain.push_back(e);
      e = next.at(e);
      if (e == first) break;
    }
    total += chain.size();
    chains.push_back(std::move(chain));
  }
  std::vector<uint64_t> edges;
  edges.reserve(total);
  for (const auto& chain : chains) edges.insert(edges.end(), chain.begin(), chain.end());
  std::vector<Point> crossings(total);
  std::atomic<std::size_t> worker_drops{0};
  const std::size_t work_chunk = 8;
  // Progress: the crossings the first half of the level, the chords the second.
  BatchOptions first_half{batch_.threads, {}, batch_.within}, second_half{batch_.threads, {}, batch_.within};
  if (batch_.progress) {
    first_half.progress = [&](double f) { return batch_.progress(0.5 * f); };
    second_half.progress = [&](double f) { return batch_.progress(0.5 + 0.5 * f); };
  }
  parallel_chunks(total, work_chunk, first_half, [&](std::size_t begin, std::size_t end) {
    Probe pr;
    for (std::size_t i = begin; i < end; ++i) crossings[i] = edge_crossing(pr, edges[i]);
    worker_drops += pr.drops;
  });
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
  // Chords: (loop, point) pairs; each refined into its own list of inserted points.
  std::vector<std::pair<std::size_t, std::size_t>> chords;
  for (std::size_t l = 0; l < loops_pts.size(); ++l)
    for (std::size_t i = 0; i < loops_pts[l].size(); ++i) chords.emplace_back(l, i);
  std::vector<std::vector<Point>> inserted(chords.size());
  parallel_chunks(chords.size(), work_chunk, second_half, [&](std::size_t begin, std::size_t end) {
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

}  // namespace

void waterline_grid_size(const WaterlineOptions& options, std::size_t& nx, std::size_t& ny) {
  check_options(options);
  nx = nodes_along(options.xmax - options.xmin, options.sample_step);
  ny = nodes_along(options.ymax - options.ymin, options.sample_step);
  const double padded = (static_cast<double>(nx) + 2.0) * (static_cast<double>(ny) + 2.0);
  if (padded > static_cast<double>(kMaxWaterlineGridNodes)) {
    std::ostringstream msg;
    msg << "waterline sample step " << options.sample_step << " mm over " << options.xmax - options.xmin << " x "
        << options.ymax - options.ymin << " mm gives a drop grid of " << padded << " nodes, more than the "
        << "kernel's limit of " << kMaxWaterlineGridNodes << "; use a larger sample step or smaller bounds";
    throw std::invalid_argument(msg.str());
  }
}

std::vector<std::vector<WaterlineLoop>> waterline(const MeshIndex& index, const Cutter& cutter,
                                                  const std::vector<double>& zs, const WaterlineOptions& o,
                                                  const BatchOptions& batch, WaterlineStats* stats) {
  std::size_t nx = 0, ny = 0;
  waterline_grid_size(o, nx, ny);
  double zlow = kInf, zhigh = -kInf;
  for (double z : zs) {
    if (!std::isfinite(z)) {
      std::ostringstream msg;
      msg << "waterline level z must be finite, got " << z;
      throw std::invalid_argument(msg.str());
    }
    require_in_range(z, "waterline level z");
    zlow = std::min(zlow, z);
    zhigh = std::max(zhigh, z);
  }
  std::vector<std::vector<WaterlineLoop>> result(zs.size());
  if (zs.empty()) return result;

  Grid g;
  g.NX = nx + 2;
  g.NY = ny + 2;
  g.x0 = o.xmin;
  g.y0 = o.ymin;
  g.dx = (o.xmax - o.xmin) / static_cast<double>(nx - 1);
  g.dy = (o.ymax - o.ymin) / static_cast<double>(ny - 1);
  if (o.min_step > 0) {
    const double cell = std::max(g.dx, g.dy);
    while (cell / static_cast<double>(g.k) > o.min_step && g.k < 256) g.k *= 2;
  }
  // Progress: the grid's share of the work by a rough count of drops (a level costs some 30 drops per
  // crossing, a few crossings per grid line).
  const double grid_work = static_cast<double>(nx * ny);
  const double level_work = static_cast<double>(zs.size()) * 60.0 * static_cast<double>(nx + ny);
  const double grid_share = grid_work / (grid_work + level_work);
  BatchOptions grid_batch{batch.threads, {}};
  if (batch.progress)
    grid_batch.progress = [&](double f) { return batch.progress(f * grid_share); };
  {
    std::vector<double> xy(2 * nx * ny), z(nx * ny);
    for (std::size_t j = 0; j < ny; ++j)
      for (std::size_t i = 0; i < nx; ++i) {
        xy[2 * (j * nx + i)] = g.x(i + 1);
        xy[2 * (j * nx + i) + 1] = g.y(j + 1);
      }
    // Any floor below the lowest level: a height at the floor is free at every level.
    // Heights far above the highest level are capped (the scan stops at the first contact above): they only
    // say "blocked" to every level and every band test (docs/waterline.md, "Adaptive grid").
    drop_batch_capped(index, cutter, xy.data(), nx * ny, zlow - 1.0, zhigh + grid_margin(cutter, g), z.data(),
                      grid_batch);
    g.h.assign(g.NX * g.NY, -kInf);
    for (std::size_t j = 0; j < ny; ++j)
      std::copy(z.begin() + j * nx, z.begin() + (j + 1) * nx, g.h.begin() + (j + 1) * g.NX + 1);
  }
  g.row_lo.assign(g.NY - 1, kInf);
  g.row_hi.assign(g.NY - 1, -kInf);
  for (std::size_t J = 0; J + 1 < g.NY; ++J) {
    for (std::size_t I = 0; I < g.NX; ++I) {
      for (std::size_t r : {J, J + 1}) {
        g.row_lo[J] = std::min(g.row_lo[J], g.h[r * g.NX + I]);
        g.row_hi[J] = std::max(g.row_hi[J], g.h[r * g.NX + I]);
      }
    }
  }

  std::atomic<std::size_t> drops{0}, refined{0};
  BatchOptions level_batch{batch.threads, {}};
  if (batch.progress)
    level_batch.progress = [&](double f) { return batch.progress(grid_share + f * (1.0 - grid_share)); };
  // Fewer levels than threads: the levels one after the other, each on all threads (its crossings and chords;
  // progress and cancel within the level). Otherwise the levels in parallel, each on one thread.
  const unsigned hardware = std::max(1u, std::thread::hardware_concurrency());
  const std::size_t threads = batch.threads > 0 ? static_cast<std::size_t>(batch.threads) : hardware;
  if (zs.size() < threads) {
    for (std::size_t k = 0; k < zs.size(); ++k) {
      BatchOptions inner{batch.threads, {}};
      if (batch.progress) {
        const double n = static_cast<double>(zs.size());
        inner.progress = [&, k, n](double f) {
          return batch.progress(grid_share + (static_cast<double>(k) + f) / n * (1.0 - grid_share));
        };
        if (!batch.progress(grid_share + static_cast<double>(k) / n * (1.0 - grid_share))) throw Cancelled();
      }
      Level level(index, cutter, g, o, zs[k], inner);
      result[k] = level.loops();
      drops += level.drops();
      refined += level.refined_cells();
    }
  } else {
    parallel_chunks(zs.size(), 1, level_batch, [&](std::size_t begin, std::size_t end, ChunkContext& ctx) {
      const BatchOptions one{1, {}, &ctx};  // a level stops within itself when the batch stops
      for (std::size_t k = begin; k < end; ++k) {
        Level level(index, cutter, g, o, zs[k], one);
        result[k] = level.loops();
        drops += level.drops();
        refined += level.refined_cells();
      }
    });
  }
  if (stats) {
    stats->grid_nodes = nx * ny;
    stats->drops = drops.load();
    stats->refined_cells = refined.load();
  }
  return result;
}

}  // namespace tmm
