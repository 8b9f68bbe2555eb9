// Tool assembly drop profiling driver: an STL, a ball D6 on a zig-zag raster of `step` over the mesh's box, the
// cutter alone (drop_batch) against the cutter + shank r3 (clearance 0.5, from stick-out - 15) + holder
// (clearance 2, 60 long) as benchmarks/drop_assembly.py's shank_holder cases; one thread, best of `reps`.
//   build/tmm_assembly_profile shared/benchmarks/stl/wheel_in_box.stl 30 20 0.5 20 && perf record ...
// Arguments: stl, stick-out, holder radius, step, reps, [what: both | cutter | assembly | floors (the cutter
// with a floor per point)].
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <string>
#include <vector>

#include "tmm/mesh/mesh.hpp"
#include "tmm/mesh/stl_io.hpp"
#include "tmm/query/drop_assembly.hpp"
#include "tmm/query/drop_cutter.hpp"

namespace {

template <class F>
double best_of(int reps, F&& run) {
  double best = 1e300;
  for (int r = 0; r < reps; ++r) {
    const auto t0 = std::chrono::steady_clock::now();
    run();
    best = std::min(best, std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count());
  }
  return best;
}

}  // namespace

int main(int argc, char** argv) {
  if (argc < 6) {
    std::fprintf(stderr, "usage: %s stl stick_out holder_radius step reps [both|cutter|assembly]\n", argv[0]);
    return 2;
  }
  const double stick = std::atof(argv[2]), holder_r = std::atof(argv[3]), step = std::atof(argv[4]);
  const int reps = std::atoi(argv[5]);
  const std::string what = argc > 6 ? argv[6] : "both";
  const tmm::Mesh mesh = tmm::weld(tmm::read_stl(argv[1]), 1e-6);
  const tmm::MeshIndex index(mesh.V, mesh.F);
  const tmm::Cutter ball(3, 3);
  const tmm::ToolAssembly tool(ball, {{stick - 15.0, stick, 3.0, 3.0, 0.5}, {stick, stick + 60.0, holder_r, holder_r, 2.0}}, 0.0);
  const Eigen::RowVector3d lo = mesh.V.colwise().minCoeff(), hi = mesh.V.colwise().maxCoeff();
  std::vector<double> xy;
  int row = 0;
  for (double y = lo(1); y <= hi(1) + 1e-9; y += step, ++row) {
    std::vector<double> xs;
    for (double x = lo(0); x <= hi(0) + 1e-9; x += step) xs.push_back(x);
    if (row % 2) std::reverse(xs.begin(), xs.end());
    for (double x : xs) xy.insert(xy.end(), {x, y});
  }
  const std::size_t n = xy.size() / 2;
  std::vector<double> z0(n), z1(n);
  std::vector<int32_t> by(n);
  const tmm::BatchOptions one{1, {}};
  const double floor = lo(2) - 1.0;
  double tc = 0, ta = 0;
  if (what != "assembly") tc = best_of(reps, [&] { tmm::drop_batch(index, ball, xy.data(), n, floor, z0.data(), one); });
  if (what == "floors") {
    std::vector<double> fl(n, floor);
    tc = best_of(reps, [&] { tmm::drop_batch(index, ball, xy.data(), n, fl.data(), z0.data(), one); });
  }
  if (what != "cutter" && what != "floors")
    ta = best_of(reps, [&] { tmm::drop_assembly_batch(index, tool, xy.data(), n, floor, z1.data(), by.data(), one); });
  std::size_t lifted = 0;
  double checksum = 0;
  for (std::size_t i = 0; i < n; ++i) {
    lifted += by[i] >= 0;
    checksum += z1[i];
  }
  std::printf("%zu points: cutter %.2f ms, assembly %.2f ms, ratio %.2f, lifted %zu, checksum %.9f\n", n, tc * 1e3,
              ta * 1e3, tc > 0 ? ta / tc : 0.0, lifted, checksum);
  return 0;
}
