// The 3-axis sweep's band of rows (internal to src/sim): the per-move cell update over one band of the stock,
// apart from how the moves are assigned to bands and the bands to threads (sweep3.cpp).
#pragma once

#include <cstddef>
#include <cstdint>
#include <vector>

#include "tmm/cutter/cutter.hpp"
#include "tmm/sim/sim_report.hpp"
#include "tmm/sim/sweep3.hpp"
#include "tmm/sim/zmap.hpp"
#include "tmm/util/parallel.hpp"

namespace tmm {
namespace sweep3_detail {

// Index range [lo, hi] of the cell centres g0 + (i + 0.5) cell in [a, b], clamped to [0, n); false if none.
// Widened by a hair: the exact distance test per cell decides. (Integer conversion after clamping to a small
// range: std::floor and std::ceil are calls without SSE4.1, and this runs for every row of every move.)
inline bool index_range(double a, double b, double g0, double cell, std::size_t n, std::size_t& lo, std::size_t& hi) {
  const double fl = (a - g0) / cell - 0.5 - 1e-9, fh = (b - g0) / cell - 0.5 + 1e-9;
  const double top = static_cast<double>(n) - 1;
  if (!(fl <= fh) || fh < 0.0 || fl > top) return false;
  const double cl = maxd(fl, 0.0), ch = mind(fh, top);  // in [0, n - 1]: safe to convert
  std::size_t l = static_cast<std::size_t>(cl);
  if (static_cast<double>(l) < cl) ++l;  // ceil
  const std::size_t h = static_cast<std::size_t>(ch);  // floor (ch >= 0)
  if (l > h) return false;
  lo = l, hi = h;
  return true;
}

// A band of rows and what it learns while cutting.
struct BandResult {
  std::size_t lowered = 0;
  std::vector<RapidCollision> removals;  // rapids that removed anything, in move order
  std::vector<BodyCollision> bodies;     // the body check's, per move and piece
};

// Cuts the band's moves (moves[0..count), indices of tips and kinds, in move order) into rows j0..j1 of the
// stock. Progress within the batch's chunk: done_before bands, then the fraction of this band's moves; the
// band stops between moves when the batch stops.
// With check (may be null), each move's bodies are tested against the stock before the move is cut.
void cut_band(ZMap& stock, const Cutter& cutter, const double* tips, const MoveKind* kinds,
              const std::uint32_t* moves, std::size_t count, std::size_t j0, std::size_t j1, double done_before,
              ChunkContext& ctx, BandResult& out, const BodyCheck* check = nullptr);

}  // namespace sweep3_detail
}  // namespace tmm
