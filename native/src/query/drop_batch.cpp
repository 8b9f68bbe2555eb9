// The drop-cutter's batches and DropTiles: points in tiles, each tile's candidate list gathered once and
// scanned per point (drop_tile_scan.hpp); tiles too sparse or too crowded for a list go through drop_point.
#include <algorithm>
#include <atomic>
#include <cmath>
#include <cstdint>
#include <memory>
#include <stdexcept>
#include <vector>

#include "drop_tile_scan.hpp"
#include "tmm/query/drop_cutter.hpp"
#include "tmm/util/range.hpp"

namespace tmm {

using namespace drop_detail;  // NOLINT: the tile scan split off from this file

namespace {

constexpr std::uint64_t kUntiled = ~std::uint64_t{0};  // the tile key of a point that goes alone

// A batch's points in runs of one tile each: sorted by tile (stable within a tile, so a raster keeps its order
// and the warm-start hint its value); points with a non-finite coordinate go alone through drop_point (the
// floor). Heights do not depend on the thread count: tiles and their hints do not.
struct TileRuns {
  bool tiled = false;
  std::vector<std::uint64_t> key;  // per point: (iy << 27) | ix of its tile, kUntiled when alone
  std::vector<std::size_t> order;  // the points by tile
  std::vector<std::size_t> start;  // run r: order[start[r] .. start[r + 1])
  std::size_t runs() const { return start.size() - 1; }
};

// Each point's tile key (tiles kTileFactor cutter radii wide over the points' box); tiled false when there
// are no finite points or too many tiles for a key.
void tile_keys(const Cutter& cutter, const double* xy, std::size_t n, TileRuns& t, double& tiles_x,
               double& tiles_y) {
  const double tile = kTileFactor * cutter.max_radius();
  const auto [x0, y0, x1, y1] = finite_box(xy, n);
  const double span = std::max(x1 - x0, y1 - y0);
  constexpr double kMaxTiles = 1 << 26;  // per side; beyond it tiles are pointless anyway
  t.tiled = n > 0 && x0 <= x1 && span / tile < kMaxTiles;
  t.key.assign(n, kUntiled);
  if (t.tiled) {
    for (std::size_t i = 0; i < n; ++i) {
      const double x = xy[2 * i], y = xy[2 * i + 1];
      if (!std::isfinite(x) || !std::isfinite(y)) continue;
      const auto ix = static_cast<std::uint64_t>((x - x0) / tile);
      const auto iy = static_cast<std::uint64_t>((y - y0) / tile);
      t.key[i] = (iy << 27) | ix;
    }
  }
  tiles_x = t.tiled ? std::floor((x1 - x0) / tile) + 1.0 : 0.0;
  tiles_y = t.tiled ? std::floor((y1 - y0) / tile) + 1.0 : 0.0;
}

TileRuns tile_runs(const Cutter& cutter, const double* xy, std::size_t n) {
  TileRuns t;
  double tiles_x = 0.0, tiles_y = 0.0;
  tile_keys(cutter, xy, n, t, tiles_x, tiles_y);
  const std::vector<std::uint64_t>& key = t.key;
  std::vector<std::size_t>& order = t.order;
  order.resize(n);
  // By a counting sort on the tile's place in the box when the tiles are not many more than the points (a
  // grid, a raster: O(n)), else a stable sort of the keys; the same order.
  if (t.tiled && tiles_x * tiles_y <= 4.0 * static_cast<double>(n) + 1024.0) {
    const auto ntx = static_cast<std::uint64_t>(tiles_x);
    const std::size_t buckets = static_cast<std::size_t>(tiles_x * tiles_y) + 1;  // the last: untiled points
    auto bucket = [&](std::size_t i) {
      const std::uint64_t k = key[i];
      return k == kUntiled ? buckets - 1 : static_cast<std::size_t>((k >> 27) * ntx + (k & ((1u << 27) - 1)));
    };
    std::vector<std::size_t> start(buckets + 1, 0);
    for (std::size_t i = 0; i < n; ++i) ++start[bucket(i) + 1];
    for (std::size_t b = 0; b < buckets; ++b) start[b + 1] += start[b];
    for (std::size_t i = 0; i < n; ++i) order[start[bucket(i)]++] = i;
  } else {
    for (std::size_t i = 0; i < n; ++i) order[i] = i;
    if (t.tiled)
      std::stable_sort(order.begin(), order.end(), [&](std::size_t a, std::size_t b) { return key[a] < key[b]; });
  }
  // Runs of one key; untiled points (and tiles too sparse for a list) are runs of one point.
  for (std::size_t k = 0; k < n;) {
    std::size_t e = k + 1;
    if (t.tiled && key[order[k]] != kUntiled)
      while (e < n && key[order[e]] == key[order[k]]) ++e;
    t.start.push_back(k);
    k = e;
  }
  t.start.push_back(n);
  return t;
}

// One batch's runs solved one at a time (each thread its own candidate list): the floor of point i is
// floors ? floors[i] : floor_z; with a finite ceiling each point's scan stops at its first contact above it
// and reports min(h, ceiling).
// A thread's lists, kept from run to run: the cutter's and a follower's; the tile's box, the heights so far.
struct RunScratch {
  TileCandidates cutter, follower;
  double x0 = 0, y0 = 0, x1 = 0, y1 = 0;
  std::vector<double> height, base;
  std::vector<int32_t> owner;
};

class RunSolver {
 public:
  using TileDrop = double (*)(const MeshIndex&, const Cutter&, const TileCandidates&, double, double, double,
                              std::size_t&, int32_t&, double);

