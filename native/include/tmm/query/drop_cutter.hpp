// Drop-cutter along -Z: for each (x, y), the lowest tip height at which the cutter touches the mesh without
// penetrating it (the highest of all vertex, edge and facet contacts), never below a floor.
#pragma once

#include <cstddef>
#include <functional>
#include <limits>
#include <memory>
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

// xy: n points (x0, y0, x1, y1, ...); z_out: n tip heights. Throws Cancelled if progress returns false,
// std::invalid_argument for a floor_z outside the kernel's range (NaN included; tmm/util/range.hpp).
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

// Drops at many scattered points of a region, in an order not known in advance (a waterline level's crossings
// and chords), each scanning the candidate list of its tile as drop_batch does: square tiles of side `tile`
// (or larger: at most kDropTilesMost of them) over [x0, x1] x [y0, y1], each list (the triangles within the
// cutter's radius of the tile whose top is above `floor`, by decreasing height) gathered the first time a
// point falls in its tile and kept. Points outside the region, floors below `floor`, tiles of more than
// kDropTilesMostPerTile candidates and tiles past kDropTilesBudget candidates in all use drop_point.
// drop() may be called from several threads at once.
constexpr std::size_t kDropTilesMost = 1 << 16;
constexpr std::size_t kDropTilesMostPerTile = 4096;
constexpr std::size_t kDropTilesBudget = 1 << 18;  // about 22 MB of lists

class DropTiles {
 public:
  // Throws std::invalid_argument on non-finite or empty bounds or a non-finite tile or floor.
  DropTiles(const MeshIndex& index, const Cutter& cutter, double x0, double y0, double x1, double y1, double tile,
            double floor);
  ~DropTiles();
  DropTiles(const DropTiles&) = delete;
  DropTiles& operator=(const DropTiles&) = delete;
  // drop_point(index, cutter, x, y, floor_z, nullptr, hint, ceiling): the same height (the same exact test of
  // each triangle that can raise it; the lists' filters are bounds of that test's own pruning), the hint as
  // there (a position in index.triangles(); -1 for none).
  double drop(double x, double y, double floor_z, int32_t* hint,
              double ceiling = std::numeric_limits<double>::infinity()) const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace tmm
