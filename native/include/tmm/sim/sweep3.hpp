// Exact 3-axis cutting simulation on a z-map: linear moves of a vertical generalized APT cutter lower the
// stock to the lower envelope of the swept tool.
//
// For a move from tip P0 to tip P1 (the tip at constant velocity, t in [0, 1]) a cell centre c within
// max_radius of the XY segment gets z = min(z, m(c)),
//   m(c) = min over t with |c - p(t)| <= max_radius of  z(t) + h(|c - p(t)|).
// With s the along-move XY offset of the tip, u the cell's along-move coordinate and q its distance from
// the move's line, |c - p| = sqrt(v^2 + q^2) for v = s - u, and z(t) is linear in s: the function of v is
// convex (h convex and non-decreasing of a convex distance, plus a linear term), and its free minimiser
// v*(q) depends on q alone. The constrained minimum is at v*(q) clamped to the move ([-u, L - u]).
// v*(q) is solved per profile piece:
//   bottom cone and taper (h' constant k):  v = |m| q / sqrt(k^2 - m^2)      (m = dz / L, the move's slope)
//   corner arc centred on the axis (ball):   v = |m| sqrt(r^2 - q^2) / sqrt(1 + m^2)
//   flat bottom, sharp corners:              the kink or the end of the reach
//   corner arc off the axis (bull-nose, general APT): the stationarity condition squared is a quartic in
//     the arc's offset t = rho - e; safeguarded Newton on it within the arc's bracket, stopped by the
//     convexity certificate |g'(v)| * (bracket width) <= 1e-10 mm.
//
// Error bound: a lowered cell's height is within kSweep3Tolerance (1e-9 mm) above the exact m(c), never
// below it beyond rounding (~1e-12 mm for coordinates of a metre): closed forms are exact up to
// rounding; the arc solve's certificate bounds its excess by 1e-10 mm. A move with an XY length below
// kVerticalLength (1e-12 mm) is a plunge at its start's XY. Tested against a brute force stamping the tool
// at 200000 instants per move (native/tests/sim/test_sweep3.cpp).
//
// Order and threads: the grid is split into bands of rows; each band replays, in move order, the moves
// whose swept footprint meets it, so a rapid sees the stock its predecessors left. Every cell's result
// depends only on its row and the moves, so heights are bit-identical for any thread count and band split.
#pragma once

#include <cstddef>

#include "tmm/cutter/cutter.hpp"
#include "tmm/sim/body_check.hpp"
#include "tmm/sim/sim_report.hpp"
#include "tmm/sim/zmap.hpp"
#include "tmm/util/parallel.hpp"

namespace tmm {

inline constexpr double kSweep3Tolerance = 1e-9;   // mm above the exact envelope, at most
inline constexpr double kVerticalLength = 1e-12;   // mm of XY travel below which a move is a plunge

struct Sweep3Options {
  double collision_tol = 1e-3;  // mm a rapid may remove before it counts as a collision (finite, >= 0)
  std::size_t band_rows = 0;    // rows per parallel band, 0: automatic (results do not depend on it)
  const BodyCheck* body_check = nullptr;  // the bodies above the flutes against the stock; null: no check
};

// tips: n tool tips (x, y, z), row-major n x 3; kinds: n - 1 move kinds (kinds[k] for tips[k] -> tips[k+1];
// may be null when n < 2). Cut and Rapid moves lower the stock; Jump moves are skipped. Collisions: the
// rapids that removed more than options.collision_tol, in move order, with their deepest removal.
// With options.body_check, report.body_collisions holds the bodies' collisions with the stock (body_check.hpp);
// the heights are the same with or without it.
// Throws std::invalid_argument naming the bad input (a non-finite tip and its row, an unknown kind and its
// move, a bad tolerance), before touching the stock; Cancelled when batch.progress returns false (the stock
// is then partly cut).
SimReport cut_3axis(ZMap& stock, const Cutter& cutter, const double* tips, const MoveKind* kinds,
                    std::size_t n, const Sweep3Options& options, const BatchOptions& batch);

}  // namespace tmm
