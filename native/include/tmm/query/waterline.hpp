// Exact waterline: at a tip height z, the closed loops of tool positions (x, y) where the cutter touches the
// mesh without gouging. The loops are the boundary of the blocked region F(z) = {(x, y): h(x, y) > z}, h the
// exact drop-cutter tip height (drop_cutter.hpp, any APT cutter; where no triangle lies under the tool the
// point is free).
//
// Method (docs/waterline.md): one grid of drop heights over the bounds, shared by every level, padded with a
// ring of free nodes so that every loop closes; per level marching squares on blocked/free nodes (saddles
// resolved by a drop at the cell centre); each crossing made exact by a bracketed search along its grid edge
// (Illinois on z - h, bisection to finish, since h can jump, e.g. a flat end mill at a vertical wall) to a
// bracket of `bracket` mm, keeping the free end (h <= z: no gouge); then points inserted where the chord
// between two loop points lies farther than `chord_tol` from the exact loop (measured on the perpendicular
// through the chord's midpoint). The blocked region lies on the left of every loop: islands (loops around
// material) run counter-clockwise, pockets clockwise.
//
// Adaptive grid (min_step > 0): per level, grid cells where a feature could hide between their corners are
// split into quarters, recursively, down to sample_step / k (k a power of two, that step <= min_step):
// saddles; squares with a corner within the cutter's lift over the square (h(side), h the profile) of z,
// all-free ones only where triangles can hold the tool above z (a blocked piece that reaches no corner
// comes from mesh points less than that lift above z, next to such a corner); all-blocked ones within a
// ball's lift over twice the side above z (pockets: a heuristic), or, for grid cells, when the cubic
// through the 4 x 4 nodes around dips that close to z. Then squares whose boundary (with smaller
// neighbours' nodes) changes state more than twice are split until none does, so that neighbouring loop
// pieces meet on the same boundary segment (docs/waterline.md, "Adaptive grid").
#pragma once

#include <cstddef>
#include <cstdint>
#include <vector>

#include "tmm/cutter/cutter.hpp"
#include "tmm/mesh/mesh_index.hpp"
#include "tmm/util/parallel.hpp"

namespace tmm {

struct WaterlineOptions {
  double xmin = 0, ymin = 0, xmax = 0, ymax = 0;  // bounds of the tip positions (mm)
  double sample_step = 0;       // grid spacing (mm, > 0): features narrower than this may be missed
  double chord_tol = 0.01;      // largest distance of a chord from the exact loop (mm, > 0)
  double bracket = 1e-7;        // width of the bracket of every exact crossing (mm)
  double min_segment = 1e-4;    // chords shorter than this are not split further (sharp corners)
  int max_depth = 16;           // splits of one grid chord at most
  double min_step = 0;          // adaptive grid: the finest cell (mm); 0: one uniform grid (no refinement)
};

// The largest drop grid the kernel accepts (nodes, padding included): about 1.6 GB of heights.
constexpr std::size_t kMaxWaterlineGridNodes = 200'000'000;
// The most fine nodes one level's refinement may sample (about 100 MB of states); more throws.
constexpr std::size_t kMaxWaterlineFineNodes = 4'000'000;

struct WaterlineLoop {
  double z = 0;
  std::vector<double> xy;         // x0, y0, x1, y1, ...; closed implicitly (the first point not repeated)
  std::vector<uint8_t> contact;   // per point: 1 an exact contact, 0 on the bounds' edge (blocked beyond)
  std::size_t size() const { return contact.size(); }
  double area() const;            // signed (shoelace): > 0 counter-clockwise (an island)
};

struct WaterlineStats {
  std::size_t grid_nodes = 0;   // drops of the shared grid
  std::size_t drops = 0;        // drops of the levels (crossings, saddles, refinement)
  std::size_t refined_cells = 0;  // coarse cells sampled again on the fine lattice, over all levels
};

// The grid's node counts along X and Y (bounds included, padding excluded) for these options; throws
// std::invalid_argument on empty or non-finite bounds, a step <= 0 or a grid above kMaxWaterlineGridNodes.
void waterline_grid_size(const WaterlineOptions& options, std::size_t& nx, std::size_t& ny);

// The loops of each level zs[k] (result[k]), in a fixed order: the same for any thread count. Levels are
// computed in parallel on batch.threads threads; batch.progress is called with the fraction done (false
// cancels: throws Cancelled). Throws std::invalid_argument on bad options or a non-finite z.
std::vector<std::vector<WaterlineLoop>> waterline(const MeshIndex& index, const Cutter& cutter,
                                                  const std::vector<double>& zs, const WaterlineOptions& options,
                                                  const BatchOptions& batch, WaterlineStats* stats = nullptr);

}  // namespace tmm
