#include "tmm/sim/sweep3.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <sstream>
#include <stdexcept>
#include <thread>
#include <utility>
#include <vector>

#include "body_check_band.hpp"
#include "sweep3_band.hpp"
#include "tmm/util/range.hpp"

namespace tmm {

namespace {

using sweep3_detail::BandResult;
using sweep3_detail::index_range;

[[noreturn]] void refuse(const std::string& what) { throw std::invalid_argument(what); }

// The tips, kinds and the stock's heights, refused by name when not usable (n >= 2).
void check_inputs(const ZMap& stock, const double* tips, const MoveKind* kinds, std::size_t n) {
  if (!tips) refuse("tips must not be null");
  if (!kinds) refuse("kinds must not be null when there are moves");
  if (n - 1 > std::numeric_limits<std::uint32_t>::max()) refuse("too many moves (above 4294967295)");
  for (std::size_t k = 0; k < n; ++k) {
    const double* p = tips + 3 * k;
    if (!(std::isfinite(p[0]) && std::isfinite(p[1]) && std::isfinite(p[2]))) {
      std::ostringstream msg;
      msg << "tip " << k << " is not finite: (" << p[0] << ", " << p[1] << ", " << p[2] << ")";
      refuse(msg.str());
    }
    if (!(in_range(p[0]) && in_range(p[1]) && in_range(p[2]))) {
      std::ostringstream msg;
      msg << "tip " << k << " (" << p[0] << ", " << p[1] << ", " << p[2]
          << ") " << out_of_range_text();
      refuse(msg.str());
    }
  }
  for (std::size_t k = 0; k + 1 < n; ++k) {
    const auto v = static_cast<unsigned>(kinds[k]);
    if (v > static_cast<unsigned>(MoveKind::Jump)) {
      std::ostringstream msg;
      msg << "kind of move " << k << " is " << v << ": not a move kind (0 cut, 1 rapid, 2 jump)";
      refuse(msg.str());
    }
  }
  // The heights are writable from Python: a NaN or huge cell would stay or spread as garbage.
  const std::vector<double>& heights = stock.heights();
  for (std::size_t c = 0; c < heights.size(); ++c) {
    if (in_range(heights[c])) continue;
    std::ostringstream msg;
    msg << "stock cell (" << c % stock.nx() << ", " << c / stock.nx() << ") height " << heights[c] << " "
        << out_of_range_text();
    refuse(msg.str());
  }
}

// The moves per band of rows (CSR, in move order): those whose footprint's rows meet the band.
struct BandMoves {
  std::size_t band_rows = 0, bands = 0;
  std::vector<std::size_t> count;     // band bd's moves are moves[count[bd] .. count[bd + 1])
  std::vector<std::uint32_t> moves;
};

BandMoves assign_bands(const ZMap& stock, double R, const double* tips, const MoveKind* kinds, std::size_t n,
                       std::size_t band_rows, SimReport& report) {
  const std::size_t ny = stock.ny();
  BandMoves bm;
  bm.band_rows = band_rows;
  bm.bands = (ny + band_rows - 1) / band_rows;
  const std::size_t bands = bm.bands;
  std::vector<std::size_t>& count = bm.count;
  count.assign(bands + 1, 0);
  std::vector<std::uint32_t> first_band(n - 1), last_band(n - 1);
  for (std::size_t k = 0; k + 1 < n; ++k) {
    first_band[k] = 1, last_band[k] = 0;
    if (kinds[k] == MoveKind::Jump) continue;
    ++report.moves_cut;
    const double* a = tips + 3 * k;
    const double* b = a + 3;
    std::size_t ia, ib, ja, jb;
    if (!index_range(mind(a[0], b[0]) - R, maxd(a[0], b[0]) + R, stock.x0(), stock.cell(), stock.nx(), ia, ib) ||
        !index_range(mind(a[1], b[1]) - R, maxd(a[1], b[1]) + R, stock.y0(), stock.cell(), ny, ja, jb))
      continue;
    first_band[k] = static_cast<std::uint32_t>(ja / band_rows);
    last_band[k] = static_cast<std::uint32_t>(jb / band_rows);
    for (std::size_t bd = first_band[k]; bd <= last_band[k]; ++bd) ++count[bd + 1];
  }
  for (std::size_t bd = 0; bd < bands; ++bd) count[bd + 1] += count[bd];
  bm.moves.assign(count[bands], 0);
  std::vector<std::size_t> fill(count.begin(), count.end() - 1);
  for (std::size_t k = 0; k + 1 < n; ++k)
    for (std::size_t bd = first_band[k]; bd <= last_band[k]; ++bd) bm.moves[fill[bd]++] = static_cast<std::uint32_t>(k);
  return bm;
}

// The bands' lowered cells summed; the rapids' removals merged per move (a move can cross several bands),
// those deeper than the tolerance reported as collisions in move order.
void gather(const std::vector<BandResult>& results, double collision_tol, SimReport& report) {
  std::vector<RapidCollision> removals;
  std::vector<BodyCollision> bodies;
  for (const BandResult& r : results) {
    bodies.insert(bodies.end(), r.bodies.begin(), r.bodies.end());
    report.cells_lowered += r.lowered;
    removals.insert(removals.end(), r.removals.begin(), r.removals.end());
  }
  std::sort(removals.begin(), removals.end(),
            [](const RapidCollision& a, const RapidCollision& b) { return a.move < b.move; });
  for (std::size_t i = 0; i < removals.size();) {
    RapidCollision c = removals[i];
    for (++i; i < removals.size() && removals[i].move == c.move; ++i) c.depth = maxd(c.depth, removals[i].depth);
    if (c.depth > collision_tol) report.collisions.push_back(c);
  }
  report.body_collisions = merge_body_collisions(std::move(bodies));
}

// The body check's inputs, and the poses of each move within bounds; the bodies' reach from the axis.
double check_bodies(const BodyCheck& check, const Cutter& cutter, const ZMap& stock, const double* tips,
                    std::size_t n) {
  validate(check);
  const double step = check.step > 0.0 ? check.step : 0.5 * stock.cell();
  for (std::size_t k = 0; k + 1 < n; ++k) {
    const double* a = tips + 3 * k;
    const double len = std::sqrt((a[3] - a[0]) * (a[3] - a[0]) + (a[4] - a[1]) * (a[4] - a[1]) +
                                 (a[5] - a[2]) * (a[5] - a[2]));
    if (len / step > 1e9) {
      std::ostringstream msg;
      msg << "body check: move " << k << " (" << len << " mm) needs more than 1e9 poses of step " << step
          << " mm: use a larger step";
      refuse(msg.str());
    }
  }
  return body_detail::BodyBand3::reach(cutter, check);
}

}  // namespace

SimReport cut_3axis(ZMap& stock, const Cutter& cutter, const double* tips, const MoveKind* kinds,
                    std::size_t n, const Sweep3Options& options, const BatchOptions& batch) {
  if (!(std::isfinite(options.collision_tol) && options.collision_tol >= 0.0)) {
    std::ostringstream msg;
    msg << "collision_tol must be finite and >= 0 mm, got " << options.collision_tol;
    refuse(msg.str());
  }
  SimReport report;
  if (n < 2) return report;
  check_inputs(stock, tips, kinds, n);

  const std::size_t ny = stock.ny();
  const int threads = batch.threads > 0 ? batch.threads : default_threads();
  std::size_t band_rows = options.band_rows;
  if (band_rows == 0) band_rows = std::max<std::size_t>(8, (ny + 8 * threads - 1) / (8 * threads));
  // With the body check a band also replays the moves whose bodies reach it (a move that misses the band's
  // cells cuts nothing there: the heights are the same).
  const double reach = options.body_check ? std::max(cutter.max_radius(),
                                                     check_bodies(*options.body_check, cutter, stock, tips, n))
                                          : cutter.max_radius();
  const BandMoves bm = assign_bands(stock, reach, tips, kinds, n, band_rows, report);

  // Each band on its own (a rapid sees the stock before it: its band's moves in move order), the bands in
  // parallel: the heights do not depend on the thread count.
  std::vector<BandResult> results(bm.bands);
  parallel_chunks(bm.bands, 1, batch, [&](std::size_t b0, std::size_t b1, ChunkContext& ctx) {
    for (std::size_t bd = b0; bd < b1; ++bd) {
      const std::size_t first = bm.count[bd];
      sweep3_detail::cut_band(stock, cutter, tips, kinds, bm.moves.data() + first, bm.count[bd + 1] - first,
                              bd * band_rows, std::min(ny, (bd + 1) * band_rows) - 1,
                              static_cast<double>(bd - b0), ctx, results[bd], options.body_check);
    }
  });
  gather(results, options.collision_tol, report);
  return report;
}

}  // namespace tmm
