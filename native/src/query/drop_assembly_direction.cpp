// The tool assembly dropped along any direction: its grown pieces as convex drop_direction solids (see
// drop_assembly_direction.hpp), each set up once per axis and dropped with the travel so far as its cap (the
// solid that stopped the previous start first), or along the tool's own axis the vertical assembly drop in the
// rotated frame.
#include "tmm/query/drop_assembly_direction.hpp"

#include <algorithm>
#include <atomic>
#include <cstdint>
#include <cmath>
#include <stdexcept>
#include <string>

#include "tmm/util/range.hpp"

namespace tmm {

using Eigen::Vector3d;
using direction_detail::kParallelAxisTol;
using direction_detail::require_unit;

namespace {

constexpr double kTileFactor = 2.0;  // a tile's side in cutter radii

// A frustum grown by c from its narrow end (radius rn, `narrow` along the tool axis from the tip) to its wide
// end (radius rw, `length` further towards dir: +1 up the axis, -1 down it). `wide_covered`: another grown
// body holds the wide disc grown by c, so the rim's ball is left out.
void add_grown_frustum(std::vector<AssemblySolid>& out, double narrow, double dir, double rn, double rw,
                       double length, double c, bool wide_covered, int32_t owner) {
  const bool flipped = dir < 0.0;
  const double beta = std::atan2(rw - rn, length);
  // The APT cutter of the vertical drop: flat bottom rn, corner c, the side offset by c up to the rim's ball.
  out.push_back({Cutter::apt(rw + c * std::cos(beta), c, length + c * (1.0 - std::sin(beta)), 0.0, beta),
                 narrow - dir * c, flipped, owner});
  if (c == 0.0 || wide_covered) return;
  const Cutter rim = Cutter::apt(rw + c, c, c, 0.0, 0.0);  // the wide disc grown by c, one half
  const double wide = narrow + dir * length;
  if (beta > 0.0) out.push_back({rim, wide - dir * c, flipped, owner});  // the ball between side and disc
  out.push_back({rim, wide + dir * c, !flipped, owner});                 // beyond the wide end
}

// The cutter solid of drop_direction (an endless one cut where the first body starts), grown by the cutter's
// clearance c: a flat-bottomed profile offset by c (as drop_assembly.cpp's), the top rim's ball and the top
// disc. With beta2 <= 0 the solid is the cylinder of the widest radius above the arc, grown as one.
void add_cutter(std::vector<AssemblySolid>& out, const ToolAssembly& tool) {
  Cutter k = tool.cutter();
  if (!std::isfinite(k.cutting_length())) {
    if (tool.bodies().empty())
      throw std::invalid_argument(
          "a drop with the tool axis not opposite to the direction needs a cutter with a finite cutting length "
          "or a body above it (nothing above the cutter is modelled)");
    try {
      k = Cutter::apt(k.radius(), k.corner_radius(), tool.bodies()[0].z0, k.beta1(), 0.0);
    } catch (const std::invalid_argument& e) {
      throw std::invalid_argument(std::string("the endless cutter cut where the first tool body starts: ") + e.what());
    }
  }
  const double c = tool.cutter_clearance();
  if (c == 0.0) {
    out.push_back({k, 0.0, false, kSetByCutter});
    return;
  }
  const double Lc = k.cutting_length(), R = k.max_radius(), b2 = std::max(k.beta2(), 0.0);
  out.push_back({Cutter::apt(R + c * std::cos(b2), k.corner_radius() + c, Lc + c * (1.0 - std::sin(b2)), 0.0, b2),
                 -c, false, kSetByCutter});
  if (tool.disc_covered(ToolAssembly::kNoBody, Lc, R, c)) return;
  const Cutter rim = Cutter::apt(R + c, c, c, 0.0, 0.0);
  if (b2 > 0.0) out.push_back({rim, Lc - c, false, kSetByCutter});
  out.push_back({rim, Lc + c, true, kSetByCutter});
}

bool along_axis(const DirectionalIndex& index, const Vector3d& axis) {
  return (index.rotation() * axis.normalized() - Vector3d::UnitZ()).norm() <= kParallelAxisTol;
}

// Along the tool's axis: the vertical drop in the rotated frame, travel = start height - tip height.
double axial_drop(const DirectionalIndex& index, const ToolAssembly& tool, const Vector3d& start, double max_travel,
                  int32_t* set_by, DropStats* stats) {
  const Vector3d s = index.rotation() * start;
  const double floor_z = s.z() - max_travel;
  const double z = drop_assembly_point(index.index(), tool, s.x(), s.y(), floor_z, set_by, stats);
  return z <= floor_z ? max_travel : s.z() - z;
}

// The solids set up for drops along the index's direction with the tool axis `axis` (once per axis).
std::vector<AlongCutter> along_cutters(const DirectionalIndex& index, const std::vector<AssemblySolid>& solids,
                                       const Vector3d& axis, bool fine_planes = false) {
  std::vector<AlongCutter> out;
  out.reserve(solids.size());
  for (const AssemblySolid& s : solids)
    out.emplace_back(index, s.profile, s.flipped ? Vector3d(-axis) : axis, fine_planes);
  return out;
}

// The earliest contact of the solids (set up by along_cutters) from `start` (hints: one per solid, or null),
// capped at max_travel. `lead` (or null): the solid dropped first, then set to the one that set the travel. The
// next start is likely stopped by the same solid: its travel, found first, caps the others' searches (a holder
// that holds the tool well above the part leaves the cutter little to test). A solid earlier in the list than
// the one that stopped the tool so far wins a tie, as in the list's order.
double along_solids(const std::vector<AssemblySolid>& solids, const std::vector<AlongCutter>& cutters,
                    const Vector3d& start, const Vector3d& axis, double max_travel, int32_t* set_by, DropStats* stats,
                    int32_t* hints, std::size_t* lead) {
  constexpr std::size_t kNone = ~std::size_t{0};
  double best = max_travel;
  std::size_t winner = kNone;
  auto drop = [&](std::size_t k) {
    const double cap = winner != kNone && k < winner ? std::nextafter(best, INFINITY) : best;
    const double t = cutters[k].drop(start + solids[k].lift * axis, cap, stats, hints ? &hints[k] : nullptr);
    if (t < best || (t == best && winner != kNone && k < winner)) {
      best = t;
      winner = k;
    }
  };
  const std::size_t first = lead && *lead < solids.size() ? *lead : 0;
  drop(first);
  for (std::size_t k = 0; k < solids.size(); ++k)
    if (k != first) drop(k);
  if (lead) *lead = winner == kNone ? 0 : winner;
  if (set_by) *set_by = winner == kNone ? kSetByFloor : solids[winner].owner;
  return best;
}

// A batch's starts in tiles `side` wide on the index's XY' plane: the starts by tile (in their order within
// one) and where each tile's run begins (the last entry: n).
void tile_runs(const DirectionalIndex& index, const double* starts, std::size_t n, double side,
               std::vector<std::size_t>& order, std::vector<std::size_t>& runs) {
  if (!(side > 0.0)) side = 1.0;  // a point cutter: any tile will do
  std::vector<std::uint64_t> key(n);
  double x0 = INFINITY, y0 = INFINITY;
  std::vector<Eigen::Vector2d> xy(n);
  for (std::size_t i = 0; i < n; ++i) {
    const Vector3d s = index.rotation() * Vector3d(starts[3 * i], starts[3 * i + 1], starts[3 * i + 2]);
    xy[i] = s.head<2>();
    x0 = std::min(x0, s.x()), y0 = std::min(y0, s.y());
  }
  for (std::size_t i = 0; i < n; ++i)
    key[i] = (static_cast<std::uint64_t>((xy[i].y() - y0) / side) << 32) |
             static_cast<std::uint64_t>((xy[i].x() - x0) / side);
  order.resize(n);
  for (std::size_t i = 0; i < n; ++i) order[i] = i;
  std::stable_sort(order.begin(), order.end(), [&](std::size_t a, std::size_t b) { return key[a] < key[b]; });
  runs.clear();
  for (std::size_t k = 0; k < n; ++k)
    if (k == 0 || key[order[k]] != key[order[k - 1]]) runs.push_back(k);
  runs.push_back(n);
}

// One tilted axis for a batch, per tile of nearby starts (their order within the tile kept), in two steps.
// First, at each start, each body against the triangle that last stopped it nearby (a contact of the body, so
// an upper bound of its travel that costs one triangle: beside a tall part or over a deep pocket the holder's
// caps the cutter's walk, which then meets little), then the cutter's walk capped by them; a start still
// uncapped (its cutter misses) gets every body's walk. Then each body from one gather of candidates with the
// travels so far as the caps (the tool stops no later than that: a holder high above the part gathers
// nothing): the triangles within its reach of a start, above its lowest point at that start's cap and not
// below one of its planes at every start, the same travels as a walk per start and body. Ties go to the solid
// earlier in the list, as in along_solids.
class TiledSolids {
 public:
  TiledSolids(const std::vector<AssemblySolid>& solids, const std::vector<AlongCutter>& cutters, const Vector3d& axis,
              const double* starts, std::size_t n, double max_travel)
      : solids_(solids), cutters_(cutters), axis_(axis), starts_(starts), best_(n, max_travel), winner_(n, kNone),
        walked_(n, 0) {}

