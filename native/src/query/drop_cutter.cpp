#include "tmm/query/drop_cutter.hpp"

#include <algorithm>
#include <atomic>
#include <cmath>
#include <cstdint>
#include <memory>
#include <stdexcept>
#include <vector>

#if defined(__SSE2__)
#include <emmintrin.h>
#endif

#include "tmm/query/drop_contacts.hpp"
#include "tmm/util/range.hpp"

namespace tmm {

double drop_on_triangle(const Cutter& c, double x, double y, const IndexedTriangle& t, double above) {
  double z = std::max(above, facet_drop(c, x, y, t.p[0], t.p[1], t.p[2], t.n, t.zmax, above));
  z = std::max(z, edge_drop(c, x, y, t.p[0], t.p[1], z));
  z = std::max(z, edge_drop(c, x, y, t.p[1], t.p[2], z));
  z = std::max(z, edge_drop(c, x, y, t.p[2], t.p[0], z));
  return z > above ? z : kNoContact;
}

namespace {

// The highest contact above `above` of the edges (and so the vertices) this triangle owns (see
// IndexedTriangle::owned_edges), or -inf.
double owned_edges_drop(const Cutter& c, double x, double y, const IndexedTriangle& t, double above) {
  double z = above;
  if (t.owned_edges & 1u) z = std::max(z, edge_drop(c, x, y, t.p[0], t.p[1], z));
  if (t.owned_edges & 2u) z = std::max(z, edge_drop(c, x, y, t.p[1], t.p[2], z));
  if (t.owned_edges & 4u) z = std::max(z, edge_drop(c, x, y, t.p[2], t.p[0], z));
  return z > above ? z : kNoContact;
}

// drop_on_triangle for the walk. The drop onto the triangle's plane bounds the triangle's contact; when its
// contact point lies inside the triangle it is that contact (no edge can be higher), otherwise only the
// edges this triangle owns are solved, and only if the plane bound exceeds `above`.
double drop_on_owned(const Cutter& c, double x, double y, const IndexedTriangle& t, double above) {
  bool inside = false;
  const double zp = plane_drop(c, x, y, t.p[0], t.p[1], t.p[2], t.n, inside);
  if (zp != kNoContact) {  // a plane that faces up: its drop bounds the triangle's
    if (zp <= above) return kNoContact;
    if (inside) return zp;
  }
  return owned_edges_drop(c, x, y, t, above);
}

}  // namespace

double drop_point(const MeshIndex& index, const Cutter& cutter, double x, double y, double floor_z,
                  DropStats* stats, int32_t* hint, double ceiling) {
  double best = floor_z;
  int32_t winner = -1;
  std::size_t tested = 0;
  const auto& tris = index.triangles();
  if (hint && *hint >= 0 && static_cast<std::size_t>(*hint) < tris.size()) {
    ++tested;
    const double z = drop_on_owned(cutter, x, y, tris[*hint], best);
    if (z > best) {
      best = z;
      winner = *hint;
    }
  }
  // The walk prunes with `prune`: best, or +inf once best is above the ceiling (every box fails then).
  double prune = best > ceiling ? INFINITY : best;
  const int32_t skip = winner;
  if (prune != INFINITY)
    index.walk(x, y, cutter, prune, [&](const IndexedTriangle& t, int32_t i) {
      if (i == skip || prune == INFINITY) return;
      ++tested;
      const double z = drop_on_owned(cutter, x, y, t, best);
      if (z > best) {
        best = z;
        winner = i;
        prune = best > ceiling ? INFINITY : best;
      }
    });
  if (stats) stats->triangles_tested += tested;
  if (hint) *hint = winner;
  return best;
}

namespace {

// Batches are solved tile by tile: points are grouped into square tiles, each tile gathers once the
// triangles any of its points can rest on, sorted by decreasing height, and each point scans that list
// only until a triangle's top is no higher than its best contact (no later one can raise the cutter).
// This replaces a tree walk per point by a short linear scan over a list that stays in cache.
// A tile of side kTileFactor * cutter radius; tiles holding fewer points than kMinTilePoints, or more
// candidates than kMaxCandidatesPerPoint per point, are not worth a list and use the per-point walk.
constexpr double kTileFactor = 1.5;
constexpr std::size_t kMinTilePoints = 8;
// On dense meshes a tile's list grows with the square of the triangle density while its points stay the
// same: sorting and preparing the list then costs more than it saves, and the walk serves those tiles
// (measured on the benchmark's height fields: 2M triangles, 0.5 mm raster).
constexpr std::size_t kMaxCandidatesPerPoint = 40;
constexpr double kPlaneMargin = 1e-9;
// Candidates per filter block, a bit each in an unsigned mask: 32 measured faster than 8 or 16 (fewer
// breaks and mask loops; the few entries filtered past the break are cheap).
constexpr int kBlock = 32;

// Candidates of one tile, structure of arrays in order of decreasing zmax.
struct TileCandidates {
  std::vector<double> zmax, xmin, ymin, xmax, ymax;
  // The drop onto the triangle's plane at (x, y) is plane_a x + plane_b y + plane_c (the plane's height plus
  // the cutter's lift off it, which depends only on the slope): an upper bound on the triangle's contact
  // for three operations (+inf for a plane that does not face up).
  std::vector<double> plane_a, plane_b, plane_c;
  // From the axis to the plane's contact point (the facet contact when that point lies in the triangle).
  std::vector<double> contact_dx, contact_dy;
  std::vector<int32_t> id;
  std::vector<std::pair<double, int32_t>> sorted;