  // with `follow`, ceiling must be +inf
  RunSolver(const MeshIndex& index, const Cutter& cutter, const double* xy, const double* floors, double floor_z,
            double* z_out, double ceiling, const FollowPieces* follow = nullptr)
      : index_(index), cutter_(cutter), xy_(xy), floors_(floors), floor_z_(floor_z), z_out_(z_out),
        ceiling_(ceiling), capped_(ceiling < INFINITY), follow_(follow),
        drop_in_tile_(tile_drop<false>(cutter)) {
    for (std::size_t j = 1; follow && j < follow->count; ++j)
      follow_in_tile_.push_back(tile_drop<true>(follow->pieces[j].profile));
  }

  // The heights of run r's points (and the follower's); adds the triangles tested to `tested`.
  void solve(const TileRuns& t, std::size_t r, RunScratch& scratch, std::size_t& tested) const {
    TileCandidates& cands = scratch.cutter;
    const std::size_t a = t.start[r], b = t.start[r + 1];
    const std::vector<std::size_t>& order = t.order;
    bool listed = b - a >= kMinTilePoints && t.key[order[a]] != kUntiled;
    std::size_t k = a;
    if (capped_ && listed) {
      k = above_ceiling(order, a, b, tested);
      if (k == b) return;
    }
    const bool boxed = listed;  // the tile's box is in scratch
    if (listed) listed = gather(order, a, b, scratch);
    solve_cutter(order, k, b, listed, cands, tested);
    if (follow_) solve_followers(order, a, b, boxed, scratch, tested);
  }

 private:
  // The tile scan specialised for the profile's reach test, chosen once.
  template <bool kExact>
  static TileDrop tile_drop(const Cutter& c) {
    return c.kind() == CutterKind::Flat   ? &drop_point_in_tile<Reach::Flat, kExact>
           : c.kind() == CutterKind::Ball ? &drop_point_in_tile<Reach::Ball, kExact>
           : c.kind() == CutterKind::Bull ? &drop_point_in_tile<Reach::Bull, kExact>
                                          : &drop_point_in_tile<Reach::Scalar, kExact>;
  }

  void solve_cutter(const std::vector<std::size_t>& order, std::size_t k, std::size_t b, bool listed,
                    const TileCandidates& cands, std::size_t& tested) const {
    int32_t hint = -1;
    if (!listed) {
      DropStats s;
      for (; k < b; ++k) {
        const std::size_t i = order[k];
        z_out_[i] = std::min(drop_point(index_, cutter_, xy_[2 * i], xy_[2 * i + 1], floor_of(i), &s, &hint,
                                        ceiling_),
                             ceiling_);
      }
      tested += s.triangles_tested;
      return;
    }
    for (; k < b; ++k) {
      const std::size_t i = order[k];
      const double x = xy_[2 * i], y = xy_[2 * i + 1], floor_i = floor_of(i);
      z_out_[i] = std::min(drop_in_tile_(index_, cutter_, cands, x, y, floor_i, tested, hint, ceiling_), ceiling_);
    }
  }