  // A worker's lists, kept from tile to tile.
  struct TileScratch {
    explicit TileScratch(std::size_t solids) : hints(solids, -1), probe(solids, -1), wins(solids, 0), skip(solids, 0) {}
    std::vector<int32_t> hints;  // per solid: its walk's or list's last winner (tried first), or -1
    std::vector<int32_t> probe;  // per solid: the last triangle that stopped it, or -1
    std::vector<int32_t> known;  // per start of the tile and solid: the triangle its probe solved, or -1
    std::vector<Eigen::Vector4d> tangents;  // the same: the plane of support of its contact (level +inf: none)
    std::size_t last = ~std::size_t{0};  // the start the first step did last
    std::vector<std::size_t> order, wins, listed;  // the bodies' order; each solid's wins in the last tile
    std::vector<int> skip;  // per solid: tiles left that walk (its last list was too long)
    std::vector<Vector3d> lifted;
    std::vector<double> caps;
    AlongCutter::Candidates cands;
  };

  // The first step over the tile of starts run[0, m): the bodies' probes, the cutter's walk.
  void cutter(const std::size_t* run, std::size_t m, TileScratch& t, DropStats* stats) {
    const std::size_t S = solids_.size();
    t.known.assign(m * S, -1);
    t.tangents.assign(m * S, Eigen::Vector4d(0.0, 0.0, 0.0, INFINITY));
    for (std::size_t j = 0; j < m; ++j) {
      const std::size_t i = run[j];
      // The tool stops near where it stopped at the last start: a probe solved beyond that is not worth it.
      const double near = t.last < best_.size()
                              ? best_[t.last] + kProbeSlope * (lifted(i, 0) - lifted(t.last, 0)).norm() : INFINITY;
      for (std::size_t k = 1; k < S; ++k)
        if (t.probe[k] >= 0) {
          const double c = std::min(cap(i, k), near);
          const double u = cutters_[k].drop_on(lifted(i, k), c, t.probe[k], stats, &t.tangents[j * S + k]);
          if (u < c) update(i, k, u);
          if (u < c || !(near < cap(i, k))) t.known[j * S + k] = t.probe[k];
        }
      update(i, 0, drop(0, i, stats, t));
      t.last = i;
      if (!std::isfinite(best_[i])) {  // nothing caps the bodies: each one's walk, capped by those before
        for (std::size_t k = 1; k < S; ++k) update(i, k, drop(k, i, stats, t));
        walked_[i] = 1;
      }
    }
  }

