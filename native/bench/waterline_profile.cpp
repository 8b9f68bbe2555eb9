// Waterline profiling driver: one level of an STL at a fraction of its height, the bounds grown by the cutter
// radius + 1 mm, as benchmarks/waterline_bench.py --quick --all-tools --chord-tol 0.003 --step 0.5
// --min-step 0.05 calls it; best of `reps` calls. For perf, without Python in the way:
//   build/tmm_waterline_profile shared/benchmarks/stl/sphere_on_plate.stl ball 50 1 && perf record ... && perf report
// Arguments: stl, cutter (ball d6 | flat d6 | bull d10 r2), reps, threads, [fraction 0.62, step 0.5, min step 0.05,
// chord tolerance 0.003].
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <string>
#include <vector>

#include "tmm/mesh/mesh.hpp"
#include "tmm/mesh/stl_io.hpp"
#include "tmm/query/waterline.hpp"

int main(int argc, char** argv) {
  if (argc < 2) {
    std::fprintf(stderr, "usage: %s model.stl [ball|flat|bull] [reps] [threads] [fraction] [step] [min_step] [tol]\n",
                 argv[0]);
    return 2;
  }
  const std::string kind = argc > 2 ? argv[2] : "ball";
  const int reps = argc > 3 ? std::atoi(argv[3]) : 20;
  const int threads = argc > 4 ? std::atoi(argv[4]) : 1;
  const double fraction = argc > 5 ? std::atof(argv[5]) : 0.62;
  if (kind != "ball" && kind != "flat" && kind != "bull") {
    std::fprintf(stderr, "cutter must be ball, flat or bull\n");
    return 2;
  }
  const tmm::Mesh mesh = tmm::weld(tmm::read_stl(argv[1]), 1e-6);
  const tmm::MeshIndex index(mesh.V, mesh.F);
  const tmm::Cutter cutter = kind == "ball" ? tmm::Cutter(3, 3) : kind == "flat" ? tmm::Cutter(3, 0) : tmm::Cutter(5, 2);
  const Eigen::RowVector3d lo = mesh.V.colwise().minCoeff(), hi = mesh.V.colwise().maxCoeff();
  const double g = cutter.max_radius() + 1.0;
  tmm::WaterlineOptions o;
  o.xmin = lo(0) - g;
  o.ymin = lo(1) - g;
  o.xmax = hi(0) + g;
  o.ymax = hi(1) + g;
  o.sample_step = argc > 6 ? std::atof(argv[6]) : 0.5;
  o.min_step = argc > 7 ? std::atof(argv[7]) : 0.05;
  o.chord_tol = argc > 8 ? std::atof(argv[8]) : 0.003;
  o.bracket = 1e-7;
  const std::vector<double> zs{lo(2) + fraction * (hi(2) - lo(2))};
  const tmm::BatchOptions batch{threads, {}};
  double best = 1e300;
  tmm::WaterlineStats stats;
  std::size_t points = 0, loops = 0;
  double checksum = 0;  // sum of |x| + |y| over the points: the same loops give the same sum
  for (int r = 0; r < reps; ++r) {
    const auto t0 = std::chrono::steady_clock::now();
    const auto out = tmm::waterline(index, cutter, zs, o, batch, &stats);
    best = std::min(best, std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count());
    loops = out[0].size();
    points = 0;
    checksum = 0;
    for (const auto& l : out[0]) {
      points += l.size();
      for (double v : l.xy) checksum += std::abs(v);
    }
  }
  std::printf("%s %s z %.4f: best %.2f ms of %d on %d threads; grid %zu, level drops %zu, refined cells %zu, "
              "loops %zu, points %zu, checksum %.9f\n", argv[1], kind.c_str(), zs[0], best * 1e3, reps, threads,
              stats.grid_nodes, stats.drops, stats.refined_cells, loops, points, checksum);
  return 0;
}