  // The followers over run [a, b) once the cutter's heights are in (see FollowPieces); the tile's heights,
  // owners and floors kept in scratch, written out once.
  void solve_followers(const std::vector<std::size_t>& order, std::size_t a, std::size_t b, bool boxed,
                       RunScratch& scratch, std::size_t& tested) const {
    const FollowPieces& f = *follow_;
    std::vector<double>& height = scratch.height;
    std::vector<double>& base = scratch.base;
    std::vector<int32_t>& owner = scratch.owner;
    height.resize(b - a);
    base.resize(b - a);
    owner.assign(b - a, kSetByFloor);
    for (std::size_t k = a; k < b; ++k) {
      const std::size_t i = order[k];
      height[k - a] = f.floors ? f.floors[i] : f.floor_z;
      FollowPieces::raise(height[k - a], owner[k - a], z_out_[i], f.pieces[0]);
    }
    std::size_t open = boxed ? f.count : 1;  // the first piece left open
    for (std::size_t j = 1; j < open; ++j)
      if (!follow_piece(order, a, b, f.pieces[j], j - 1, scratch, tested)) open = j;
    for (std::size_t k = a; k < b; ++k) {
      const std::size_t i = order[k];
      f.height[i] = height[k - a];
      f.owner[i] = owner[k - a];
      f.first_open[i] = static_cast<std::uint8_t>(open);
    }
  }

  // One follower over the tile (its scan at position `scan`); false when its list would be too long.
  bool follow_piece(const std::vector<std::size_t>& order, std::size_t a, std::size_t b, const AssemblyPiece& p,
                    std::size_t scan, RunScratch& scratch, std::size_t& tested) const {
    std::vector<double>& height = scratch.height;
    std::vector<double>& base = scratch.base;
    double lowest = INFINITY;
    for (std::size_t k = 0; k < b - a; ++k) {
      base[k] = height[k] + p.lift;
      lowest = std::min(lowest, base[k]);
    }
    TileCandidates& fc = scratch.follower;
    const std::size_t most = kMaxFollowerCandidatesPerPoint * (b - a);
    fc.sorted.clear();
    bool crowded = false;
    index_.near_rect(scratch.x0, scratch.y0, scratch.x1, scratch.y1, p.profile.max_radius(), lowest,
                     [&](const IndexedTriangle& t, int32_t id) {
                       crowded = fc.sorted.size() == most;
                       if (!crowded) fc.sorted.emplace_back(t.zmax, id);
                       return !crowded;
                     });
    if (crowded) return false;
    if (fc.sorted.empty()) return true;  // nothing rises above any floor
    fc.prepare(index_, p.profile, most);
    const double highest = fc.zmax[0];
    const auto& tris = index_.triangles();
    int32_t hint = -1;
    for (std::size_t k = a; k < b; ++k) {
      const double floor_k = base[k - a];
      if (!(highest > floor_k)) continue;
      // A holder over a plateau: the last winner holding the flat bottom at its top is a lower bound without a
      // contact solve (the scan then only looks above it).
      const std::size_t i = order[k];
      const double x = xy_[2 * i], y = xy_[2 * i + 1];
      double from = floor_k;
      int32_t h = hint;
      if (h >= 0) {
        const IndexedTriangle& t = tris[static_cast<std::size_t>(fc.id[static_cast<std::size_t>(h)])];
        if (t.zmax > floor_k && rests_flat(p.profile, t, x, y, t.zmax)) {
          from = t.zmax;
          h = -1;
        }
      }
      const double top = follow_in_tile_[scan](index_, p.profile, fc, x, y, from, tested, h, INFINITY);
      hint = h < 0 && from > floor_k ? hint : h;
      FollowPieces::raise(height[k - a], scratch.owner[k - a], top, p);
    }
    return true;
  }

  double floor_of(std::size_t i) const { return floors_ ? floors_[i] : floor_z_; }