  // The second step over the same tile: the bodies.
  void bodies(const std::size_t* run, std::size_t m, TileScratch& t, DropStats* stats) {
    const std::size_t S = solids_.size();
    // The bodies that stopped most of the last tile's starts first: their travels lower the others' caps.
    t.order.resize(S - 1);
    for (std::size_t k = 1; k < S; ++k) t.order[k - 1] = k;
    std::stable_sort(t.order.begin(), t.order.end(),
                     [&](std::size_t a, std::size_t b) { return t.wins[a] > t.wins[b]; });
    for (const std::size_t k : t.order) {
      t.lifted.clear(), t.caps.clear(), t.listed.clear();
      for (std::size_t j = 0; j < m; ++j) {
        const std::size_t i = run[j];
        if (walked_[i]) continue;  // done in the first step
        if (m < kMinTileStarts || t.skip[k] > 0) {
          update(i, k, drop(k, i, stats, t));
          continue;
        }
        t.lifted.push_back(lifted(i, k));
        t.caps.push_back(cap(i, k));
        t.listed.push_back(j);
      }
      if (t.skip[k] > 0) --t.skip[k];
      if (t.listed.empty()) continue;
      // A list longer than this many triangles a start (a holder over a dense plate): each start's walk,
      // which prunes it by its own contacts, costs less.
      const bool listed = cutters_[k].gather(t.lifted.data(), t.caps.data(), t.lifted.size(), t.cands,
                                             kMaxListPerStart * t.lifted.size());
      if (!listed) t.skip[k] = kWalkAfterLong;  // the next tiles are likely alike: no gather for a few
      for (std::size_t q = 0; q < t.listed.size(); ++q) {
        const std::size_t j = t.listed[q];
        update(run[j], k,
               listed ? cutters_[k].drop_listed(t.lifted[q], t.caps[q], t.cands, stats, &t.hints[k], t.known[j * S + k],
                                                 &t.tangents[j * S + k])
                      : cutters_[k].drop(t.lifted[q], t.caps[q], stats, &t.hints[k]));
        if (t.hints[k] >= 0) t.probe[k] = t.hints[k];
      }
    }
    std::fill(t.wins.begin(), t.wins.end(), 0);
    for (std::size_t j = 0; j < m; ++j)
      if (winner_[run[j]] != kNone) ++t.wins[winner_[run[j]]];
  }

