// Adaptive raster (seed 000 section 3.5.2.2): the across-offsets of parallel passes such that the
// largest cusp between neighbours is the tolerance, each pass placed from the real CL points of the previous
// one. The kernel's port of the numpy placement in tests/core/adaptive_raster_reference.py, the slow
// reference that explains the method; the two must agree (tests/core/test_adaptive_raster.py).
//
// In short: the work happens in a frame where the passes run along +X' (`index` is the mesh turned so:
// the cutter is a solid of revolution, so its drop does not change when the mesh turns about Z). For a pass
// a at y0 and a candidate b at y1 (dropped at a's x), sections across the passes through a's CL points
// (clear of the pass ends) get each pass's lower surface: the least over its instances near the section
// (neighbours along the pass count) of z + h(rho). A dense raster of the same tool (kDense - 1 passes
// between a and b) gives the reachable envelope E; the cusp is the largest (min(a, b) - E) along E's normal
// where the slope across is at most max_slope and E lies within the cusp of the design (the mesh, by a
// needle's drop: elsewhere the tool cannot reach, counted as unreachable); at each section's ridge (where
// a's and b's surfaces cross) it is solved by bisection. The step is the largest whose cusp is at most
// 0.95 x the tolerance, found by a few evaluations (secant on sqrt(cusp) in a bracket), never below
// step_min (a gap still above the tolerance there is counted as limited).
#pragma once

#include <cstddef>
#include <vector>

#include "tmm/cutter/cutter.hpp"
#include "tmm/mesh/mesh_index.hpp"
#include "tmm/util/parallel.hpp"

namespace tmm {

struct AdaptiveRasterOptions {
  double xmin = 0, ymin = 0, xmax = 0, ymax = 0;  // the boundary of the tool centres, model frame (mm)
  double angle = 0;            // the passes' direction from +X (radians); `index` is the mesh turned by -angle
  double cusp = 0;             // the tolerance (mm, > 0)
  double sample_step = 0;      // CL points along a pass at most this far apart (mm, > 0)
  double floor_z = 0;          // no tip below this height (mm)
  double stock_to_leave = 0;   // the design is the mesh offset by this (mm)
  double max_slope = 0;        // cusps measured where the envelope's slope across is at most this (rad, (0, pi/2))
  double step_min = 0;         // the smallest step the search may choose (mm, > 0)
  double step_max = 0;         // the largest (mm, step_min <= step_max < 2 x the cutter's max radius)
};

// The most samples of one pass's section grid (sections x samples across; two grids of doubles, the design
// and the previous pass's surface): about 400 MB.
constexpr std::size_t kMaxAdaptiveSectionSamples = 25'000'000;

struct AdaptiveRasterResult {
  std::vector<double> offsets;       // (k,) across-offsets of the passes, from the boundary's lowest to its highest
  std::vector<double> cusps;         // (k - 1,) measured cusp between neighbours (mm)
  std::size_t limited = 0;           // gaps at the smallest step whose cusp still exceeds the tolerance
  std::size_t unreachable = 0;       // gaps with places the tool cannot bring within the cusp (not measured)
  std::size_t evaluations = 0;       // candidate passes dropped and measured
  std::size_t drops = 0;             // drop-cutter queries (CL points and design samples)
};

// The work the options ask for, estimated before anything is allocated: the CL points dropped at most
// ((passes at step_min) x points per pass x (evaluations per pass + 1)) and one pass's section-grid samples.
// Throws std::invalid_argument naming the parameter on bad options, or when the section grid exceeds
// kMaxAdaptiveSectionSamples.
struct AdaptiveRasterWork {
  double cl_points = 0;
  double section_samples = 0;
};
AdaptiveRasterWork adaptive_raster_work(const Cutter& cutter, const AdaptiveRasterOptions& options);

// The passes (see the head). `tool` is dropped (the cutter grown by the stock to leave: its tip raised by
// the stock gives the drop on the offset design); `cutter`'s profile shapes the surface the instances leave.
// Threads and progress as batch queries do: batch.threads for the drops and the sections, batch.progress
// (from the calling thread: before each pass the fraction of the width placed, then within the pass's
// batches every 20 ms that same fraction, so that a long pass can be cancelled too; false cancels: throws
// Cancelled). Throws std::invalid_argument on bad options (adaptive_raster_work).
AdaptiveRasterResult adaptive_raster(const MeshIndex& index, const Cutter& tool, const Cutter& cutter,
                                     const AdaptiveRasterOptions& options, const BatchOptions& batch);

}  // namespace tmm
