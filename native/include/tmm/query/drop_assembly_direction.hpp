// Drop of the whole tool assembly along any direction V with the tool axis in any fixed orientation: the tool
// (cutter, then the bodies above it, each grown by its clearance) translated with its tip at start + t V from
// t = -inf; the travel of the first contact of any piece is returned (as drop_along_point for the cutter).
//
// Along its own axis (V = -axis) only the pieces' lower envelopes meet the mesh: that is drop_assembly in the
// frame where V = -Z (the same heights, each piece a column upward). Along any other direction the whole grown
// solids count. A body grown by c is convex and of revolution; cut at its widest section it falls into convex
// solids each of the drop_direction form {h(rho) <= z <= L_C} (an APT profile with a flat top), some of them
// upside down (their axis is -axis):
//   from the narrow end to the wide one: the APT cutter with a flat bottom (the narrow radius), corner c and
//     the side offset by c (the pieces of the vertical drop), then the wide rim's ball up to the wide end's
//     plane (a bull-nose of radius r + c, corner c, height c);
//   beyond the wide end: the wide disc grown by c, the same bull-nose upside down.
// A cylinder's narrow end is its bottom (the rounded rim low, where the part is met, and the seam to the top
// disc far from it; the top disc is often covered by the body sitting on it), unless only its bottom disc is
// covered.
// The cutter is the cutter solid of drop_direction (with a clearance: grown alike); an endless cutter is cut
// at the first body's z0 (the bodies sit on it). Above the last body nothing is modelled. The union of the
// solids is the grown assembly exactly; the first contact of a union is the earliest of its solids'.
#pragma once

#include <cstddef>
#include <cstdint>
#include <vector>

#include <Eigen/Core>

#include "tmm/query/drop_assembly.hpp"
#include "tmm/query/drop_direction.hpp"

namespace tmm {

// One convex solid of the grown assembly: `profile` (finite cutting length) with its tip `lift` along the
// tool axis from the tool's tip, pointing along the axis or, `flipped`, against it.
struct AssemblySolid {
  Cutter profile;
  double lift;
  bool flipped;
  int32_t owner;  // kSetByCutter or the body's position
};

// The solids, the cutter's first then each body's. Throws std::invalid_argument for an endless cutter with no
// body above it, or a cut the APT profile refuses (named).
std::vector<AssemblySolid> assembly_solids(const ToolAssembly& tool);

// One start: the smallest travel of a contact of any piece, capped at max_travel (returned, with set_by
// kSetByFloor, when nothing is touched before it). set_by (may be null): kSetByCutter or the body. With
// axis = -V exactly drop_assembly_point in the frame where V = -Z (travel = start height - tip height).
double drop_assembly_along_point(const DirectionalIndex& index, const ToolAssembly& tool, const Eigen::Vector3d& start,
                                 const Eigen::Vector3d& axis, double max_travel = kNoTravel,
                                 int32_t* set_by = nullptr, DropStats* stats = nullptr);

// starts: n points (x, y, z, ...); axes: one unit axis (axes_per_point = false) or n; travel_out: n; set_by
// (may be null): n codes as above. With one axis = -V: drop_assembly_batch in the rotated frame, each point's
// floor max_travel below its start. Threads, progress and cancel (Cancelled) as drop_batch.
void drop_assembly_along_batch(const DirectionalIndex& index, const ToolAssembly& tool, const double* starts,
                               const double* axes, bool axes_per_point, std::size_t n, double max_travel,
                               double* travel_out, int32_t* set_by, const BatchOptions& options,
                               DropStats* stats = nullptr);

}  // namespace tmm
