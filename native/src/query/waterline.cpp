#include "tmm/query/waterline.hpp"

#include <algorithm>
#include <array>
#include <atomic>
#include <cmath>
#include <limits>
#include <sstream>
#include <stdexcept>
#include <thread>
#include <utility>
#include <unordered_map>

#include "tmm/query/drop_cutter.hpp"
#include "tmm/util/bracket_1d.hpp"
#include "tmm/util/range.hpp"

#include "waterline_level.hpp"

namespace tmm {

double WaterlineLoop::area() const {
  const std::size_t n = size();
  double a = 0;
  for (std::size_t i = 0, j = n - 1; i < n; j = i++) a += xy[2 * j] * xy[2 * i + 1] - xy[2 * i] * xy[2 * j + 1];
  return 0.5 * a;
}

namespace {

void check_options(const WaterlineOptions& o) {
  auto fail = [](const char* what, double v, const char* allowed) {
    std::ostringstream msg;
    msg << "waterline " << what << " must be " << allowed << ", got " << v;
    throw std::invalid_argument(msg.str());
  };
  for (double v : {o.xmin, o.ymin, o.xmax, o.ymax})
    if (!std::isfinite(v)) fail("bounds", v, "finite");
  require_in_range(o.xmin, "waterline bounds xmin");
  require_in_range(o.ymin, "waterline bounds ymin");
  require_in_range(o.xmax, "waterline bounds xmax");
  require_in_range(o.ymax, "waterline bounds ymax");
  if (!(o.xmax > o.xmin)) fail("bounds xmax", o.xmax, "> xmin");
  if (!(o.ymax > o.ymin)) fail("bounds ymax", o.ymax, "> ymin");
  if (!(o.sample_step > 0 && std::isfinite(o.sample_step))) fail("sample step", o.sample_step, "> 0 (mm)");
  if (!(o.chord_tol > 0 && std::isfinite(o.chord_tol))) fail("chord tolerance", o.chord_tol, "> 0 (mm)");
  if (!(o.bracket > 0 && o.bracket < 0.5 * o.chord_tol)) fail("bracket", o.bracket, "in (0, chord tolerance / 2)");
  if (!(o.min_segment > 0 && std::isfinite(o.min_segment))) fail("minimum segment", o.min_segment, "> 0 (mm)");
  if (o.max_depth < 0 || o.max_depth > 64) fail("maximum depth", o.max_depth, "in [0, 64]");
  if (!(o.min_step >= 0 && std::isfinite(o.min_step))) fail("minimum step", o.min_step, ">= 0 (mm; 0: no refinement)");
  if (o.min_step > 0 && !(o.min_step >= o.sample_step / 256.0))
    fail("minimum step", o.min_step, ">= sample step / 256 (mm)");
}

std::size_t nodes_along(double width, double step) {
  const double cells = std::ceil(width / step - 1e-9);
  if (!(cells < 1e9)) return std::numeric_limits<std::size_t>::max();
  return std::max<std::size_t>(2, static_cast<std::size_t>(cells) + 1);
}

}  // namespace

using waterline_detail::Grid;
using waterline_detail::Level;
using waterline_detail::grid_margin;

void waterline_grid_size(const WaterlineOptions& options, std::size_t& nx, std::size_t& ny) {
  check_options(options);
  nx = nodes_along(options.xmax - options.xmin, options.sample_step);
  ny = nodes_along(options.ymax - options.ymin, options.sample_step);
  const double padded = (static_cast<double>(nx) + 2.0) * (static_cast<double>(ny) + 2.0);
  if (padded > static_cast<double>(kMaxWaterlineGridNodes)) {
    std::ostringstream msg;
    msg << "waterline sample step " << options.sample_step << " mm over " << options.xmax - options.xmin << " x "
        << options.ymax - options.ymin << " mm gives a drop grid of " << padded << " nodes, more than the "
        << "kernel's limit of " << kMaxWaterlineGridNodes << "; use a larger sample step or smaller bounds";
    throw std::invalid_argument(msg.str());
  }
}

namespace {

// The levels' range; each level finite and within the kernel's range.
void level_range(const std::vector<double>& zs, double& zlow, double& zhigh) {
  zlow = kInf;
  zhigh = -kInf;
  for (double z : zs) {
    if (!std::isfinite(z)) {
      std::ostringstream msg;
      msg << "waterline level z must be finite, got " << z;
      throw std::invalid_argument(msg.str());
    }
    require_in_range(z, "waterline level z");
    zlow = std::min(zlow, z);
    zhigh = std::max(zhigh, z);
  }
}

// The grid's geometry: nx x ny nodes over the bounds plus the ring, and the fine lattice's factor k.
Grid grid_layout(const WaterlineOptions& o, std::size_t nx, std::size_t ny) {
  Grid g;
  g.NX = nx + 2;
  g.NY = ny + 2;
  g.x0 = o.xmin;
  g.y0 = o.ymin;
  g.dx = (o.xmax - o.xmin) / static_cast<double>(nx - 1);
  g.dy = (o.ymax - o.ymin) / static_cast<double>(ny - 1);
  if (o.min_step > 0) {
    const double cell = std::max(g.dx, g.dy);
    while (cell / static_cast<double>(g.k) > o.min_step && g.k < 256) g.k *= 2;
  }
  return g;
}

// The grid's drop heights (one batch shared by every level) and each cell row's height range.
void sample_grid(const MeshIndex& index, const Cutter& cutter, double zlow, double zhigh, const BatchOptions& batch,
                 Grid& g) {
  const std::size_t nx = g.NX - 2, ny = g.NY - 2;
  {
    std::vector<double> xy(2 * nx * ny), z(nx * ny);
    for (std::size_t j = 0; j < ny; ++j)
      for (std::size_t i = 0; i < nx; ++i) {
        xy[2 * (j * nx + i)] = g.x(i + 1);
        xy[2 * (j * nx + i) + 1] = g.y(j + 1);
      }
    // Any floor below the lowest level: a height at the floor is free at every level.
    // Heights far above the highest level are capped (the scan stops at the first contact above): they only
    // say "blocked" to every level and every band test (docs/waterline.md, "Adaptive grid").
    drop_batch_capped(index, cutter, xy.data(), nx * ny, zlow - 1.0, zhigh + grid_margin(cutter, g), z.data(),
                      batch);
    g.h.assign(g.NX * g.NY, -kInf);
    for (std::size_t j = 0; j < ny; ++j)
      std::copy(z.begin() + j * nx, z.begin() + (j + 1) * nx, g.h.begin() + (j + 1) * g.NX + 1);
  }
  g.row_lo.assign(g.NY - 1, kInf);
  g.row_hi.assign(g.NY - 1, -kInf);
  for (std::size_t J = 0; J + 1 < g.NY; ++J) {
    for (std::size_t I = 0; I < g.NX; ++I) {
      for (std::size_t r : {J, J + 1}) {
        g.row_lo[J] = std::min(g.row_lo[J], g.h[r * g.NX + I]);
        g.row_hi[J] = std::max(g.row_hi[J], g.h[r * g.NX + I]);
      }
    }
  }
}

// The levels over the sampled grid, progress from grid_share to 1. Fewer levels than threads: the levels one
// after the other, each on all threads (its crossings and chords; progress and cancel within the level).
// Otherwise the levels in parallel, each on one thread.
void run_levels(const MeshIndex& index, const Cutter& cutter, const Grid& g, const std::vector<double>& zs,
                const WaterlineOptions& o, const BatchOptions& batch, double grid_share,
                std::vector<std::vector<WaterlineLoop>>& result, std::size_t& drops_out, std::size_t& refined_out) {
  std::atomic<std::size_t> drops{0}, refined{0};
  BatchOptions level_batch{batch.threads, {}};
  if (batch.progress)
    level_batch.progress = [&](double f) { return batch.progress(grid_share + f * (1.0 - grid_share)); };
  const std::size_t threads = static_cast<std::size_t>(batch.threads > 0 ? batch.threads : default_threads());
  if (zs.size() < threads) {
    for (std::size_t k = 0; k < zs.size(); ++k) {
      BatchOptions inner{batch.threads, {}};
      if (batch.progress) {
        const double n = static_cast<double>(zs.size());
        inner.progress = [&, k, n](double f) {
          return batch.progress(grid_share + (static_cast<double>(k) + f) / n * (1.0 - grid_share));
        };
        if (!batch.progress(grid_share + static_cast<double>(k) / n * (1.0 - grid_share))) throw Cancelled();
      }
      Level level(index, cutter, g, o, zs[k], inner);
      result[k] = level.loops();
      drops += level.drops();
      refined += level.refined_cells();
    }
  } else {
    parallel_chunks(zs.size(), 1, level_batch, [&](std::size_t begin, std::size_t end, ChunkContext& ctx) {
      const BatchOptions one{1, {}, &ctx};  // a level stops within itself when the batch stops
      for (std::size_t k = begin; k < end; ++k) {
        Level level(index, cutter, g, o, zs[k], one);
        result[k] = level.loops();
        drops += level.drops();
        refined += level.refined_cells();
      }
    });
  }
  drops_out = drops.load();
  refined_out = refined.load();
}

}  // namespace

std::vector<std::vector<WaterlineLoop>> waterline(const MeshIndex& index, const Cutter& cutter,
                                                  const std::vector<double>& zs, const WaterlineOptions& o,
                                                  const BatchOptions& batch, WaterlineStats* stats) {
  std::size_t nx = 0, ny = 0;
  waterline_grid_size(o, nx, ny);
  double zlow = kInf, zhigh = -kInf;
  level_range(zs, zlow, zhigh);
  std::vector<std::vector<WaterlineLoop>> result(zs.size());
  if (zs.empty()) return result;

  Grid g = grid_layout(o, nx, ny);
  // Progress: the grid's share of the work by a rough count of drops (a level costs some 30 drops per
  // crossing, a few crossings per grid line).
  const double grid_work = static_cast<double>(nx * ny);
  const double level_work = static_cast<double>(zs.size()) * 60.0 * static_cast<double>(nx + ny);
  const double grid_share = grid_work / (grid_work + level_work);
  BatchOptions grid_batch{batch.threads, {}};
  if (batch.progress)
    grid_batch.progress = [&](double f) { return batch.progress(f * grid_share); };
  sample_grid(index, cutter, zlow, zhigh, grid_batch, g);

  std::size_t drops = 0, refined = 0;
  run_levels(index, cutter, g, zs, o, batch, grid_share, result, drops, refined);
  if (stats) {
    stats->grid_nodes = nx * ny;
    stats->drops = drops;
    stats->refined_cells = refined;
  }
  return result;
}

}  // namespace tmm