  // Capped heights (a waterline's grid): while the tile's points stand above the ceiling (over the top of a
  // part) they are solved without its list: the last winner alone lifting the tool above the ceiling gives
  // the ceiling, else a walk that stops at the first contact above it. Returns the position after the first
  // point below the ceiling (its height set), where the list is gathered; b when there is none.
  std::size_t above_ceiling(const std::vector<std::size_t>& order, std::size_t a, std::size_t b,
                            std::size_t& tested) const {
    const auto& tris = index_.triangles();
    int32_t last = -1;  // the last winner, a position in tris
    std::size_t k = a;
    DropStats s;
    for (; k < b; ++k) {
      const std::size_t i = order[k];
      const double x = xy_[2 * i], y = xy_[2 * i + 1];
      if (last >= 0) {
        ++s.triangles_tested;
        if (drop_on_owned(cutter_, x, y, tris[static_cast<std::size_t>(last)], floor_of(i)) > ceiling_) {
          z_out_[i] = ceiling_;
          continue;
        }
      }
      int32_t winner = last;
      const double h = drop_point(index_, cutter_, x, y, floor_of(i), &s, &winner, ceiling_);
      z_out_[i] = std::min(h, ceiling_);
      if (!(h > ceiling_)) {
        ++k;
        break;
      }
      last = winner;
    }
    tested += s.triangles_tested;
    return k;
  }

