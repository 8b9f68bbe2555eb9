#include "tmm/mesh/mesh.hpp"

#include <Eigen/Geometry>

#include <algorithm>
#include <cmath>
#include <limits>
#include <sstream>
#include <stdexcept>
#include <string>
#include <vector>

#include "tmm/util/parallel.hpp"
#include "tmm/util/range.hpp"
#include "mesh_passes.hpp"

namespace tmm {
using mesh_passes::adjacency;
using mesh_passes::check_mesh;
using mesh_passes::kNone;
using mesh_passes::unit_face_normals;
using mesh_passes::vertex;

namespace {

using Vec3 = Eigen::Vector3d;

std::string num(double x) {
  std::ostringstream s;
  s.precision(17);
  s << x;
  return s.str();
}

// ---------------------------------------------------------------------------------------------------
// Welding: a hash grid of cubic cells keyed by integer cell coordinates. Each occupied cell holds a
// singly linked list of the vertices whose position lies in it (heads in an open-addressing table,
// links in `next`), so building it allocates only a few flat arrays, never per vertex.

// floor(x) for |x| < 2^62, without a libm call.
int64_t floor_int(double x) {
  const auto i = static_cast<int64_t>(x);
  return i - (x < static_cast<double>(i));
}

struct Cell {
  int64_t x, y, z;
  bool operator==(const Cell& o) const { return x == o.x && y == o.y && z == o.z; }
};

uint64_t hash_cell(const Cell& c) {
  uint64_t h = static_cast<uint64_t>(c.x) * 0x9E3779B97F4A7C15ull;
  h ^= static_cast<uint64_t>(c.y) * 0xC2B2AE3D27D4EB4Full + (h << 6) + (h >> 2);
  h ^= static_cast<uint64_t>(c.z) * 0x165667B19E3779F9ull + (h << 6) + (h >> 2);
  h ^= h >> 31;  // splitmix64 finaliser: the low bits index the table, so mix the high bits down
  h *= 0xBF58476D1CE4E5B9ull;
  h ^= h >> 27;
  return h;
}

class WeldGrid {
 public:
  WeldGrid(double cell, Eigen::Index triangles) : inv_cell_(1.0 / cell) {
    // A closed mesh has about m/2 vertices; both arrays grow if there are more.
    std::size_t cap = 64;
    while (cap < static_cast<std::size_t>(triangles)) cap *= 2;
    slots_.assign(cap, Slot{});
    pos_.resize(triangles / 2 + 64, 3);
    next_.reserve(static_cast<std::size_t>(pos_.rows()));
  }

  // Cells are centred on multiples of the cell size, so round coordinates sit far from cell faces.
  Cell cell_of(const Vec3& p) const {
    return {floor_int(p.x() * inv_cell_ + 0.5), floor_int(p.y() * inv_cell_ + 0.5), floor_int(p.z() * inv_cell_ + 0.5)};
  }

  // Starts loading the table slot of p's own cell: for big meshes nearly every first lookup of a vertex
  // misses the cache, so the caller asks a few corners ahead.
  void prefetch(const Vec3& p) const {
#if defined(__GNUC__) || defined(__clang__)
    __builtin_prefetch(&slots_[hash_cell(cell_of(p)) & (slots_.size() - 1)]);
#endif
  }

  Vec3 position(int32_t v) const { return pos_.row(v).transpose(); }

  // Nearest vertex within sqrt(tol2) of p, or kNone. Looks at every cell the ball of radius `reach`
  // (tol plus a rounding margin) around p touches: with cells 16*tol wide, usually just its own.
  int32_t find(const Vec3& p, double tol2, double reach) const {
    const Cell own = cell_of(p);
    int32_t best = kNone;
    double best_d2 = std::numeric_limits<double>::infinity();
    if (scan(own, p, tol2, best, best_d2)) return best;  // identical corners are by far the common case
    const Cell lo = cell_of(p - Vec3::Constant(reach));
    const Cell hi = cell_of(p + Vec3::Constant(reach));
    for (int64_t cx = lo.x; cx <= hi.x; ++cx)
      for (int64_t cy = lo.y; cy <= hi.y; ++cy)
        for (int64_t cz = lo.z; cz <= hi.z; ++cz) {
          const Cell c{cx, cy, cz};
          if (!(c == own) && scan(c, p, tol2, best, best_d2)) return best;
        }
    return best;
  }

