// Lean passes: along each straight run of a 3-axis raster, the fewest straight moves that stay
// within +-tol of the exact CL path (the drop height profile z(s) along the run).
//
// Per run: (1) the exact profile between the given samples, by adaptive exact drops: an interval is halved while
// it is longer than max_step, while its midpoint leaves the chord of its ends by more than rep_fraction x tol,
// or while the triangle holding the cutter (the drop's winner) differs at its ends and midpoint, down to
// min_step: so every breakpoint of the profile (the cutter leaving a facet for an edge or vertex roll) is
// located to min_step and the polyline through the drops represents the profile within about 2 x rep_fraction
// x tol (a convex or concave stretch leaves its chord by at most twice the midpoint's offset).
// (2) Between vertices that must stay (the ends, both ends of vertical moves, moves kept as sampled), the
// min-link polyline in the band +-fit_fraction x tol about those drops by windows: each move reaches as far as
// any line from the previous move's window of end heights can, then the vertices are placed backwards in the
// middle of what is feasible. (3) Checks: the exact drop at the midpoint of every drop interval where a move
// comes within (1 - fit_fraction) x tol of the band's edge; a move that leaves +-tol there gets the point
// as a drop and its stretch is fitted again (up to `rounds`), else the stretch keeps every drop (a polyline
// within rep_fraction x tol). (4) In runs marked for arcs: consecutive moves merged into one arc (G2/G3 in the
// run's vertical plane) or one longer line where that holds the same band and checks (src/algo/lean_arcs.hpp).
#pragma once

#include <cstddef>
#include <cstdint>
#include <limits>
#include <vector>

#include "tmm/cutter/cutter.hpp"
#include "tmm/mesh/mesh_index.hpp"
#include "tmm/util/parallel.hpp"

namespace tmm {

// The exact CL height as the raster computes it: drop(tool, floor = drop_floor) + z_shift, at least
// clamp_floor; "air" (off-model, skip) where drop + z_shift <= air_below.
struct LeanDrop {
  double drop_floor = -1e6;
  double z_shift = 0.0;
  double clamp_floor = -std::numeric_limits<double>::infinity();
  double air_below = -std::numeric_limits<double>::infinity();
};

struct LeanOptions {
  double tol = 0.001;          // mm: the band about the exact CL path, both ways
  double max_step = 0.05;      // mm: exact drops at least this close along a move
  double min_step = 0.002;     // mm: breakpoints located to this
  double rep_fraction = 0.05;  // of tol: the drops' polyline against the profile (midpoint test)
  double fit_fraction = 0.85;  // of tol: the band the fit uses (the rest, > 2 rep_fraction, covers the profile
                               // between drops)
  int rounds = 4;              // refits after failed checks before a stretch keeps every drop
  bool lower_bound = false;    // also count the least lines any fit within +-tol can use (see below)
  double arc_min_radius = 0.5;     // mm: arcs (runs marked for them) no tighter than this
  double arc_max_radius = 1000.0;  // mm: nor flatter
  double arc_max_slope = 1.0;      // nor where their chord rises more steeply than this
  LeanDrop drop;
};

// Sample flags (per sample of a run).
constexpr std::uint8_t kLeanFixed = 1;  // a vertex that stays, exact
constexpr std::uint8_t kLeanKeep = 2;   // the move to the next sample stays as it is (air, a cliff)

// Runs, flattened: run r holds samples offsets[r] .. offsets[r + 1] - 1 at XY origin + s * dir (dir a unit
// vector), s non-decreasing, z their exact CL heights.
struct LeanRuns {
  std::vector<double> origin, dir;      // 2 per run
  std::vector<std::size_t> offsets;     // runs + 1
  std::vector<double> s, z;
  std::vector<std::uint8_t> flags;
  std::vector<std::uint8_t> arcs;       // per run: 1 fits arcs in its vertical plane (empty: none anywhere)
};

struct LeanResult {
  std::vector<std::size_t> offsets;  // runs + 1, into s / z
  std::vector<double> s, z;          // the vertices of each run (first and last as given)
  std::vector<double> arc_s, arc_z;  // per vertex (with arcs): the centre (s, z) of the arc ending there, NaN for
                                     // a line and at a run's first vertex; empty when no run is marked for arcs
  std::size_t arcs = 0;              // arcs made
  std::size_t drops = 0;             // exact drops made (profile and checks)
  std::size_t breakpoints = 0;       // drop intervals where the triangle holding the cutter changes
  std::size_t refits = 0;            // stretches fitted again after a failed check
  std::size_t kept_dense = 0;        // stretches that kept every drop after `rounds`
  std::size_t lower_bound = 0;       // with options.lower_bound: moves at least, over all runs (see below)
};

// The lean vertices of every run (threaded over runs). Throws std::invalid_argument naming a bad option or a
// malformed run, Cancelled when batch.progress returns false.
// options.lower_bound: the least number of lines any polyline within +-tol of the exact profile can use, taken
// on the drops: each move of such a polyline passes within tol of a run of consecutive drops, so the fewest
// runs of consecutive drops each within tol of one line (greedy, optimal for unconnected lines) bounds it.
LeanResult lean_profiles(const MeshIndex& index, const Cutter& tool, const LeanRuns& runs,
                         const LeanOptions& options, const BatchOptions& batch = {});

// The exact CL height at one point with the winner triangle (hint in, winner out); `air` set when off-model.
double lean_exact(const MeshIndex& index, const Cutter& tool, const LeanDrop& drop, double x, double y,
                  int32_t* hint, bool* air);

}  // namespace tmm