  // The tile's candidate list over its points' box and below their lowest floor; false when the tile is too
  // crowded for a list (then drop_point serves its points).
  bool gather(const std::vector<std::size_t>& order, std::size_t a, std::size_t b, RunScratch& scratch) const {
    double tx0 = INFINITY, ty0 = INFINITY, tx1 = -INFINITY, ty1 = -INFINITY;
    for (std::size_t j = a; j < b; ++j) {
      const std::size_t i = order[j];
      tx0 = std::min(tx0, xy_[2 * i]);
      tx1 = std::max(tx1, xy_[2 * i]);
      ty0 = std::min(ty0, xy_[2 * i + 1]);
      ty1 = std::max(ty1, xy_[2 * i + 1]);
    }
    double tile_floor = INFINITY;  // the lowest floor of the tile's points bounds the list
    for (std::size_t j = a; j < b; ++j) tile_floor = std::min(tile_floor, floor_of(order[j]));
    scratch.x0 = tx0;
    scratch.y0 = ty0;
    scratch.x1 = tx1;
    scratch.y1 = ty1;
    return scratch.cutter.gather(index_, cutter_, tx0, ty0, tx1, ty1, tile_floor, kMaxCandidatesPerPoint * (b - a));
  }
  const MeshIndex& index_;
  const Cutter& cutter_;
  const double* xy_;
  const double* floors_;
  const double floor_z_;
  double* z_out_;
  const double ceiling_;
  const bool capped_;
  const FollowPieces* follow_;
  const TileDrop drop_in_tile_;
  std::vector<TileDrop> follow_in_tile_;  // piece j's scan at j - 1
};

// drop_batch with the floor of point i = floors ? floors[i] : floor_z.
// ceiling: each point's scan stops at its first contact above it and reports min(h, ceiling).
void drop_batch_floors(const MeshIndex& index, const Cutter& cutter, const double* xy, std::size_t n,
                       const double* floors, double floor_z, double* z_out, const BatchOptions& options,
                       DropStats* stats, double ceiling = INFINITY, const FollowPieces* follow = nullptr) {
  const TileRuns t = tile_runs(cutter, xy, n);
  const RunSolver solver(index, cutter, xy, floors, floor_z, z_out, ceiling, follow);
  std::atomic<std::size_t> tested{0};
  parallel_chunks(t.runs(), 16, options, [&](std::size_t begin, std::size_t end) {
    std::size_t local = 0;
    RunScratch scratch;
    for (std::size_t r = begin; r < end; ++r) solver.solve(t, r, scratch, local);
    tested.fetch_add(local);
  });
  if (stats) stats->triangles_tested += tested.load();
}

}  // namespace

void drop_detail::drop_batch_follow(const MeshIndex& index, const FollowPieces& follow, const double* xy,
                                    std::size_t n, double* top, const BatchOptions& options, DropStats* stats) {
  const AssemblyPiece& cutter = follow.pieces[0];
  if (follow.count > 255) throw std::invalid_argument("drop_batch_follow: more than 255 pieces");
  for (std::size_t j = 1; j < follow.count; ++j)
    if (!(follow.pieces[j].lift >= cutter.lift))
      throw std::invalid_argument("drop_batch_follow: a follower's lift below the cutter's");
  if (!follow.floors) {
    drop_batch_floors(index, cutter.profile, xy, n, nullptr, follow.floor_z + cutter.lift, top, options, stats,
                      INFINITY, &follow);
    return;
  }
  std::vector<double> base(n);
  for (std::size_t i = 0; i < n; ++i) base[i] = follow.floors[i] + cutter.lift;
  drop_batch_floors(index, cutter.profile, xy, n, base.data(), 0.0, top, options, stats, INFINITY, &follow);
}

void drop_batch(const MeshIndex& index, const Cutter& cutter, const double* xy, std::size_t n,
                double floor_z, double* z_out, const BatchOptions& options, DropStats* stats) {
  require_in_range(floor_z, "floor_z");  // a NaN floor would come back as every height
  drop_batch_floors(index, cutter, xy, n, nullptr, floor_z, z_out, options, stats);
}

void drop_batch_capped(const MeshIndex& index, const Cutter& cutter, const double* xy, std::size_t n,
                       double floor_z, double ceiling, double* z_out, const BatchOptions& options) {
  require_in_range(floor_z, "floor_z");
  if (std::isnan(ceiling)) throw std::invalid_argument("drop ceiling must not be NaN");
  drop_batch_floors(index, cutter, xy, n, nullptr, floor_z, z_out, options, nullptr, ceiling);
}

void drop_batch(const MeshIndex& index, const Cutter& cutter, const double* xy, std::size_t n,
                const double* floors, double* z_out, const BatchOptions& options, DropStats* stats) {
  drop_batch_floors(index, cutter, xy, n, floors, 0.0, z_out, options, stats);
}

// Tiles of a DropTiles: null until gathered, then the list, or kWalk where drop_point serves the tile.
struct DropTiles::Impl {
  const MeshIndex& index;
  const Cutter& cutter;
  double x0 = 0, y0 = 0, tile = 1, floor = 0;
  std::size_t nx = 0, ny = 0;
  double (*scan)(const MeshIndex&, const Cutter&, const TileCandidates&, double, double, double, int32_t&,
                 std::size_t, std::size_t&, double);
  std::unique_ptr<std::atomic<TileCandidates*>[]> slots;
  std::atomic<std::size_t> kept{0};  // candidates in all lists: bounded by kDropTilesBudget
  static TileCandidates* walk() { return reinterpret_cast<TileCandidates*>(std::uintptr_t{1}); }

