// Arrival-time field of the "3D offset" passes: a front leaves a start set (the machining
// region's boundary, or a chosen curve) and moves across the CL surface at the speed F = the XY step the cusp
// rule allows there, so that the passes, the level sets {T = k}, lie one local step apart everywhere and stay
// long and smooth (a distance field has no pieces of its own: its level sets split only where the region does).
//
// Fast marching (Sethian's first-order upwind scheme on a square grid, a binary heap of trial nodes). The step
// depends on the direction across the passes (the slope and the concave curvature of the CL surface along
// grad T): each update solves the upwind quadratic, takes the front's direction from that solution and solves
// again with that direction's speed (kDirectionRounds rounds). Where the speed is the same in every direction
// (a plane), the scheme is exact for straight fronts (linear T) and the level sets of the bilinear T are their
// exact offsets; on a curved or sloped surface the passes are spaced to first order in the cell.
#pragma once

#include <cstdint>
#include <vector>

#include "tmm/util/parallel.hpp"

namespace tmm {

struct ArrivalGrid {
  int nx = 0, ny = 0;  // nodes along X and Y; node (i, j) is the index j * nx + i, at (i * cell, j * cell)
  double cell = 0;     // node spacing (mm, > 0)
};

// The cusp rule's step along the front's direction u (unit XY) at a node: steps[k] is the allowed XY step
// (mm) where the CL surface rises across the passes at the angle k * dslope (rad), linear between entries and
// the last entry beyond; divided by sqrt(1 + radius * k) where the CL section along u bends up with curvature
// k (a concave place: two balls leave (1 + R k) times the flat cusp); never below min_step. The slope is the
// larger secant of the two halves of [-probe, +probe] along u, the curvature from the same three heights.
struct StepRuleTable {
  std::vector<double> steps;  // at least one entry, each > 0 (mm)
  double dslope = 0;          // table spacing (rad, > 0)
  double radius = 0;          // the cutter's radius for the concave correction (mm, >= 0)
  double probe = 0;           // half the secant span (mm, > 0)
  double min_step = 0;        // the least step (mm, > 0)
};

constexpr int kDirectionRounds = 3;

// Throws std::invalid_argument naming what is wrong: a grid under 2 x 2 nodes, z not nx ny finite heights, an
// empty table or a value out of its range.
void check_arrival_inputs(const ArrivalGrid& grid, const std::vector<double>& z, const StepRuleTable& rule);

// The step (mm) at grid point (x, y) (mm from node 0) for a front moving along (ux, uy) (normalized here).
double arrival_step(const ArrivalGrid& grid, const std::vector<double>& z, const StepRuleTable& rule, double x,
                    double y, double ux, double uy);

// T at every node (in steps: |grad T| = 1 / F). z: CL heights at the nodes (nx ny); active: nonzero where the
// front may go; start: T of the start band's nodes (finite: fixed), NaN at the others. Nodes the front never
// reaches (inactive or cut off) are +inf. Throws std::invalid_argument on inconsistent sizes or bad values
// (heights and lengths outside the kernel's range included), Cancelled when batch.progress (called from this
// thread, on which it runs: batch.threads is not used) returns false.
std::vector<double> arrival_field(const ArrivalGrid& grid, const std::vector<double>& z,
                                  const std::vector<std::uint8_t>& active, const std::vector<double>& start,
                                  const StepRuleTable& rule, const BatchOptions& batch = {});

}  // namespace tmm
