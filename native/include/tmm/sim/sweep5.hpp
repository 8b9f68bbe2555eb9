// 5-axis cutting simulation on a z-map: a TorusTool moved along a tool path (tip and unit axis per point)
// lowers every cell whose vertical line meets the tool solid to the lowest point of the solid on that line.
// The kernel port of tmm_workbench/core/verify/zmap.py: the same solid, the same closed forms, the same motion.
//
// Tool solid (as zmap.py and tmm::tool_distance): with C = tip + Ri a the torus centre, h the height above the
// centre plane and rho the distance from the axis,
//   RoundInsert  the full torus (major radius Ro, minor Ri) united with the body {h >= 0, rho <= Ro + Ri},
//                an endless half-cylinder (the shank) that also closes the hollow rho < Ro - Ri at h = 0;
//   BullNose     the torus, the flat-bottomed core {rho <= Ro, h >= -Ri} and the same half-cylinder;
//   Ro = 0       a ball of radius Ri (both shapes).
// The lowest point on a vertical line is exact: the torus by the depressed quartic in t (height above C_z)
//   t^4 + P t^2 + Q t + R = 0, P = 2K - 4 Ro^2 (1 - a_z^2), Q = 8 Ro^2 (q.a) a_z, R = K^2 - 4 Ro^2 (|q|^2 - (q.a)^2),
//   K = |q|^2 + Ro^2 - Ri^2, q = (x - C_x, y - C_y, 0),
// solved by Ferrari (resolvent root by Cardano / the trigonometric form, Newton-polished), each root polished
// by 3 clipped Newton steps and kept if it lies within 1e-7 mm of the tube (a line that close counts as
// touching: the tool grown by at most 1e-7 mm). Lines with a candidate within 0.05 mm of the tube but not on
// it (near-tangent lines, rounding in the closed form) are solved again by isolating the real roots between
// the critical points of the quartic (closed-form cubic, safeguarded Newton); zmap.py uses the companion
// matrix' eigenvalues there. In the sweep, where it can be certified, the same lowest root is found faster by
// Newton from the left (the quartic convex and decreasing below the start, so no root or near-tangent minimum
// lies below; started from the tangent at the cell's current height), Ferrari being the general path and
// lowest_on_vertical's. The ball is closed form, the half-cylinders a quadratic clipped by a plane.
//
// Motion (zmap.py's default): between points k and k + 1 the tip moves linearly and the axis by slerp
// (constant angular rate about a_k x a_k+1). A move is cut into n = max(1, ceil((|tip_k+1 - tip_k| + theta
// r_tool) / max_step)) equal steps, theta the angle between the axes and r_tool = hypot(Ro + Ri, 2 Ri) the
// farthest torus point from the tip, so that no torus point moves more than max_step between two instances;
// every instance (both ends of each simulated move included) is stamped into the z-map.
//
// Error bound (the only approximation; everything per instance is exact): a cell is never below the exact
// swept envelope (up to rounding, ~1e-9 mm), and above it by at most the cusp between consecutive instances,
//   s^2 / (8 Ri) / cos(alpha),  s <= max_step the displacement of the cutting point between instances,
// alpha the slope of the machined (swept) surface at the cell: s^2 / (8 Ri) is the cusp of two balls of radius
// Ri a distance s apart, measured along the normal of the surface, exact for a ball moving along a line and
// for the torus' lower part whose curvature radii are >= Ri. It assumes the cell is cut by the torus (the flat
// core leaves no cusp; the shank is not counted in the step: points of the shank far above the tip move more
// when the axis turns) and a moderate slope (the vertical measure is unbounded on the vertical walls at the
// edges of a pass). For max_step = 0.05 and Ri = 6 that is 5.2e-5 mm / cos(alpha). The motion model is
// zmap.py's; a real control interpolating the machine joints differs from it by its nonlinearity error.
//
// Rapids cut too (the machine does), but a rapid that lowers any cell by more than collision_tol (its total
// removal over the move) is a collision, reported with the deepest removal; Jump moves are not simulated.
// Work is split into bands of grid rows, each band processing every instance whose footprint meets it in path
// order, so the result does not depend on the thread count (bit-identical for any number of threads).
#pragma once

#include <Eigen/Core>

#include <cstddef>

#include "tmm/cutter/torus_tool.hpp"
#include "tmm/sim/body_check.hpp"
#include "tmm/sim/sim_report.hpp"
#include "tmm/sim/zmap.hpp"
#include "tmm/util/parallel.hpp"

namespace tmm {

struct Sweep5Options {
  double max_step = 0.05;       // mm: no torus point moves more than this between two stamped instances
  double collision_tol = 1e-3;  // mm: a rapid removing more than this is a collision
  const BodyCheck* body_check = nullptr;  // the bodies above the flutes against the stock; null: no check
};

// Counters of one simulation (for benchmarks and tests).
struct Sweep5Stats {
  std::size_t instances = 0;      // tool instances stamped (over all simulated moves)
  std::size_t cells_tested = 0;   // cell-instance pairs inside an instance's footprint
  std::size_t exact_solves = 0;   // of those, the torus quartics solved (pairs its bounds could not prune)
  std::size_t lowerings = 0;      // cell-instance pairs that lowered the cell
  std::size_t fallback_solves = 0;  // quartics re-solved by root isolation (near-tangent lines)
};

// Lowest z of the tool solid at (tip, axis) on the vertical line through (x, y); +inf when the line misses it.
// axis: unit, a_z > 0 (not checked here: the caller's contract).
double lowest_on_vertical(const TorusTool& tool, const Eigen::Vector3d& tip, const Eigen::Vector3d& axis,
                          double x, double y);

// Cuts the tool path into the stock. tips, axes: n rows of 3 (row-major); axes are normalised here and need
// a_z > 0 (the tool pointing down onto the z-map); kinds: n - 1 moves k -> k + 1 (may be null when n < 2).
// Throws std::invalid_argument naming the offending row or parameter (non-finite tip, zero, non-finite or
// non-upward axis, unknown move kind, max_step not > 0, collision_tol < 0, invalid tool), Cancelled when
// batch.progress returns false. Collisions are sorted by move index. With options.body_check, each instance's
// bodies are tested before it is stamped (body_check.hpp): report.body_collisions; the heights are the same.
SimReport cut_5axis(ZMap& stock, const TorusTool& tool, const double* tips, const double* axes,
                    const MoveKind* kinds, std::size_t n, const Sweep5Options& options, const BatchOptions& batch,
                    Sweep5Stats* stats = nullptr);

}  // namespace tmm