  // Collects the tile's candidates; false (and nothing prepared) when there are more than `most` of them.
  bool gather(const MeshIndex& index, const Cutter& cutter, double x0, double y0, double x1, double y1,
              double floor, std::size_t most) {
    const double radius = cutter.max_radius();
    sorted.clear();
    index.near_rect(x0, y0, x1, y1, radius, floor,
                    [&](const IndexedTriangle& t, int32_t i) { sorted.emplace_back(t.zmax, i); });
    if (sorted.size() > most) return false;
    std::sort(sorted.begin(), sorted.end(),
              [](const auto& a, const auto& b) { return a.first > b.first; });
    const std::size_t m = sorted.size();
    // Padded to whole blocks with entries that fail every test.
    const std::size_t padded = (m + kBlock - 1) / kBlock * kBlock;
    for (auto* v : {&zmax, &plane_c}) v->assign(padded, -INFINITY);
    for (auto* v : {&xmin, &ymin}) v->assign(padded, INFINITY);
    for (auto* v : {&xmax, &ymax}) v->assign(padded, -INFINITY);
    for (auto* v : {&plane_a, &plane_b, &contact_dx, &contact_dy}) v->assign(padded, 0.0);
    id.assign(padded, -1);
    const auto& tris = index.triangles();
    for (std::size_t k = 0; k < m; ++k) {
      const IndexedTriangle& t = tris[sorted[k].second];
      zmax[k] = t.zmax;
      xmin[k] = t.xmin;
      ymin[k] = t.ymin;
      xmax[k] = t.xmax;
      ymax[k] = t.ymax;
      id[k] = sorted[k].second;
      const double nx = t.n[0], ny = t.n[1], nz = t.n[2];
      if (nz <= 1e-12) {  // as plane_drop: no plane bound
        plane_a[k] = plane_b[k] = 0.0;
        plane_c[k] = INFINITY;
        continue;
      }
      const double nxy = std::sqrt(nx * nx + ny * ny);
      double lift = 0.0;
      if (nxy > 1e-15) {  // as plane_drop: the contact point lies uphill, rho from the axis
        const double rho = cutter.facet_contact_radius(nxy, nz);
        lift = rho * nxy / nz - cutter.height(rho);
        contact_dx[k] = -rho * nx / nxy;
        contact_dy[k] = -rho * ny / nxy;
      }
      plane_a[k] = -nx / nz;
      plane_b[k] = -ny / nz;
      plane_c[k] = t.p[0][2] + (nx * t.p[0][0] + ny * t.p[0][1]) / nz + lift;
    }
    return true;
  }
};

// How the block filter tests reach (Cutter::reach2) for the cutters with a flat bottom and a corner arc
// of radius r centred e from the axis: d^2 < reach2(lift) is lift >= r or d < e + sqrt(r^2 - (r - lift)^2).
enum class Reach {
  Scalar,  // any other profile: Cutter::reach2 on the survivors
  Flat,    // r = 0: anything within the radius is within reach
  Ball,    // e = 0: d^2 < r^2 - (r - lift)^2, no root
  Bull,
};

// Bit j set: candidate k + j may hold the cutter above `best` at (x, y): top above best, box within the
// cutter's radius, plane bound above best, and (but for Reach::Scalar) box within reach. Two lanes at a
// time where SSE2 is there (every x86-64).
template <Reach kReach>
inline unsigned block_mask(const TileCandidates& c, std::size_t k, double x, double y, double r2, double best,
                           double r, double e) {
  unsigned mask = 0;
#if defined(__SSE2__)
  const __m128d X = _mm_set1_pd(x), Y = _mm_set1_pd(y), B = _mm_set1_pd(best), R2 = _mm_set1_pd(r2);
  const __m128d zero = _mm_setzero_pd(), margin = _mm_set1_pd(kPlaneMargin);
  const __m128d Rc = _mm_set1_pd(r), Rc2 = _mm_set1_pd(r * r), E = _mm_set1_pd(e);
  for (int j = 0; j < kBlock; j += 2) {
    const std::size_t q = k + j;
    const __m128d dx = _mm_max_pd(_mm_max_pd(_mm_sub_pd(_mm_loadu_pd(&c.xmin[q]), X),
                                             _mm_sub_pd(X, _mm_loadu_pd(&c.xmax[q]))), zero);
    const __m128d dy = _mm_max_pd(_mm_max_pd(_mm_sub_pd(_mm_loadu_pd(&c.ymin[q]), Y),
                                             _mm_sub_pd(Y, _mm_loadu_pd(&c.ymax[q]))), zero);
    const __m128d d2 = _mm_add_pd(_mm_mul_pd(dx, dx), _mm_mul_pd(dy, dy));
    const __m128d plane = _mm_add_pd(_mm_add_pd(_mm_mul_pd(_mm_loadu_pd(&c.plane_a[q]), X),
                                                _mm_mul_pd(_mm_loadu_pd(&c.plane_b[q]), Y)),
                                     _mm_add_pd(_mm_loadu_pd(&c.plane_c[q]), margin));
    const __m128d top = _mm_loadu_pd(&c.zmax[q]);
    __m128d pass = _mm_and_pd(_mm_and_pd(_mm_cmpgt_pd(top, B), _mm_cmple_pd(d2, R2)), _mm_cmpgt_pd(plane, B));
    if (kReach == Reach::Ball || kReach == Reach::Bull) {
      const __m128d lift = _mm_sub_pd(top, B);
      const __m128d below = _mm_sub_pd(Rc, lift);
      const __m128d arc = _mm_max_pd(_mm_sub_pd(Rc2, _mm_mul_pd(below, below)), zero);
      __m128d reach2 = arc;
      if (kReach == Reach::Bull) {
        const __m128d rho = _mm_add_pd(E, _mm_sqrt_pd(arc));
        reach2 = _mm_mul_pd(rho, rho);
      }
      pass = _mm_and_pd(pass, _mm_or_pd(_mm_cmpge_pd(lift, Rc), _mm_cmplt_pd(d2, reach2)));
    }
    mask |= static_cast<unsigned>(_mm_movemask_pd(pass)) << j;
  }
#else
  for (int j = 0; j < kBlock; ++j) {
    const std::size_t q = k + j;
    const double dx = maxd(maxd(c.xmin[q] - x, x - c.xmax[q]), 0.0);
    const double dy = maxd(maxd(c.ymin[q] - y, y - c.ymax[q]), 0.0);
    const double d2 = dx * dx + dy * dy;
    const double plane = c.plane_a[q] * x + c.plane_b[q] * y + (c.plane_c[q] + kPlaneMargin);
    bool pass = (c.zmax[q] > best) & (d2 <= r2) & (plane > best);
    if (kReach == Reach::Ball || kReach == Reach::Bull) {
      const double lift = c.zmax[q] - best, below = r - lift;
      const double rho = e + std::sqrt(maxd(r * r - below * below, 0.0));
      pass = pass & ((lift >= r) | (d2 < rho * rho));
    }
    mask |= static_cast<unsigned>(pass) << j;
  }
#endif
  return mask;
}

// drop_on_owned for candidate q of a tile: raises best (and winner, the position in the list) when its
// contact is higher. kExact: drop_on_owned itself, the very value drop_point gets; else with the tile's
// precomputed plane drop (the same value up to rounding, fewer operations).
template <bool kExact>
inline void test_candidate(const MeshIndex& index, const Cutter& cutter, const TileCandidates& c, std::size_t q,
                           double x, double y, double& best, int32_t& winner, std::size_t& tested) {
  ++tested;
  const IndexedTriangle& t = index.triangles()[c.id[q]];
  double z;
  if (kExact) {
    z = drop_on_owned(cutter, x, y, t, best);
  } else {
    const double zp = c.plane_a[q] * x + c.plane_b[q] * y + c.plane_c[q];
    if (zp <= best) return;  // the plane bounds the triangle (+inf for a plane not facing up: edges only)
    z = zp != INFINITY && inside_xy(t.p[0], t.p[1], t.p[2], x + c.contact_dx[q], y + c.contact_dy[q])
            ? zp
            : owned_edges_drop(cutter, x, y, t, best);
  }
  if (z > best) {
    best = z;
    winner = static_cast<int32_t>(q);
  }
}

// The scan of a tile's list from a lower bound `best` (winner: the position in the list that gave it, or -1)
// up to the first contact above `ceiling`, skipping position `skip` (a warm start's, already tested).
// Candidates are filtered in blocks without branches (top above best, box within reach, plane bound above
// best, each a bound of the exact test's own pruning): most fail, and a mispredicted branch per candidate
// cost more than the exact tests.
template <Reach kReach, bool kExact = false>
double scan_tile(const MeshIndex& index, const Cutter& cutter, const TileCandidates& c, double x, double y,
                 double best, int32_t& winner, std::size_t skip, std::size_t& tested, double ceiling) {
  const double r2 = cutter.max_radius() * cutter.max_radius();
  const std::size_t m = c.zmax.size();  // a multiple of kBlock
  for (std::size_t k = 0; k < m && !(best > ceiling); k += kBlock) {
    if (c.zmax[k] <= best) break;  // sorted: nothing from here on can hold the cutter above best
    unsigned mask = block_mask<kReach>(c, k, x, y, r2, best, cutter.corner_radius(), cutter.arc_centre_radius());
    while (mask) {
      const std::size_t q = k + static_cast<std::size_t>(__builtin_ctz(mask));
      mask &= mask - 1;
      const double top = c.zmax[q];
      if (!(top > best) || q == skip || best > ceiling) continue;  // best may have risen within the block
      if (kReach != Reach::Scalar) {
        // within reach of a lower best: the exact test prunes with its own bounds
        test_candidate<kExact>(index, cutter, c, q, x, y, best, winner, tested);
        continue;
      }
      const double dx = maxd(maxd(c.xmin[q] - x, x - c.xmax[q]), 0.0);
      const double dy = maxd(maxd(c.ymin[q] - y, y - c.ymax[q]), 0.0);
      if (dx * dx + dy * dy < cutter.reach2(top - best))
        test_candidate<kExact>(index, cutter, c, q, x, y, best, winner, tested);
    }
  }
  return best;
}

// drop_point over a tile's candidate list; same result as the walk (the same bounds, a different order).
template <Reach kReach>
double drop_point_in_tile(const MeshIndex& index, const Cutter& cutter, const TileCandidates& c, double x,
                          double y, double floor_z, std::size_t& tested, int32_t& hint, double ceiling) {
  double best = floor_z;
  int32_t winner = -1;  // position in the tile's list
  // Warm start: the previous point's winner (a position in this list) gives a true lower bound at once.
  if (hint >= 0) test_candidate<false>(index, cutter, c, static_cast<std::size_t>(hint), x, y, best, winner, tested);
  best = scan_tile<kReach>(index, cutter, c, x, y, best, winner, static_cast<std::size_t>(hint), tested, ceiling);
  hint = winner;
  return best;
}

}  // namespace

namespace {

// drop_batch with the floor of point i = floors ? floors[i] : floor_z.
// ceiling: each point's scan stops at its first contact above it and reports min(h, ceiling).
void drop_batch_floors(const MeshIndex& index, const Cutter& cutter, const double* xy, std::size_t n,
                       const double* floors, double floor_z, double* z_out, const BatchOptions& options,
                       DropStats* stats, double ceiling = INFINITY) {
  auto floor_of = [&](std::size_t i) { return floors ? floors[i] : floor_z; };
  // Tiles: points sorted by tile (stable within a tile, so a raster keeps its order and the warm-start
  // hint its value); points with a non-finite coordinate go alone through drop_point (the floor). Heights
  // do not depend on the thread count: tiles and their hints do not.
  const double tile = kTileFactor * cutter.max_radius();
  double x0 = INFINITY, y0 = INFINITY, x1 = -INFINITY, y1 = -INFINITY;
  for (std::size_t i = 0; i < n; ++i) {
    const double x = xy[2 * i], y = xy[2 * i + 1];
    if (!std::isfinite(x) || !std::isfinite(y)) continue;
    x0 = std::min(x0, x);
    x1 = std::max(x1, x);
    y0 = std::min(y0, y);
    y1 = std::max(y1, y);
  }
  const double span = std::max(x1 - x0, y1 - y0);
  constexpr double kMaxTiles = 1 << 26;  // per side; beyond it tiles are pointless anyway
  const bool tiled = n > 0 && x0 <= x1 && span / tile < kMaxTiles;
  std::vector<std::uint64_t> key(n, ~std::uint64_t{0});
  if (tiled) {
    for (std::size_t i = 0; i < n; ++i) {
      const double x = xy[2 * i], y = xy[2 * i + 1];
      if (!std::isfinite(x) || !std::isfinite(y)) continue;
      const auto ix = static_cast<std::uint64_t>((x - x0) / tile);
      const auto iy = static_cast<std::uint64_t>((y - y0) / tile);
      key[i] = (iy << 27) | ix;
    }
  }
  std::vector<std::size_t> order(n);
  // By a counting sort on the tile's place in the box when the tiles are not many more than the points (a
  // grid, a raster: O(n)), else a stable sort of the keys; the same order.
  const double tiles_x = tiled ? std::floor((x1 - x0) / tile) + 1.0 : 0.0;
  const double tiles_y = tiled ? std::floor((y1 - y0) / tile) + 1.0 : 0.0;
  if (tiled && tiles_x * tiles_y <= 4.0 * static_cast<double>(n) + 1024.0) {
    const auto ntx = static_cast<std::uint64_t>(tiles_x);
    const std::size_t buckets = static_cast<std::size_t>(tiles_x * tiles_y) + 1;  // the last: untiled points
    auto bucket = [&](std::size_t i) {
      const std::uint64_t k = key[i];
      return k == ~std::uint64_t{0} ? buckets - 1 : static_cast<std::size_t>((k >> 27) * ntx + (k & ((1u << 27) - 1)));
    };
    std::vector<std::size_t> start(buckets + 1, 0);
    for (std::size_t i = 0; i < n; ++i) ++start[bucket(i) + 1];
    for (std::size_t b = 0; b < buckets; ++b) start[b + 1] += start[b];
    for (std::size_t i = 0; i < n; ++i) order[start[bucket(i)]++] = i;
  } else {
    for (std::size_t i = 0; i < n; ++i) order[i] = i;
    if (tiled)
      std::stable_sort(order.begin(), order.end(), [&](std::size_t a, std::size_t b) { return key[a] < key[b]; });
  }
  // Runs of one key; untiled points (and tiles too sparse for a list) are runs of one point.
  std::vector<std::size_t> run_start;
  for (std::size_t k = 0; k < n;) {
    std::size_t e = k + 1;
    if (tiled && key[order[k]] != ~std::uint64_t{0})
      while (e < n && key[order[e]] == key[order[k]]) ++e;
    run_start.push_back(k);
    k = e;
  }
  run_start.push_back(n);
  const std::size_t runs = run_start.size() - 1;

  // The tile scan specialised for the cutter's reach test, chosen once.
  const auto drop_in_tile = cutter.kind() == CutterKind::Flat   ? &drop_point_in_tile<Reach::Flat>
                            : cutter.kind() == CutterKind::Ball ? &drop_point_in_tile<Reach::Ball>
                            : cutter.kind() == CutterKind::Bull ? &drop_point_in_tile<Reach::Bull>
                                                                : &drop_point_in_tile<Reach::Scalar>;
  std::atomic<std::size_t> tested{0};
  const bool capped = ceiling < INFINITY;
  const auto& tris = index.triangles();
  parallel_chunks(runs, 16, options, [&](std::size_t begin, std::size_t end) {
    std::size_t local = 0;
    TileCandidates cands;
    for (std::size_t r = begin; r < end; ++r) {
      const std::size_t a = run_start[r], b = run_start[r + 1];
      int32_t hint = -1;
      bool listed = b - a >= kMinTilePoints && key[order[a]] != ~std::uint64_t{0};
      // Capped heights (a waterline's grid): while the tile's points stand above the ceiling (over the top of
      // a part) they are solved without its list: the last winner alone lifting the tool above the ceiling
      // gives the ceiling, else a walk that stops at the first contact above it; the list is gathered at the
      // first point below the ceiling.
      int32_t last = -1;  // the last winner, a position in tris
      std::size_t k = a;
      if (capped && listed) {
        DropStats s;
        for (; k < b; ++k) {
          const std::size_t i = order[k];
          const double x = xy[2 * i], y = xy[2 * i + 1];
          if (last >= 0) {
            ++s.triangles_tested;
            if (drop_on_owned(cutter, x, y, tris[static_cast<std::size_t>(last)], floor_of(i)) > ceiling) {
              z_out[i] = ceiling;
              continue;
            }
          }
          int32_t winner = last;
          const double h = drop_point(index, cutter, x, y, floor_of(i), &s, &winner, ceiling);
          z_out[i] = std::min(h, ceiling);
          if (!(h > ceiling)) {
            ++k;
            break;
          }
          last = winner;
        }
        local += s.triangles_tested;
        if (k == b) continue;
      }
      if (listed) {
        double tx0 = INFINITY, ty0 = INFINITY, tx1 = -INFINITY, ty1 = -INFINITY;
        for (std::size_t j = a; j < b; ++j) {
          const std::size_t i = order[j];
          tx0 = std::min(tx0, xy[2 * i]);
          tx1 = std::max(tx1, xy[2 * i]);
          ty0 = std::min(ty0, xy[2 * i + 1]);
          ty1 = std::max(ty1, xy[2 * i + 1]);
        }
        double tile_floor = INFINITY;  // the lowest floor of the tile's points bounds the list
        for (std::size_t j = a; j < b; ++j) tile_floor = std::min(tile_floor, floor_of(order[j]));
        listed = cands.gather(index, cutter, tx0, ty0, tx1, ty1, tile_floor, kMaxCandidatesPerPoint * (b - a));
      }
      if (!listed) {
        DropStats s;
        for (; k < b; ++k) {
          const std::size_t i = order[k];
          z_out[i] = std::min(drop_point(index, cutter, xy[2 * i], xy[2 * i + 1], floor_of(i), &s, &hint, ceiling),
                              ceiling);
        }
        local += s.triangles_tested;
        continue;
      }
      for (; k < b; ++k) {
        const std::size_t i = order[k];
        const double x = xy[2 * i], y = xy[2 * i + 1], floor_i = floor_of(i);
        z_out[i] = std::min(drop_in_tile(index, cutter, cands, x, y, floor_i, local, hint, ceiling), ceiling);
      }
    }
    tested.fetch_add(local);
  });
  if (stats) stats->triangles_tested += tested.load();
}

}  // namespace

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