  int32_t add(const Vec3& p) {
    const auto v = static_cast<int32_t>(next_.size());
    if (v == pos_.rows()) pos_.conservativeResize(pos_.rows() + pos_.rows() / 2, 3);  // realloc, no copy
    pos_.row(v) = p.transpose();
    const Cell c = cell_of(p);
    const uint64_t h = hash_cell(c);
    Slot& s = slots_[probe(c, h)];
    if (s.head == kNone) ++used_;
    next_.push_back(s.head);
    s = Slot{static_cast<uint32_t>(h >> 32), v};
    if (2 * used_ > slots_.size()) grow();
    return v;
  }

  // The vertex positions, in the order they were added; the grid is unusable afterwards.
  Vertices take_positions() && {
    pos_.conservativeResize(static_cast<Eigen::Index>(next_.size()), 3);
    return std::move(pos_);
  }

 private:
  struct Slot {
    uint32_t tag = 0;      // high hash bits, to skip most foreign cells without touching their vertices
    int32_t head = kNone;  // first vertex of the cell's list; kNone marks an empty slot
  };

  // Index of the slot holding cell c, or of the empty slot where it would go.
  std::size_t probe(const Cell& c, uint64_t h) const {
    const std::size_t mask = slots_.size() - 1;
    const auto tag = static_cast<uint32_t>(h >> 32);
    for (std::size_t i = h & mask;; i = (i + 1) & mask) {
      const Slot& s = slots_[i];
      if (s.head == kNone || (s.tag == tag && cell_of(position(s.head)) == c)) return i;
    }
  }

  bool scan(const Cell& c, const Vec3& p, double tol2, int32_t& best, double& best_d2) const {
    for (int32_t v = slots_[probe(c, hash_cell(c))].head; v != kNone; v = next_[static_cast<std::size_t>(v)]) {
      const double d2 = (position(v) - p).squaredNorm();
      if (d2 <= tol2 && d2 < best_d2) {
        best = v;
        best_d2 = d2;
        if (d2 == 0) return true;
      }
    }
    return false;
  }

  // Doubles the table. Walking the vertices in order (not the old slots) reads positions sequentially;
  // the last vertex of each cell ends up as its head, as add() left it, so `next` stays valid.
  void grow() {
    slots_.assign(slots_.size() * 2, Slot{});
    for (int32_t v = 0; v < static_cast<int32_t>(next_.size()); ++v) {
      const Cell c = cell_of(position(v));
      const uint64_t h = hash_cell(c);
      slots_[probe(c, h)] = Slot{static_cast<uint32_t>(h >> 32), v};
    }
  }

  double inv_cell_;
  std::vector<Slot> slots_;
  std::size_t used_ = 0;     // occupied slots
  Vertices pos_;             // capacity rows; the first next_.size() are vertices
  std::vector<int32_t> next_;  // next vertex in the same cell
};

// Zero area up to rounding: twice the area |e1 x e2| is below what the rounding of the coordinates
// (magnitude `mag`) can produce for edges of length `len`.
bool zero_area(const Vec3& a, const Vec3& b, const Vec3& c) {
  const Vec3 e1 = b - a, e2 = c - a, e3 = c - b;
  const double len = std::sqrt(std::max({e1.squaredNorm(), e2.squaredNorm(), e3.squaredNorm()}));
  const double mag = std::max({a.cwiseAbs().maxCoeff(), b.cwiseAbs().maxCoeff(), c.cwiseAbs().maxCoeff(), len});
  return e1.cross(e2).norm() <= 16 * std::numeric_limits<double>::epsilon() * len * mag;
}

// Incident triangles of each vertex in compressed rows: triangles of v are tri[start[v] .. start[v+1]).
// A triangle is listed once per distinct vertex, even if an index repeats in it.
struct VertexTriangles {
  std::vector<int32_t> start, tri;

