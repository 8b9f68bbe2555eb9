#include "tmm/drop_cutter.hpp"

#include <algorithm>
#include <atomic>
#include <chrono>
#include <thread>
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

namespace {

// Joins its threads on every exit path.
class ThreadGroup {
 public:
  ~ThreadGroup() {
    for (auto& t : threads_) t.join();
  }
  template <class F>
  void spawn(F&& f) { threads_.emplace_back(std::forward<F>(f)); }

 private:
  std::vector<std::thread> threads_;
};

}  // namespace

void drop_batch(const MeshIndex& index, const Cutter& cutter, const double* xy, std::size_t n,
                double floor_z, double* z_out, const BatchOptions& options, DropStats* stats) {
  int threads = options.threads > 0 ? options.threads
                                    : static_cast<int>(std::max(1u, std::thread::hardware_concurrency()));
  // Chunks of consecutive points: footprints are ordered, so neighbours share the same triangles.
  const std::size_t chunk = 256;
  const std::size_t chunks = (n + chunk - 1) / chunk;
  threads = static_cast<int>(std::min<std::size_t>(threads, std::max<std::size_t>(chunks, 1)));
  std::atomic<std::size_t> next{0}, done{0}, tested{0};
  std::atomic<bool> cancel{false};
  auto work = [&] {
    DropStats local;
    for (;;) {
      const std::size_t k = next.fetch_add(1);
      if (k >= chunks || cancel.load(std::memory_order_relaxed)) break;
      const std::size_t e = std::min(n, (k + 1) * chunk);
      // Consecutive points of a chunk are neighbours along the footprint. The hint starts afresh with each
      // chunk so every result depends on its chunk only: the same bits whatever the thread count.
      int32_t hint = -1;
      for (std::size_t i = k * chunk; i < e; ++i) {
        z_out[i] = drop_point(index, cutter, xy[2 * i], xy[2 * i + 1], floor_z, &local, &hint);
      }
      done.fetch_add(e - k * chunk);
    }
    tested.fetch_add(local.triangles_tested);
  };
  {
    ThreadGroup group;
    if (!options.progress) {
      for (int t = 1; t < threads; ++t) group.spawn(work);
      work();
    } else {
      // Workers compute while the caller's thread reports progress: the callback may need the caller's
      // thread (Python), and an exception from it stops the workers before it propagates.
      for (int t = 0; t < threads; ++t) group.spawn(work);
      try {
        while (done.load() < n && !cancel.load()) {
          std::this_thread::sleep_for(std::chrono::milliseconds(20));
          const double fraction = static_cast<double>(done.load()) / static_cast<double>(n);
          if (!options.progress(fraction)) cancel.store(true);
        }
      } catch (...) {
        cancel.store(true);
        throw;
      }
    }
  }
  if (cancel.load()) throw Cancelled();
  if (options.progress) options.progress(1.0);
  if (stats) stats->triangles_tested += tested.load();
}

}  // namespace tmm
