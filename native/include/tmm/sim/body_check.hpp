// The non-cutting part of the tool (neck, shank, holder pieces: everything above the flutes) checked against
// the stock as the simulation cuts it: at every pose of every move, a cell under a body whose stock height
// comes closer to the body than the body's clearance is a collision.
//
// Geometry: each body is a frustum coaxial with the tool (tmm::ToolBody, tip coordinates) grown by its
// clearance. The lowest point of the grown body on a cell's vertical line is compared with the cell's height
// (the z-map holds no overhangs: material on the line reaches up to the height).
//   vertical tool (3-axis): exact: the grown body is the Minkowski sum with a ball, whose lower envelope over
//     the radial distance is the assembly drop's APT pieces (tmm/query/drop_assembly.hpp);
//   tilted tool (5-axis): conservative: the grown body is replaced by the frusta that enclose it,
//     radius r(h) + c (1 + |dr/dh|) over the body's height range grown by c at both ends (a point within c of
//     the body lies within c of a body point whose height differs by at most c, and the radius changes by at
//     most c |dr/dh| over that), and their lowest point on the vertical line is solved in closed form.
//
// Order within a move: the flutes cut only up to the cutting-edge height (flute_top), so material above it
// can only have been removed by earlier moves or by this move's cutter where it came to the cell first.
//   3-axis: the move is sampled at poses at most `step` apart (3D tip travel); at each pose the cutter is
//     stamped into a scratch copy of the stock before the move, lowering a cell only where its top is within
//     the flutes' reach (below tip + flute_top: the flutes cut from above; a column standing above the flutes
//     stays), and then the bodies are tested against the scratch. Conservative: discrete stamps remove less
//     than the continuous motion, and a column taller than the flutes is kept whole; the bodies are tested
//     at the poses (between two poses a body is at most step / 2 from one of them).
//   5-axis: each sub-step instance's bodies are tested against the stock as the move's earlier instances left
//     it, before the instance itself is stamped (its endless shank would cut what the bodies are tested on).
//     The simulated tool's solid is endless above the torus, so cells its earlier instances passed count as
//     cut even above the flutes (unlike 3-axis); material entered at the leading edge within a body's
//     clearance below it counts.
// A cell stands for the vertical line through its centre (the z-map's own model). Tiles of cells whose height
// bound cannot reach a body, or cannot deepen a piece's worst of the move, are skipped: the depths do not depend
// on it, nor on the threads or bands; among cells of equal depth the one reported may differ with the band split.
// Memory: collisions are aggregated per move and piece (the deepest cell); per band a scratch of its cells.
#pragma once

#include <Eigen/Core>

#include <cstddef>
#include <vector>

#include "tmm/query/drop_assembly.hpp"
#include "tmm/sim/sim_report.hpp"

namespace tmm {

struct BodyCheck {
  std::vector<ToolBody> bodies;  // above the flutes, from the tip up (ToolAssembly's rules)
  double flute_top = 0.0;        // mm above the tip: the flutes cut material only up to here (3-axis)
  double tolerance = 1e-3;       // mm: depths up to this are not collisions
  double step = 0.0;             // mm between 3-axis poses; 0: half a cell
};


// Refuses (std::invalid_argument naming the value) bodies ToolAssembly refuses, a flute_top not finite or
// < 0, a tolerance not finite or < 0, a step not finite or < 0.
void validate(const BodyCheck& check);

// The lowest point on the vertical line through (x, y) of the frustum of axis `a` (unit, a_z > 0) from `tip`:
// heights h in [h0, h1] (h1 > h0) along the axis, radius rad0 at h0 to rad1 at h1 (both >= 0); +inf when the
// line misses it. Closed form (a quadratic), lowered by at most 1e-9 mm against rounding.
double frustum_lowest(const Eigen::Vector3d& tip, const Eigen::Vector3d& a, double h0, double h1, double rad0,
                      double rad1, double x, double y);

// The per (move, piece) deepest collisions of several bands merged (deepest kept), sorted by move, piece.
std::vector<BodyCollision> merge_body_collisions(std::vector<BodyCollision> all);

}  // namespace tmm
