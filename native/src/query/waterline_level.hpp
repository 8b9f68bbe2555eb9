// The waterline's one level (internal to src/query): its shared grid of drop heights and the Level that turns
// it into loops. Split by the algorithm's stages: waterline_cells.cpp holds the grid side (node heights, the
// adaptive cells, the exact crossing on an edge), waterline_loops.cpp the loop side (marching squares,
// chaining, chord refinement); waterline.cpp samples the grid and runs the levels.
#pragma once

#include <algorithm>
#include <array>
#include <atomic>
#include <cstddef>
#include <cstdint>
#include <unordered_map>
#include <vector>

#include "tmm/query/drop_cutter.hpp"
#include "tmm/query/waterline.hpp"

namespace tmm {
namespace waterline_detail {

inline constexpr int kIllinoisSteps = 16;  // then bisection: h can jump (a flat end mill at a vertical wall)
// The level's drop tiles (DropTiles) are this many cutter radii wide: their lists hold the triangles within a
// radius of the tile, so smaller tiles scan fewer candidates per drop but gather more lists (0.25-1.5
// measured on sphere_on_plate.stl: 0.5 the fewest instructions).
inline constexpr double kTileFactor = 0.5;

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
inline double height_margin(const Cutter& cutter, const Grid& g) {
  return 2.0 * std::max({cutter.max_radius(), g.dx, g.dy}) + cutter.height(cutter.max_radius());
}

// How far above the highest level the grid's heights are exact, higher ones capped there: above every band of
// split_wanted (the lift h(side) <= h(2 side), the pocket band <= max(that, 2 side), the sagitta of a chord 2
// side long at most that long), so every split decision but the cubic's sees the same.
inline double grid_margin(const Cutter& cutter, const Grid& g) {
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
  // The steps of loops(): marching squares over every cell (segments into next_, starts_), the segments
  // chained into loops of edges, the edges' exact crossings (duplicates merged), the chords refined, and the
  // loops with their inserted points.
  void march_cells();
  std::vector<std::vector<uint64_t>> chain_edges() const;
  std::vector<std::vector<Point>> loop_points(const std::vector<std::vector<uint64_t>>& chains,
                                              const BatchOptions& batch);
  std::vector<std::vector<Point>> refine_chords(const std::vector<std::vector<Point>>& loops_pts,
                                                const BatchOptions& batch);
  std::vector<WaterlineLoop> assemble(const std::vector<std::vector<Point>>& loops_pts,
                                      const std::vector<std::vector<Point>>& inserted) const;
  static constexpr std::size_t kWorkChunk = 8;  // crossings or chords per chunk (fixed: thread-independent)

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

}  // namespace waterline_detail
}  // namespace tmm
