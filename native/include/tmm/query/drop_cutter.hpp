// Drop-cutter along -Z: for each (x, y), the lowest tip height at which the cutter touches the mesh without
// penetrating it (the highest of all vertex, edge and facet contacts), never below a floor.
#pragma once

#include <cstddef>
#include <functional>
#include <limits>
#include <stdexcept>

#include "tmm/cutter/cutter.hpp"
#include "tmm/mesh/mesh_index.hpp"
#include "tmm/util/parallel.hpp"

namespace tmm {

struct DropStats {
  std::size_t triangles_tested = 0;  // triangles whose contacts were computed
};

// One point. `stats` may be null. `hint`, if given, is the position in index.triangles() of a triangle
// likely to hold the cutter (the previous point's winner): tested first, its contact is a true lower
// bound that prunes most of the walk; on return it holds this point's winner (or -1).
// `ceiling`: the walk stops at the first contact above it, returned as found (> ceiling, not the height):
// callers that only ask whether the height exceeds a value (a waterline's blocked test) stop early.
double drop_point(const MeshIndex& index, const Cutter& cutter, double x, double y, double floor_z,
                  DropStats* stats = nullptr, int32_t* hint = nullptr,
                  double ceiling = std::numeric_limits<double>::infinity());

// Exact contact of the cutter with one triangle (max of facet, edge and vertex contacts), or -inf. With
// `above`, only a contact higher than it is computed (the rest is pruned by cheap bounds) and returned.
double drop_on_triangle(const Cutter& cutter, double x, double y, const IndexedTriangle& t,
                        double above = -std::numeric_limits<double>::infinity());

// xy: n points (x0, y0, x1, y1, ...); z_out: n tip heights. Throws Cancelled if progress returns false.
void drop_batch(const MeshIndex& index, const Cutter& cutter, const double* xy, std::size_t n,
                double floor_z, double* z_out, const BatchOptions& options,
                DropStats* stats = nullptr);

// As above, but each point's scan stops at its first contact above `ceiling` and reports `ceiling` there:
// heights min(h, ceiling), for callers that need the exact height only up to a value (a waterline's grid).
void drop_batch_capped(const MeshIndex& index, const Cutter& cutter, const double* xy, std::size_t n,
                       double floor_z, double ceiling, double* z_out, const BatchOptions& options);

// As above with a floor per point (floors: n heights), e.g. starts at different heights.
void drop_batch(const MeshIndex& index, const Cutter& cutter, const double* xy, std::size_t n,
                const double* floors, double* z_out, const BatchOptions& options,
                DropStats* stats = nullptr);

}  // namespace tmm
