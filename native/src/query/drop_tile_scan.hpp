// The drop-cutter's tile scan (internal to src/query): a batch's points grouped into tiles, each tile's
// candidate triangles gathered once in order of decreasing height, each point scanning that list with a
// branch-free block filter. Shared by the point query (drop_cutter.cpp) and the batches and DropTiles
// (drop_batch.cpp).
#pragma once

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <utility>
#include <vector>

#if defined(__SSE2__)
#include <emmintrin.h>
#endif

#include "tmm/query/drop_assembly.hpp"
#include "tmm/query/drop_contacts.hpp"
#include "tmm/query/drop_cutter.hpp"

namespace tmm {
namespace drop_detail {

// The box of a batch's finite points; x0 > x1 when there is none.
struct PointsBox {
  double x0 = INFINITY, y0 = INFINITY, x1 = -INFINITY, y1 = -INFINITY;
};

inline PointsBox finite_box(const double* xy, std::size_t n) {
  PointsBox b;
  for (std::size_t i = 0; i < n; ++i) {
    const double x = xy[2 * i], y = xy[2 * i + 1];
    if (!std::isfinite(x) || !std::isfinite(y)) continue;
    b.x0 = std::min(b.x0, x);
    b.x1 = std::max(b.x1, x);
    b.y0 = std::min(b.y0, y);
    b.y1 = std::max(b.y1, y);
  }
  return b;
}

// The highest contact above `above` of the edges (and so the vertices) this triangle owns (see
// IndexedTriangle::owned_edges), or -inf.
inline double owned_edges_drop(const Cutter& c, double x, double y, const IndexedTriangle& t, double above) {
  double z = above;
  if (t.owned_edges & 1u) z = std::max(z, edge_drop(c, x, y, t.p[0], t.p[1], z));
  if (t.owned_edges & 2u) z = std::max(z, edge_drop(c, x, y, t.p[1], t.p[2], z));
  if (t.owned_edges & 4u) z = std::max(z, edge_drop(c, x, y, t.p[2], t.p[0], z));
  return z > above ? z : kNoContact;
}

// drop_on_triangle for the walk. The drop onto the triangle's plane bounds the triangle's contact; when its
// contact point lies inside the triangle it is that contact (no edge can be higher), otherwise only the
// edges this triangle owns are solved, and only if the plane bound exceeds `above`.
inline double drop_on_owned(const Cutter& c, double x, double y, const IndexedTriangle& t, double above) {
  bool inside = false;
  const double zp = plane_drop(c, x, y, t.p[0], t.p[1], t.p[2], t.n, inside);
  if (zp != kNoContact) {  // a plane that faces up: its drop bounds the triangle's
    if (zp <= above) return kNoContact;
    if (inside) return zp;
  }
  return owned_edges_drop(c, x, y, t, above);
}

// A bound of any contact of a profile reaching r from its axis at (x, y) on the segment p-q: the segment's
// highest point within r of the axis in XY (the profile's height above its tip is >= 0), -inf when none lies
// there; widened by a margin against the rounding of the clip.
inline double segment_top_within(double x, double y, double r, const double* p, const double* q) {
  const double dx = q[0] - p[0], dy = q[1] - p[1], fx = p[0] - x, fy = p[1] - y;
  const double reach = r * (1.0 + 1e-12) + 1e-12;
  const double a = dx * dx + dy * dy, b = fx * dx + fy * dy, c = fx * fx + fy * fy - reach * reach;
  double t0 = 0.0, t1 = 1.0;
  if (a > 0.0) {
    const double disc = b * b - a * c;
    if (disc < 0.0) return -INFINITY;
    const double root = std::sqrt(disc);
    t0 = std::max(0.0, (-b - root) / a - 1e-9);
    t1 = std::min(1.0, (-b + root) / a + 1e-9);
    if (t0 > t1) return -INFINITY;
  } else if (c > 0.0) {
    return -INFINITY;
  }
  const double top = std::max(p[2] + t0 * (q[2] - p[2]), p[2] + t1 * (q[2] - p[2]));
  return top + 1e-9 * (1.0 + std::fabs(top));
}

// drop_on_owned with each owned edge first bounded by its part within the profile's reach: the same value, the
// contact solve skipped for an edge that only rises above `above` out of reach (a long wall facet's diagonal
// beside a shank).
inline double drop_on_owned_clipped(const Cutter& c, double x, double y, const IndexedTriangle& t, double above) {
  bool inside = false;
  const double zp = plane_drop(c, x, y, t.p[0], t.p[1], t.p[2], t.n, inside);
  if (zp != kNoContact) {
    if (zp <= above) return kNoContact;
    if (inside) return zp;
  }
  const double r = c.max_radius();
  double z = above;
  for (int k = 0; k < 3; ++k) {
    if (!(t.owned_edges & (1u << k))) continue;
    const double* p = t.p[k];
    const double* q = t.p[(k + 1) % 3];
    if (segment_top_within(x, y, r, p, q) > z) z = std::max(z, edge_drop(c, x, y, p, q, z));
  }
  return z > above ? z : kNoContact;
}

// Does `profile`'s flat bottom rest at height h at (x, y) on triangle t: a corner or an edge of t at h (both
// ends) within the flat bottom's radius? Then the drop is at least h (the flat bottom cannot pass below that
// edge), and exactly h when nothing within reach is higher (h a bound of the heights around). A holder over a
// plateau: the common case, answered without a contact solve.
inline bool rests_flat(const Cutter& profile, const IndexedTriangle& t, double x, double y, double h) {
  const double e = profile.flat_radius();
  if (!(t.zmax == h && e > 0.0 && profile.beta1() == 0.0)) return false;
  for (int k = 0; k < 3; ++k) {
    const double* p = t.p[k];
    const double* q = t.p[(k + 1) % 3];
    if (p[2] != h) continue;
    double s = 0.0;  // the closest point of the edge p-q (of p alone when q is lower)
    const double ex = q[0] - p[0], ey = q[1] - p[1], l2 = ex * ex + ey * ey;
    if (q[2] == h && l2 > 0.0) s = std::clamp(((x - p[0]) * ex + (y - p[1]) * ey) / l2, 0.0, 1.0);
    const double dx = p[0] + s * ex - x, dy = p[1] + s * ey - y;
    if (dx * dx + dy * dy <= e * e) return true;
  }
  return false;
}

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
    sorted.clear();
    index.near_rect(x0, y0, x1, y1, cutter.max_radius(), floor,
                    [&](const IndexedTriangle& t, int32_t i) { sorted.emplace_back(t.zmax, i); });
    return prepare(index, cutter, most);
  }

