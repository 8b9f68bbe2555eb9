// Lean passes' arcs (internal to lean_profile.cpp): consecutive moves of a verified lean polyline merged into one
// circular move (or one longer line) in the run's vertical plane where it stays within the same band.
#pragma once

#include <cstddef>
#include <cstdint>
#include <functional>
#include <vector>

namespace tmm::lean {

struct ArcLimits {
  double min_radius = 0.5;      // mm: tighter arcs are a valley's kink rounded, not the path
  double max_radius = 1000.0;   // mm: flatter ones are lines to a controller (and to the post's rounding)
  double max_chord_slope = 1.0;  // arcs only where their chord rises at most 45 deg (a vertical band is thin
                                 // along the normal on steep ground)
};

// The exact CL height at t (hint: the triangle of a neighbouring drop); false where the cutter is in the air.
using ExactAt = std::function<bool(double t, int32_t hint, double& z)>;

// The profile of one stretch: drops (t, e) with their holding triangles, the band e -half .. +half (never below
// `floor` where e is above it), and `near`: how close to the band's edge a move may come at a drop interval's
// midpoint before the exact drop there is checked (against `fail`).
struct Stretch {
  const std::vector<double>& t;
  const std::vector<double>& e;
  const std::vector<int32_t>& win;
  double half, floor, near, fail;
};

// Merges the moves of the polyline (vertex drop indices vi, heights vz) greedily from its start: each merged move
// reaches the farthest vertex an arc (or a line) through both vertices can while staying within the band at every
// drop between, within it (with the arc's own bend between drops) at every drop interval's midpoint and, near the
// band's edge there, within `fail` of the exact drop. Out: vi, vz shortened; ct, cz per vertex: the centre of the
// arc ending there, NaN for a line (ct[0], cz[0] NaN). Returns the arcs made.
std::size_t merge_arcs(const Stretch& p, const ArcLimits& limits, const ExactAt& exact, std::vector<std::size_t>& vi,
                       std::vector<double>& vz, std::vector<double>& ct, std::vector<double>& cz);

}  // namespace tmm::lean