  Impl(const MeshIndex& i, const Cutter& c) : index(i), cutter(c) {}
  ~Impl() {
    for (std::size_t k = 0; slots && k < nx * ny; ++k) {
      TileCandidates* c = slots[k].load();
      if (c != walk()) delete c;
    }
  }
  // Tile (i, j)'s list, gathered by the first thread that asks (another gathering the same one at the same
  // time throws its copy away: both are equal); null for a tile served by drop_point.
  const TileCandidates* candidates(std::size_t i, std::size_t j) {
    std::atomic<TileCandidates*>& slot = slots[j * nx + i];
    TileCandidates* c = slot.load(std::memory_order_acquire);
    if (!c) {
      auto made = std::make_unique<TileCandidates>();
      const double tx = x0 + static_cast<double>(i) * tile, ty = y0 + static_cast<double>(j) * tile;
      const std::size_t used = kept.load(std::memory_order_relaxed);
      const std::size_t most = std::min(kDropTilesMostPerTile, kDropTilesBudget - std::min(used, kDropTilesBudget));
      TileCandidates* fresh = walk();
      if (made->gather(index, cutter, tx, ty, tx + tile, ty + tile, floor, most)) {
        made->sorted = {};  // (scratch of the gather)
        fresh = made.get();
      }
      if (slot.compare_exchange_strong(c, fresh, std::memory_order_acq_rel, std::memory_order_acquire)) {
        c = fresh;
        if (fresh != walk()) kept.fetch_add(made.release()->id.size(), std::memory_order_relaxed);
      }
    }
    return c == walk() ? nullptr : c;
  }
};

DropTiles::DropTiles(const MeshIndex& index, const Cutter& cutter, double x0, double y0, double x1, double y1,
                     double tile, double floor)
    : impl_(std::make_unique<Impl>(index, cutter)) {
  for (double v : {x0, y0, x1, y1, tile, floor})
    if (!std::isfinite(v)) throw std::invalid_argument("drop tiles: bounds, tile and floor must be finite");
  if (!(x1 >= x0 && y1 >= y0)) throw std::invalid_argument("drop tiles: empty bounds");
  // Tiles no smaller than the lattice of kDropTilesMost tiles needs (their slots are allocated at once).
  tile = std::max(tile, std::sqrt((x1 - x0) * (y1 - y0) / static_cast<double>(kDropTilesMost)));
  tile = std::max({tile, (x1 - x0) / 65536.0, (y1 - y0) / 65536.0, 1e-9});
  Impl& d = *impl_;
  d.x0 = x0;
  d.y0 = y0;
  d.tile = tile;
  d.floor = floor;
  d.nx = static_cast<std::size_t>((x1 - x0) / tile) + 1;
  d.ny = static_cast<std::size_t>((y1 - y0) / tile) + 1;
  d.slots = std::make_unique<std::atomic<TileCandidates*>[]>(d.nx * d.ny);
  for (std::size_t k = 0; k < d.nx * d.ny; ++k) d.slots[k].store(nullptr, std::memory_order_relaxed);
  d.scan = cutter.kind() == CutterKind::Flat   ? &scan_tile<Reach::Flat, true>
           : cutter.kind() == CutterKind::Ball ? &scan_tile<Reach::Ball, true>
           : cutter.kind() == CutterKind::Bull ? &scan_tile<Reach::Bull, true>
                                               : &scan_tile<Reach::Scalar, true>;
}

DropTiles::~DropTiles() = default;

double DropTiles::drop(double x, double y, double floor_z, int32_t* hint, double ceiling) const {
  Impl& d = *impl_;
  const double fi = std::floor((x - d.x0) / d.tile), fj = std::floor((y - d.y0) / d.tile);
  const TileCandidates* c = nullptr;
  if (fi >= 0 && fj >= 0 && fi < static_cast<double>(d.nx) && fj < static_cast<double>(d.ny) && floor_z >= d.floor)
    c = d.candidates(static_cast<std::size_t>(fi), static_cast<std::size_t>(fj));
  if (!c) return drop_point(d.index, d.cutter, x, y, floor_z, nullptr, hint, ceiling);
  // Warm start from the hint's triangle, exactly as drop_point; the scan then skips it (found among the
  // list's entries of its height: the list is by decreasing height).
  const auto& tris = d.index.triangles();
  double best = floor_z;
  int32_t from_hint = -1;
  std::size_t skip = ~std::size_t{0}, tested = 0;
  if (hint && *hint >= 0 && static_cast<std::size_t>(*hint) < tris.size()) {
    const IndexedTriangle& t = tris[*hint];
    const double z = drop_on_owned(d.cutter, x, y, t, best);
    if (z > best) {
      best = z;
      from_hint = *hint;
      const std::size_t m = c->id.size();
      std::size_t q = static_cast<std::size_t>(
          std::lower_bound(c->zmax.begin(), c->zmax.begin() + static_cast<std::ptrdiff_t>(m), t.zmax,
                           [](double a, double b) { return a > b; }) - c->zmax.begin());
      for (; q < m && c->zmax[q] == t.zmax; ++q)
        if (c->id[q] == from_hint) {
          skip = q;
          break;
        }
    }
  }
  int32_t winner = -1;
  best = d.scan(d.index, d.cutter, *c, x, y, best, winner, skip, tested, ceiling);
  if (hint) *hint = winner >= 0 ? c->id[static_cast<std::size_t>(winner)] : from_hint;
  return best;
}
}  // namespace tmm
