// The mesh query of the drop along a direction (drop_direction.hpp): a best-first walk of the rotated index's
// hierarchy bounded by the cutter solid's lowest point and its supporting planes from below; each candidate
// triangle first given the clearance certificate (swept_clearance.hpp), then, unless it is proven clear, solved
// by the general method, both with the best travel so far as the cap (docs/drop_direction.md, "Mesh query").
#include <algorithm>
#include <atomic>
#include <cmath>
#include <memory>
#include <stdexcept>
#include <vector>

#include "drop_along_walk.hpp"
#include "tmm/query/drop_direction.hpp"
#include "tmm/query/swept_clearance.hpp"
#include "tmm/util/range.hpp"

namespace tmm {

using Eigen::Vector3d;
using direction_detail::kParallelAxisTol;
using direction_detail::require_finite_length;
using direction_detail::require_unit;
using direction_detail::walk_lowest;

namespace {

constexpr double kInfinity = std::numeric_limits<double>::infinity();

}  // namespace

AlongCutter::AlongCutter(const DirectionalIndex& index, const Cutter& cutter, const Vector3d& axis)
    : index_(&index), cutter_(cutter), a_(index.rotation() * axis.normalized()), frame_(a_) {
  require_unit(axis, "cutter axis");
  if ((a_ - Vector3d::UnitZ()).norm() <= kParallelAxisTol)
    throw std::invalid_argument("AlongCutter is the general method: the cutter axis must not be opposite to the "
                                "drop direction (use drop_along_point)");
  require_finite_length(cutter);
  W_ = frame_.to_tool(Vector3d(0, 0, -1));
  ahead_ = direction_detail::support(cutter, W_).value;
  // Lowest point of K along Z' below the tip (under_): no triangle whose highest point is below the cutter's
  // lowest point can touch it, so the index walks on that height in place of the tip's. An edge shared by several
  // triangles is solved by its owner only (IndexedTriangle::owned_edges): the owner's bound covers the edge
  // (the edge lies in its box and below its highest point), so when the owner is pruned so is the edge.
  under_ = direction_detail::UnderBounds(
      frame_, [&](const Vector3d& d) { return direction_detail::support(cutter, d); }, cutter.max_radius(), 0.0);
  // K's shadow on the XY' plane lies within this distance of the tip.
  reach_ = (cutter.max_radius() + cutter.cutting_length() * under_.axis_xy()) * (1 + 1e-12) + 1e-12;
}

double AlongCutter::triangle(const Vector3d& s, const IndexedTriangle& t, double best) const {
  const Vector3d q0 = frame_.to_tool(Vector3d(t.p[0]) - s), q1 = frame_.to_tool(Vector3d(t.p[1]) - s),
                 q2 = frame_.to_tool(Vector3d(t.p[2]) - s);
  if (best < kNoTravel) {
    // Most candidates are not touched before the best contact so far: a separating plane proves it for the
    // whole triangle (its edges included) at a fraction of the cost of its pieces.
    const double t0 = std::min({q0.dot(W_), q1.dot(W_), q2.dot(W_)}) - ahead_;
    if (t0 >= best) return kNoTravel;
    if (direction_detail::triangle_clear(cutter_, q0, q1, q2, W_, t0 - 1e-9 * (1 + std::fabs(t0)), best))
      return kNoTravel;
  }
  return direction_detail::triangle_travel(cutter_, q0, q1, q2, W_, best, t.owned_edges);
}

double AlongCutter::drop(const Vector3d& start, double max_travel, DropStats* stats, int32_t* hint) const {
  const Vector3d s = index_->rotation() * start;
  const MeshIndex& mi = index_->index();
  double best = max_travel;
  int32_t winner = -1;
  std::size_t tested = 0;
  auto floor_of = [&](double t) { return s.z() - t + under_.lowest() - 1e-9; };  // margin against rounding
  double floor_ref = floor_of(best);
  auto test = [&](const IndexedTriangle& t, int32_t i) {
    ++tested;
    const double tr = triangle(s, t, best);
    if (tr < best) {
      best = tr;
      winner = i;
      floor_ref = floor_of(best);
    }
  };
  const auto& tris = mi.triangles();
  if (hint && *hint >= 0 && static_cast<std::size_t>(*hint) < tris.size()) test(tris[*hint], *hint);
  const int32_t skip = hint ? *hint : -1;
  walk_lowest(
      mi, s.x(), s.y(), reach_, floor_ref,
      [&](double d, double x0, double x1, double y0, double y1, double enough) {
        return under_.rise(d, x0, x1, y0, y1, enough);
      },
      [&](const IndexedTriangle& t, int32_t i) {
        if (i != skip) test(t, i);
      });
  if (stats) stats->triangles_tested += tested;
  if (hint) *hint = winner;
  return best;
}

double drop_along_point(const DirectionalIndex& index, const Cutter& cutter, const Vector3d& start,
                        const Vector3d& axis, double max_travel, DropStats* stats, int32_t* hint) {
  require_unit(axis, "cutter axis");
  const Vector3d s = index.rotation() * start;
  const Vector3d a = index.rotation() * axis.normalized();
  if ((a - Vector3d::UnitZ()).norm() <= kParallelAxisTol) {
    // V = -axis: the fast -Z drop-cutter in the rotated frame.
    const double floor_z = s.z() - max_travel;
    const double z = drop_point(index.index(), cutter, s.x(), s.y(), floor_z, stats, hint);
    return z <= floor_z ? max_travel : s.z() - z;
  }
  return AlongCutter(index, cutter, axis).drop(start, max_travel, stats, hint);
}

void drop_along_batch(const DirectionalIndex& index, const Cutter& cutter, const double* starts,
                      const double* axes, bool axes_per_point, std::size_t n, double max_travel,
                      double* travel_out, const BatchOptions& options, DropStats* stats) {
  // Validate up front: workers must not throw.
  require_rows_in_range(starts, n, 3, "start points");
  if (!(in_range(max_travel) || max_travel == kInfinity)) require_in_range(max_travel, "max_travel");
  for (std::size_t i = 0; i < (axes_per_point ? n : std::size_t{1}); ++i) {
    const Vector3d ax(axes[3 * i], axes[3 * i + 1], axes[3 * i + 2]);
    require_unit(ax, "cutter axis");
    if ((index.rotation() * ax.normalized() - Vector3d::UnitZ()).norm() > kParallelAxisTol)
      require_finite_length(cutter);
  }
  if (!axes_per_point && n > 0) {
    const Vector3d a = index.rotation() * Vector3d(axes[0], axes[1], axes[2]).normalized();
    if ((a - Vector3d::UnitZ()).norm() <= kParallelAxisTol) {
      // V = -axis for every point: the tiled -Z batch in the rotated frame, each point's floor max_travel
      // below its start (as drop_along_point's fast path, point by point).
      const direction_detail::RotatedStarts s(index, starts, n, max_travel);
      std::vector<double> z(n);
      drop_batch(index.index(), cutter, s.xy.data(), n, s.floors.data(), z.data(), options, stats);
      for (std::size_t i = 0; i < n; ++i) travel_out[i] = s.travel(i, z[i], max_travel);
      return;
    }
  }
  std::unique_ptr<AlongCutter> shared;  // one axis for all: its set-up once
  if (!axes_per_point && n > 0) shared = std::make_unique<AlongCutter>(index, cutter, Vector3d(axes[0], axes[1], axes[2]));
  std::atomic<std::size_t> tested{0};
  // The hint starts afresh with each chunk, so results do not depend on the thread count.
  parallel_chunks(n, 128, options, [&](std::size_t begin, std::size_t end) {
    DropStats local;
    int32_t hint = -1;
    for (std::size_t i = begin; i < end; ++i) {
      const double* ax = axes + (axes_per_point ? 3 * i : 0);
      const Vector3d start(starts[3 * i], starts[3 * i + 1], starts[3 * i + 2]);
      travel_out[i] = shared ? shared->drop(start, max_travel, &local, &hint)
                             : drop_along_point(index, cutter, start, Vector3d(ax[0], ax[1], ax[2]), max_travel,
                                                &local, &hint);
    }
    tested.fetch_add(local.triangles_tested);
  });
  if (stats) stats->triangles_tested += tested.load();
}

}  // namespace tmm