  // Reports its two passes over the triangles in progress's current part.
  VertexTriangles(const TrianglesRef& F, Eigen::Index n, SerialProgress& progress)
      : start(static_cast<std::size_t>(n) + 1, 0) {
    auto distinct = [&](Eigen::Index t, int i) {
      return (i < 1 || F(t, i) != F(t, 0)) && (i < 2 || F(t, i) != F(t, 1));
    };
    const auto m = static_cast<std::size_t>(F.rows());
    for (Eigen::Index t = 0; t < F.rows(); ++t) {
      progress.tick(static_cast<std::size_t>(t), 2 * m);
      for (int i = 0; i < 3; ++i)
        if (distinct(t, i)) ++start[static_cast<std::size_t>(F(t, i)) + 1];
    }
    for (std::size_t v = 1; v < start.size(); ++v) start[v] += start[v - 1];
    tri.resize(static_cast<std::size_t>(start.back()));
    std::vector<int32_t> fill(start.begin(), start.end() - 1);
    for (Eigen::Index t = 0; t < F.rows(); ++t) {
      progress.tick(m + static_cast<std::size_t>(t), 2 * m);
      for (int i = 0; i < 3; ++i)
        if (distinct(t, i)) tri[static_cast<std::size_t>(fill[static_cast<std::size_t>(F(t, i))]++)] = static_cast<int32_t>(t);
    }
  }
};

Eigen::Index vertex_count(const TrianglesRef& F) {
  int32_t max_index = -1;
  for (Eigen::Index t = 0; t < F.rows(); ++t)
    for (int i = 0; i < 3; ++i) {
      if (F(t, i) < 0)
        throw std::invalid_argument("triangle " + std::to_string(t) + " has a negative vertex index " +
                                    std::to_string(F(t, i)));
      max_index = std::max(max_index, F(t, i));
    }
  return static_cast<Eigen::Index>(max_index) + 1;
}

}  // namespace

// Face normals without validation; zero rows for zero-area faces.
Normals mesh_passes::unit_face_normals(const VerticesRef& V, const TrianglesRef& F, SerialProgress& progress) {
  Normals N(F.rows(), 3);
  for (Eigen::Index t = 0; t < F.rows(); ++t) {
    progress.tick(static_cast<std::size_t>(t), static_cast<std::size_t>(F.rows()));
    const Vec3 a = vertex(V, F(t, 0));
    const Vec3 c = (vertex(V, F(t, 1)) - a).cross(vertex(V, F(t, 2)) - a);
    const double len = c.norm();
    N.row(t) = (len > 0 ? Vec3(c / len) : Vec3::Zero()).transpose();
  }
  return N;
}

namespace {

// The largest coordinate magnitude of the soup; throws naming the first non-finite or out-of-range one.
double checked_magnitude(const SoupRef& soup, SerialProgress& progress) {
  const Eigen::Index m = soup.rows();
  double mag = 0;
  for (Eigen::Index t = 0; t < m; ++t) {
    progress.tick(static_cast<std::size_t>(t), static_cast<std::size_t>(m));
    if (!soup.row(t).allFinite())
      throw std::invalid_argument("triangle " + std::to_string(t) + " has a non-finite coordinate");
    mag = std::max(mag, soup.row(t).cwiseAbs().maxCoeff());
  }
  if (!in_range(mag)) {
    for (Eigen::Index t = 0; t < m; ++t)
      for (int k = 0; k < 3 * 3; ++k)
        require_in_range(soup(t, k), "triangle " + std::to_string(t) + " corner " + std::to_string(k / 3) +
                                         " coordinate " + "xyz"[k % 3]);
  }
  return mag;
}

// The corners joined into vertices: mesh.F holds every triangle, mesh.V the vertices in order of first use.
Mesh weld_corners(const SoupRef& soup, double tol, double mag, SerialProgress& progress) {
  const Eigen::Index m = soup.rows();
  // Cells 16*tol wide, so a tol-ball around a corner usually stays in one cell (a neighbour is looked
  // at along an axis only within tol of a cell face), and coarse enough that cell coordinates stay far
  // inside int64 even for a tiny or zero tolerance.
  const double cell = std::max({16 * tol, mag * 0x1p-40, std::numeric_limits<double>::min() * 0x1p60});
  const double reach = tol + 8 * std::numeric_limits<double>::epsilon() * mag;  // rounding margin
  const double tol2 = tol * tol;
  WeldGrid grid(cell, m);

  // Big meshes are bound by memory, not arithmetic: corner indices go straight into the result's F (then
  // compacted in place), and each corner's table slot is prefetched a few triangles ahead.
  Mesh mesh;
  mesh.F.resize(m, 3);
  constexpr Eigen::Index kAhead = 4;  // triangles
  for (Eigen::Index t = 0; t < m; ++t) {
    progress.tick(static_cast<std::size_t>(t), static_cast<std::size_t>(m));
    if (t + kAhead < m)
      for (int k = 0; k < 3; ++k) grid.prefetch(soup.block<1, 3>(t + kAhead, 3 * k).transpose());
    for (int k = 0; k < 3; ++k) {
      const Vec3 p = soup.block<1, 3>(t, 3 * k).transpose();
      int32_t v = grid.find(p, tol2, reach);
      if (v == kNone) v = grid.add(p);
      mesh.F(t, k) = v;
    }
  }
  mesh.V = std::move(grid).take_positions();
  return mesh;
}

// Drops the degenerate triangles of mesh.F (order kept); returns how many.
std::size_t drop_degenerate(Mesh& mesh, SerialProgress& progress) {
  const Eigen::Index m = mesh.F.rows();
  Eigen::Index kept = 0;
  for (Eigen::Index t = 0; t < m; ++t) {
    progress.tick(static_cast<std::size_t>(t), static_cast<std::size_t>(m));
    const int32_t a = mesh.F(t, 0), b = mesh.F(t, 1), c = mesh.F(t, 2);
    if (a == b || b == c || a == c || zero_area(mesh.V.row(a), mesh.V.row(b), mesh.V.row(c))) continue;
    mesh.F.row(kept++) = mesh.F.row(t);
  }
  if (kept > 0) mesh.F.conservativeResize(kept, 3);
  return static_cast<std::size_t>(m - kept);
}

// Renumbers the vertices in order of first use by the triangles left, dropping the unused ones.
void drop_unused_vertices(Mesh& mesh, SerialProgress& progress) {
  std::vector<int32_t> renumber(static_cast<std::size_t>(mesh.V.rows()), kNone);
  int32_t n = 0;
  const auto corners = static_cast<std::size_t>(mesh.F.size());
  for (std::size_t i = 0; i < corners; ++i) {
    progress.tick(i, corners);
    int32_t& r = renumber[static_cast<std::size_t>(mesh.F.data()[i])];
    if (r == kNone) r = n++;
    mesh.F.data()[i] = r;
  }
  Vertices V(n, 3);
  for (std::size_t v = 0; v < renumber.size(); ++v)
    if (renumber[v] != kNone) V.row(renumber[v]) = mesh.V.row(static_cast<Eigen::Index>(v));
  mesh.V = std::move(V);
}

}  // namespace

Mesh weld(const SoupRef& soup, double tol, std::size_t* degenerate_removed,
          const std::function<bool(double)>& progress) {
  const Eigen::Index m = soup.rows();
  if (m == 0) throw std::invalid_argument("no triangles to weld");
  if (!std::isfinite(tol) || tol < 0)
    throw std::invalid_argument("weld tolerance must be finite and >= 0, got " + num(tol));
  if (m > std::numeric_limits<int32_t>::max() / 3)
    throw std::invalid_argument("too many triangles for 32-bit indices: " + std::to_string(m));
  // Parts by their measured share of the time (the grid lookups are most of it).
  SerialProgress reporter(progress);
  reporter.part(0.0, 0.05);
  const double mag = checked_magnitude(soup, reporter);
  reporter.part(0.05, 0.9);
  Mesh mesh = weld_corners(soup, tol, mag, reporter);
  reporter.part(0.9, 0.97);
  const std::size_t removed = drop_degenerate(mesh, reporter);
  if (degenerate_removed) *degenerate_removed = removed;
  if (removed == static_cast<std::size_t>(m))
    throw std::invalid_argument("no non-degenerate triangles (all " + std::to_string(m) +
                                " collapse to a line or a point at weld tolerance " + num(tol) + ")");
  // Vertices are numbered in order of first use; only if triangles were dropped can some be unused.
  reporter.part(0.97, 1.0);
  if (removed > 0) drop_unused_vertices(mesh, reporter);
  reporter.finish();
  return mesh;
}

void require_vertices_in_range(const VerticesRef& V) {
  for (Eigen::Index v = 0; v < V.rows(); ++v)
    for (int k = 0; k < 3; ++k)
      if (!in_range(V(v, k))) require_in_range(V(v, k), "vertex " + std::to_string(v) + " coordinate " + "xyz"[k]);
}

// validate(), reporting its pass over the triangles (a big mesh's check is a pause of its own).
void mesh_passes::check_mesh(const VerticesRef& V, const TrianglesRef& F, SerialProgress& progress) {
  for (Eigen::Index v = 0; v < V.rows(); ++v)
    if (!V.row(v).allFinite()) throw std::invalid_argument("vertex " + std::to_string(v) + " has a non-finite coordinate");
  require_vertices_in_range(V);
  for (Eigen::Index t = 0; t < F.rows(); ++t) {
    progress.tick(static_cast<std::size_t>(t), static_cast<std::size_t>(F.rows()));
    for (int i = 0; i < 3; ++i)
      if (F(t, i) < 0 || F(t, i) >= V.rows())
        throw std::invalid_argument("triangle " + std::to_string(t) + " references vertex " + std::to_string(F(t, i)) +
                                    ", but there are " + std::to_string(V.rows()) + " vertices");
  }
}

void validate(const VerticesRef& V, const TrianglesRef& F) {
  const std::function<bool(double)> none;
  SerialProgress quiet(none);
  check_mesh(V, F, quiet);
}

Normals face_normals(const VerticesRef& V, const TrianglesRef& F, const std::function<bool(double)>& progress) {
  SerialProgress reporter(progress);
  reporter.part(0.0, 0.05);
  check_mesh(V, F, reporter);
  reporter.part(0.05, 1.0);
  Normals N = unit_face_normals(V, F, reporter);
  reporter.finish();
  return N;
}

namespace {

// The triangles with their vertices renumbered 0..k-1 in index order when the largest index exceeds the
// number of corners (unused vertices, or a bad index): tables sized by the vertex count then follow the
// triangles, not an index value (2^31 - 1 would ask for gigabytes). Adjacency depends only on equality.
Triangles compact_indices(const TrianglesRef& F, SerialProgress& progress) {
  const auto m = static_cast<std::size_t>(F.rows());
  std::vector<int32_t> used;
  used.reserve(3 * m);
  for (Eigen::Index t = 0; t < F.rows(); ++t) {
    progress.tick(static_cast<std::size_t>(t), 2 * m);
    for (int i = 0; i < 3; ++i) used.push_back(F(t, i));
  }
  std::sort(used.begin(), used.end());
  used.erase(std::unique(used.begin(), used.end()), used.end());
  Triangles C(F.rows(), 3);
  for (Eigen::Index t = 0; t < F.rows(); ++t) {
    progress.tick(m + static_cast<std::size_t>(t), 2 * m);
    for (int i = 0; i < 3; ++i)
      C(t, i) = static_cast<int32_t>(std::lower_bound(used.begin(), used.end(), F(t, i)) - used.begin());
  }
  return C;
}

}  // namespace

// triangle_adjacency, reporting within [lo, hi] of the job (the vertex table takes some 40 % of the time).
Adjacency mesh_passes::adjacency(const TrianglesRef& F, SerialProgress& progress, double lo, double hi) {
  const Eigen::Index n = vertex_count(F);  // refuses negative indices
  const double mid = lo + 0.4 * (hi - lo);
  progress.part(lo, mid);
  if (n > 3 * F.rows()) return adjacency(compact_indices(F, progress), progress, mid, hi);
  const VertexTriangles vt(F, n, progress);
  progress.part(mid, hi);
  Adjacency A(F.rows(), 3);
  for (Eigen::Index t = 0; t < F.rows(); ++t) {
    progress.tick(static_cast<std::size_t>(t), static_cast<std::size_t>(F.rows()));
    for (int i = 0; i < 3; ++i) {
      const int32_t a = F(t, i), b = F(t, (i + 1) % 3);
      int32_t found = kNone;
      int count = 0;
      if (a != b) {  // an edge with equal endpoints has no neighbour
        const auto va = static_cast<std::size_t>(a);
        for (int32_t j = vt.start[va]; j < vt.start[va + 1]; ++j) {
          const int32_t s = vt.tri[static_cast<std::size_t>(j)];
          if (s != t && (F(s, 0) == b || F(s, 1) == b || F(s, 2) == b)) {
            found = s;
            ++count;
          }
        }
      }
      A(t, i) = count == 1 ? found : kNone;  // non-manifold (count > 1): no single neighbour
    }
  }
  return A;
}

Adjacency triangle_adjacency(const TrianglesRef& F, const std::function<bool(double)>& progress) {
  SerialProgress reporter(progress);
  Adjacency A = adjacency(F, reporter, 0.0, 1.0);
  reporter.finish();
  return A;
}

}  // namespace tmm