  void write(double* travel_out, int32_t* set_by) const {
    for (std::size_t i = 0; i < best_.size(); ++i) {
      travel_out[i] = best_[i];
      if (set_by) set_by[i] = winner_[i] == kNone ? kSetByFloor : solids_[winner_[i]].owner;
    }
  }

 private:
  static constexpr int32_t kNone = -1;
  static constexpr std::size_t kMinTileStarts = 4;   // fewer: each start's walk costs less than a gather
  static constexpr std::size_t kMaxListPerStart = 40;
  static constexpr int kWalkAfterLong = 4;
  static constexpr double kProbeSlope = 2.0;  // a probe counts up to this much travel per mm from the last start

  Vector3d lifted(std::size_t i, std::size_t k) const {
    return Vector3d(starts_[3 * i], starts_[3 * i + 1], starts_[3 * i + 2]) + solids_[k].lift * axis_;
  }
  // Solid k's walk from start i; the triangle that stopped it is tried first at the next start.
  double drop(std::size_t k, std::size_t i, DropStats* stats, TileScratch& t) const {
    const double travel = cutters_[k].drop(lifted(i, k), cap(i, k), stats, &t.hints[k]);
    if (t.hints[k] >= 0) t.probe[k] = t.hints[k];
    return travel;
  }
  // A solid earlier in the list than the one that stopped start i so far wins a tie (as in along_solids).
  bool before(std::size_t i, std::size_t k) const {
    return winner_[i] >= 0 && k < static_cast<std::size_t>(winner_[i]);
  }
  double cap(std::size_t i, std::size_t k) const {
    return before(i, k) ? std::nextafter(best_[i], INFINITY) : best_[i];
  }
  void update(std::size_t i, std::size_t k, double t) {
    if (t < best_[i] || (t == best_[i] && before(i, k))) {
      best_[i] = t;
      winner_[i] = static_cast<int32_t>(k);
    }
  }

