#include "tmm/drop_cutter.hpp"

#include <algorithm>
#include <atomic>
#include <vector>

#include "tmm/drop_contacts.hpp"

namespace tmm {

double drop_on_triangle(const Cutter& c, double x, double y, const IndexedTriangle& t, double above) {
  double z = std::max(above, facet_drop(c, x, y, t.p[0], t.p[1], t.p[2], t.n, t.zmax, above));
  z = std::max(z, edge_drop(c, x, y, t.p[0], t.p[1], z));
  z = std::max(z, edge_drop(c, x, y, t.p[1], t.p[2], z));
  z = std::max(z, edge_drop(c, x, y, t.p[2], t.p[0], z));
  return z > above ? z : kNoContact;
}

namespace {

// drop_on_triangle for the walk. The drop onto the triangle's plane bounds the triangle's contact; when its
// contact point lies inside the triangle it is that contact (no edge can be higher), otherwise only the
// edges this triangle owns are solved (see IndexedTriangle::owned_edges), and only if the plane bound
// exceeds `above`.
double drop_on_owned(const Cutter& c, double x, double y, const IndexedTriangle& t, double above) {
  bool inside = false;
  const double zp = plane_drop(c, x, y, t.p[0], t.p[1], t.p[2], t.n, inside);
  if (zp != kNoContact) {  // a plane that faces up: its drop bounds the triangle's
    if (zp <= above) return kNoContact;
    if (inside) return zp;
  }
  double z = above;
  if (t.owned_edges & 1u) z = std::max(z, edge_drop(c, x, y, t.p[0], t.p[1], z));
  if (t.owned_edges & 2u) z = std::max(z, edge_drop(c, x, y, t.p[1], t.p[2], z));
  if (t.owned_edges & 4u) z = std::max(z, edge_drop(c, x, y, t.p[2], t.p[0], z));
  return z > above ? z : kNoContact;
}

}  // namespace

double drop_point(const MeshIndex& index, const Cutter& cutter, double x, double y, double floor_z,
                  DropStats* stats, int32_t* hint) {
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
  const int32_t skip = winner;
  index.walk(x, y, cutter, best, [&](const IndexedTriangle& t, int32_t i) {
    if (i == skip) return;
    ++tested;
    const double z = drop_on_owned(cutter, x, y, t, best);
    if (z > best) {
      best = z;
      winner = i;
    }
  });
  if (stats) stats->triangles_tested += tested;
  if (hint) *hint = winner;
  return best;
}

void drop_batch(const MeshIndex& index, const Cutter& cutter, const double* xy, std::size_t n,
                double floor_z, double* z_out, const BatchOptions& options, DropStats* stats) {
  std::atomic<std::size_t> tested{0};
  // Chunks of consecutive points: footprints are ordered, so neighbours share the same triangles. The
  // warm-start hint starts afresh with each chunk, so results do not depend on the thread count.
  parallel_chunks(n, 256, options, [&](std::size_t begin, std::size_t end) {
    DropStats local;
    int32_t hint = -1;
    for (std::size_t i = begin; i < end; ++i)
      z_out[i] = drop_point(index, cutter, xy[2 * i], xy[2 * i + 1], floor_z, &local, &hint);
    tested.fetch_add(local.triangles_tested);
  });
  if (stats) stats->triangles_tested += tested.load();
}

}  // namespace tmm
