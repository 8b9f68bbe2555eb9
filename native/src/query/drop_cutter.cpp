// The drop-cutter on one triangle and at one point (the tree walk); batches and tiles: drop_batch.cpp.
#include "tmm/query/drop_cutter.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>

#include "drop_tile_scan.hpp"
#include "tmm/query/drop_contacts.hpp"

namespace tmm {

double drop_on_triangle(const Cutter& c, double x, double y, const IndexedTriangle& t, double above) {
  double z = std::max(above, facet_drop(c, x, y, t.p[0], t.p[1], t.p[2], t.n, t.zmax, above));
  z = std::max(z, edge_drop(c, x, y, t.p[0], t.p[1], z));
  z = std::max(z, edge_drop(c, x, y, t.p[1], t.p[2], z));
  z = std::max(z, edge_drop(c, x, y, t.p[2], t.p[0], z));
  return z > above ? z : kNoContact;
}

double drop_point(const MeshIndex& index, const Cutter& cutter, double x, double y, double floor_z,
                  DropStats* stats, int32_t* hint, double ceiling) {
  double best = floor_z;
  int32_t winner = -1;
  std::size_t tested = 0;
  const auto& tris = index.triangles();
  if (hint && *hint >= 0 && static_cast<std::size_t>(*hint) < tris.size()) {
    ++tested;
    const double z = drop_detail::drop_on_owned(cutter, x, y, tris[*hint], best);
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
      const double z = drop_detail::drop_on_owned(cutter, x, y, t, best);
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

}  // namespace tmm