  // The list from the (top, triangle) pairs in `sorted`, in any order; false (and nothing prepared) when there
  // are more than `most` of them.
  bool prepare(const MeshIndex& index, const Cutter& cutter, std::size_t most) {
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
// contact is higher. kExact: drop_on_owned's value, the very value drop_point gets; else with the tile's
// precomputed plane drop (the same value up to rounding, fewer operations).
template <bool kExact>
inline void test_candidate(const MeshIndex& index, const Cutter& cutter, const TileCandidates& c, std::size_t q,
                           double x, double y, double& best, int32_t& winner, std::size_t& tested) {
  ++tested;
  const IndexedTriangle& t = index.triangles()[c.id[q]];
  double z;
  if (kExact) {
    z = drop_on_owned_clipped(cutter, x, y, t, best);
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
inline double scan_tile(const MeshIndex& index, const Cutter& cutter, const TileCandidates& c, double x, double y,
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
// kExact: each candidate by drop_on_owned, the very values of drop_point's walk.
template <Reach kReach, bool kExact = false>
inline double drop_point_in_tile(const MeshIndex& index, const Cutter& cutter, const TileCandidates& c, double x,
                          double y, double floor_z, std::size_t& tested, int32_t& hint, double ceiling) {
  double best = floor_z;
  int32_t winner = -1;  // position in the tile's list
  // Warm start: the previous point's winner (a position in this list) gives a true lower bound at once.
  if (hint >= 0) test_candidate<kExact>(index, cutter, c, static_cast<std::size_t>(hint), x, y, best, winner, tested);
  best = scan_tile<kReach, kExact>(index, cutter, c, x, y, best, winner, static_cast<std::size_t>(hint), tested, ceiling);
  hint = winner;
  return best;
}

// Followers' lists are bounded tighter than the cutter's: a holder over a dense plateau would gather thousands
// of triangles there that the height cells' bound (drop_assembly.cpp) settles at once.
constexpr std::size_t kMaxFollowerCandidatesPerPoint = 10;

// The bodies of a tool assembly dropped in the cutter's own tiles right after it, one piece after another,
// each from the height so far (as drop_assembly_point). A tile gathers per piece the triangles within its reach
// above the lowest of its points' floors (the index prunes all below: a holder high above the part gathers
// nothing) and scans them per point with drop_point's own per-triangle values. Where a piece has no list (a
// tile too sparse, or its list too long) the tile's points are left open from that piece on, for the caller.
struct FollowPieces {
  const AssemblyPiece* pieces;  // [0] the cutter, [1, count) its followers
  std::size_t count;
  const double* floors;  // per point, or null: floor_z
  double floor_z;
  double* height;            // per point: the height after the pieces before first_open
  int32_t* owner;            // per point: the piece that set it (kSetByFloor when none)
  std::uint8_t* first_open;  // per point: the first piece left open (count when none)

  // Piece p's drop from z + p.lift reached `top`: the height after it, and who set it (as drop_assembly_batch).
  static void raise(double& z, int32_t& by, double top, const AssemblyPiece& p) {
    if (top > z + p.lift && top - p.lift > z) {
      z = top - p.lift;
      by = p.owner;
    }
  }
};

// drop_batch of pieces[0] from the floors floors[i] + lift (or floor_z + lift) into `top` (scratch; may be
// follow.height: a point's cutter height is read before its height is written), its followers (see
// FollowPieces) in the same pass. Needs each follower's lift at or above the cutter's (their
// floors then lie above the cutter's tile floor) and at most 255 pieces.
void drop_batch_follow(const MeshIndex& index, const FollowPieces& follow, const double* xy, std::size_t n,
                       double* top, const BatchOptions& options, DropStats* stats);

}  // namespace drop_detail
}  // namespace tmm