  const std::vector<AssemblySolid>& solids_;
  const std::vector<AlongCutter>& cutters_;
  Vector3d axis_;
  const double* starts_;
  std::vector<double> best_;
  std::vector<int32_t> winner_;
  std::vector<char> walked_;  // per start: every solid walked in the first step
};

}  // namespace

std::vector<AssemblySolid> assembly_solids(const ToolAssembly& tool) {
  std::vector<AssemblySolid> out;
  add_cutter(out, tool);
  const std::vector<ToolBody>& bodies = tool.bodies();
  for (std::size_t i = 0; i < bodies.size(); ++i) {
    const ToolBody& b = bodies[i];
    const auto owner = static_cast<int32_t>(i);
    try {
      const bool top_covered = tool.disc_covered(i, b.z1, b.r1, b.clearance);
      const bool bottom_covered = tool.disc_covered(i, b.z0, b.r0, b.clearance);
      // A cylinder either way: from the bottom up (its rounded rim at the bottom, where the part is met, and
      // the seam to the top disc's piece far from it, or none under a body sitting on it), unless only the
      // bottom disc is covered.
      if (b.r1 > b.r0 || (b.r1 == b.r0 && (top_covered || !bottom_covered)))
        add_grown_frustum(out, b.z0, 1.0, b.r0, b.r1, b.z1 - b.z0, b.clearance, top_covered, owner);
      else  // narrowing upwards: from the top down
        add_grown_frustum(out, b.z1, -1.0, b.r1, b.r0, b.z1 - b.z0, b.clearance, bottom_covered, owner);
    } catch (const std::invalid_argument& e) {  // a cone too flat for an APT profile
      throw std::invalid_argument("tool body " + std::to_string(i) + " along a direction: " + e.what());
    }
  }
  return out;
}

double drop_assembly_along_point(const DirectionalIndex& index, const ToolAssembly& tool, const Vector3d& start,
                                 const Vector3d& axis, double max_travel, int32_t* set_by, DropStats* stats) {
  require_unit(axis, "tool axis");
  if (along_axis(index, axis)) return axial_drop(index, tool, start, max_travel, set_by, stats);
  const Vector3d a = axis.normalized();
  const std::vector<AssemblySolid> solids = assembly_solids(tool);
  return along_solids(solids, along_cutters(index, solids, a), start, a, max_travel, set_by, stats, nullptr, nullptr);
}

void drop_assembly_along_batch(const DirectionalIndex& index, const ToolAssembly& tool, const double* starts,
                               const double* axes, bool axes_per_point, std::size_t n, double max_travel,
                               double* travel_out, int32_t* set_by, const BatchOptions& options,
                               DropStats* stats) {
  // Validate up front: workers must not throw.
  require_rows_in_range(starts, n, 3, "start points");
  if (!(in_range(max_travel) || max_travel == INFINITY)) require_in_range(max_travel, "max_travel");
  bool all_along = n > 0;
  for (std::size_t i = 0; i < (axes_per_point ? n : std::size_t{1}); ++i) {
    const Vector3d ax(axes[3 * i], axes[3 * i + 1], axes[3 * i + 2]);
    require_unit(ax, "tool axis");
    all_along = all_along && along_axis(index, ax);
  }
  if (all_along && !axes_per_point) {
    // The vertical assembly batch in the rotated frame, each point's floor max_travel below its start.
    const direction_detail::RotatedStarts s(index, starts, n, max_travel);
    std::vector<double> z(n);
    drop_assembly_batch(index.index(), tool, s.xy.data(), n, s.floors.data(), z.data(), set_by, options, stats);
    for (std::size_t i = 0; i < n; ++i) travel_out[i] = s.travel(i, z[i], max_travel);
    return;
  }
  std::vector<AssemblySolid> solids;
  bool any_tilted = false;
  for (std::size_t i = 0; i < (axes_per_point ? n : std::size_t{1}) && !any_tilted; ++i)
    any_tilted = !along_axis(index, Vector3d(axes[3 * i], axes[3 * i + 1], axes[3 * i + 2]));
  if (any_tilted) solids = assembly_solids(tool);  // throws here, not in a worker
  std::atomic<std::size_t> tested{0};
  if (any_tilted && !axes_per_point) {
    // One tilted axis for all: the solids set up once, the starts in tiles.
    const Vector3d a = Vector3d(axes[0], axes[1], axes[2]).normalized();
    const std::vector<AlongCutter> shared = along_cutters(index, solids, a, true);
    TiledSolids tiled(solids, shared, a, starts, n, max_travel);
    std::vector<std::size_t> order, runs;
    tile_runs(index, starts, n, kTileFactor * tool.cutter().max_radius(), order, runs);
    // Hints and probes start afresh with each chunk of tiles, so results do not depend on the thread count.
    parallel_chunks(runs.size() - 1, 8, options, [&](std::size_t begin, std::size_t end) {
      DropStats local;
      TiledSolids::TileScratch scratch(solids.size());
      for (std::size_t r = begin; r < end; ++r) {
        tiled.cutter(order.data() + runs[r], runs[r + 1] - runs[r], scratch, &local);
        tiled.bodies(order.data() + runs[r], runs[r + 1] - runs[r], scratch, &local);
      }
      tested.fetch_add(local.triangles_tested, std::memory_order_relaxed);
    });
    tiled.write(travel_out, set_by);
    if (stats) stats->triangles_tested += tested.load();
    return;
  }
  // Hints and the solid dropped first start afresh with each chunk, so results do not depend on the thread count.
  parallel_chunks(n, 64, options, [&](std::size_t begin, std::size_t end) {
    DropStats local;
    std::vector<int32_t> hints(solids.size(), -1);
    std::size_t lead = 0;
    for (std::size_t i = begin; i < end; ++i) {
      const double* ax = axes + (axes_per_point ? 3 * i : 0);
      const Vector3d start(starts[3 * i], starts[3 * i + 1], starts[3 * i + 2]), axis(ax[0], ax[1], ax[2]);
      int32_t* by = set_by ? set_by + i : nullptr;
      if (along_axis(index, axis)) {
        travel_out[i] = axial_drop(index, tool, start, max_travel, by, &local);
      } else {
        const Vector3d a = axis.normalized();
        travel_out[i] = along_solids(solids, along_cutters(index, solids, a), start, a, max_travel, by, &local,
                                     hints.data(), &lead);
      }
    }
    tested.fetch_add(local.triangles_tested, std::memory_order_relaxed);
  });
  if (stats) stats->triangles_tested += tested.load();
}

}  // namespace tmm
