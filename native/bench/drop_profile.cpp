// Drop-cutter profiling driver: the benchmark's height field z = 10 sin(x/15) cos(y/20) + 5 exp(...) over
// 100 x 100 mm (cells x cells, interior vertices jittered by up to 10% of a cell), a 0.5 mm CL raster, one
// thread, best of `reps` batches. For perf, without Python in the way:
//   build/tmm_drop_profile ball 30 200 && perf record build/tmm_drop_profile ball 30 200 && perf report
// Arguments: cutter (ball d6 | flat d6 | bull d10 r2), reps, cells.
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <random>
#include <string>
#include <vector>

#include "tmm/query/drop_cutter.hpp"

int main(int argc, char** argv) {
  const std::string kind = argc > 1 ? argv[1] : "ball";
  const int reps = argc > 2 ? std::atoi(argv[2]) : 10;
  const int n = argc > 3 ? std::atoi(argv[3]) : 200;
  if (kind != "ball" && kind != "flat" && kind != "bull") {
    std::fprintf(stderr, "cutter must be ball, flat or bull\n");
    return 2;
  }
  tmm::Vertices V((n + 1) * (n + 1), 3);
  tmm::Triangles F(2 * n * n, 3);
  std::mt19937 rng(1);
  std::uniform_real_distribution<double> jitter(-0.1, 0.1);
  const double h = 100.0 / n;
  for (int i = 0; i <= n; ++i)
    for (int j = 0; j <= n; ++j) {
      double x = i * h, y = j * h;
      if (i > 0 && i < n && j > 0 && j < n) {
        x += jitter(rng) * h;
        y += jitter(rng) * h;
      }
      V.row(i * (n + 1) + j) << x, y,
          10 * std::sin(x / 15) * std::cos(y / 20) + 5 * std::exp(-((x - 50) * (x - 50) + (y - 50) * (y - 50)) / 400);
    }
  int t = 0;
  for (int i = 0; i < n; ++i)
    for (int j = 0; j < n; ++j) {
      const int a = i * (n + 1) + j;
      F.row(t++) << a, a + n + 1, a + 1;
      F.row(t++) << a + 1, a + n + 1, a + n + 2;
    }
  const tmm::MeshIndex index(V, F);
  const tmm::Cutter cutter = kind == "ball" ? tmm::Cutter(3, 3) : kind == "flat" ? tmm::Cutter(3, 0) : tmm::Cutter(5, 2);
  std::vector<double> xy;
  for (int j = 0; j <= 200; ++j)
    for (int i = 0; i <= 200; ++i) {
      xy.push_back(i * 0.5);
      xy.push_back(j * 0.5);
    }
  const std::size_t m = xy.size() / 2;
  std::vector<double> z(m);
  tmm::BatchOptions options;
  options.threads = 1;
  double best = INFINITY;
  tmm::DropStats stats;
  for (int r = 0; r < reps; ++r) {
    stats = tmm::DropStats{};
    const auto t0 = std::chrono::steady_clock::now();
    tmm::drop_batch(index, cutter, xy.data(), m, -100, z.data(), options, &stats);
    best = std::min(best, std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count());
  }
  std::printf("%s, %d triangles: %.0f points/s (1 thread, best of %d), %.1f triangles tested per point\n",
              kind.c_str(), 2 * n * n, m / best, reps, double(stats.triangles_tested) / m);
  return 0;
}
