// The tool assembly's drop: the grown cutter and bodies as shifted APT cutters (drop_assembly.hpp), dropped
// one after another, each from the height so far. A batch drops the bodies in the cutter's own tiles
// (drop_detail::drop_batch_follow); the points a tile cannot list go piece by piece (drop_piece).
#include "tmm/query/drop_assembly.hpp"

#include <algorithm>
#include <atomic>
#include <cmath>
#include <sstream>
#include <stdexcept>
#include <string>

#include "drop_tile_scan.hpp"
#include "tmm/util/range.hpp"

namespace tmm {

namespace {

[[noreturn]] void refuse_body(std::size_t i, const ToolBody& b, const std::string& why) {
  std::ostringstream msg;
  msg << "tool body " << i << " (z0 " << b.z0 << ", z1 " << b.z1 << ", r0 " << b.r0 << ", r1 " << b.r1
      << ", clearance " << b.clearance << "): " << why;
  throw std::invalid_argument(msg.str());
}

void check_bodies(const std::vector<ToolBody>& bodies) {
  for (std::size_t i = 0; i < bodies.size(); ++i) {
    const ToolBody& b = bodies[i];
    for (double v : {b.z0, b.z1, b.r0, b.r1, b.clearance})
      if (!in_range(v)) refuse_body(i, b, "a value " + out_of_range_text());
    if (b.z0 < 0.0) refuse_body(i, b, "z0 must be >= 0 (bodies are given in tip coordinates, above the tip)");
    if (!(b.z1 > b.z0)) refuse_body(i, b, "z1 must be above z0");
    if (b.r0 < 0.0 || b.r1 < 0.0) refuse_body(i, b, "radii must be >= 0");
    if (b.clearance < 0.0) refuse_body(i, b, "clearance must be >= 0");
    if (!(std::max(b.r0, b.r1) + b.clearance > 0.0))
      refuse_body(i, b, "a body needs a positive radius or a positive clearance");
    if (i > 0 && b.z0 < bodies[i - 1].z1) {
      std::ostringstream why;
      why << "bodies must be sorted from the tip up with z ranges not overlapping: z0 is below the previous "
             "body's z1 = "
          << bodies[i - 1].z1;
      refuse_body(i, b, why.str());
    }
  }
}

// Fewer points walk without the height cells (building them costs about a walk per cell row).
constexpr std::size_t kCellsFromPoints = 256;
// Pieces reaching at most this many cells look up the cells within their reach of a point (about 4 k^2).
constexpr double kFineCells = 6.0;
// Pieces reaching at most this many times the cutter's radius are dropped with tile lists, wider ones by walks.
constexpr double kTilesUpTo = 2.0;

// Does a body other than `skip`, grown by its clearance, hold the disc of radius `radius` at height `z` grown
// by `clearance`? Then that disc's piece (a top rim) can never set the height and is left out.
bool disc_covered(const std::vector<ToolBody>& bodies, std::size_t skip, double z, double radius,
                  double clearance) {
  for (std::size_t j = 0; j < bodies.size(); ++j) {
    const ToolBody& b = bodies[j];
    if (j == skip || b.z0 > z || b.z1 < z || b.clearance < clearance) continue;
    const double at = b.r0 + (b.r1 - b.r0) * (z - b.z0) / (b.z1 - b.z0);
    if (at >= radius) return true;
  }
  return false;
}

// The cutter grown by c. A flat-bottomed APT profile offset by c is one again: the corner radius grows by c
// about the same centre, the taper moves out by c along its normal (cos beta2, -sin beta2), the tip down by c.
// A widening taper ends at the cutter's top rim (R, L_C), whose ball the top disc's bull-nose adds.
void add_cutter(std::vector<AssemblyPiece>& out, const Cutter& k, double c, const std::vector<ToolBody>& bodies) {
  if (c == 0.0) {
    out.push_back({k, 0.0, kSetByCutter});
    return;
  }
  if (k.beta1() != 0.0)
    throw std::invalid_argument(
        "a cutter clearance needs a flat-bottomed cutter (bottom angle beta1 = 0): a conical bottom grown by a "
        "clearance is no APT profile; give the clearance to the bodies above it instead");
  const double r = k.corner_radius() + c, Lc = k.cutting_length();
  if (!std::isfinite(Lc)) {
    out.push_back({Cutter(k.radius() + c, r), -c, kSetByCutter});
    return;
  }
  const double b2 = k.beta2();
  out.push_back({Cutter::apt(k.radius() + c * std::cos(b2), r, Lc + c * (1.0 - std::sin(b2)), 0.0, b2), -c,
                 kSetByCutter});
  if (b2 > 0.0 && !disc_covered(bodies, ToolAssembly::kNoBody, Lc, k.radius(), c))
    out.push_back({Cutter(k.radius() + c, c), Lc - c, kSetByCutter});
}

// Body i grown by its clearance (see drop_assembly.hpp for the geometry).
void add_body(std::vector<AssemblyPiece>& out, std::size_t i, const std::vector<ToolBody>& bodies) {
  const ToolBody& b = bodies[i];
  const double c = b.clearance;
  const auto owner = static_cast<int32_t>(i);
  if (b.r1 <= b.r0) {  // the bottom disc shadows the rest
    out.push_back({Cutter(b.r0 + c, c), b.z0 - c, owner});
    return;
  }
  const double height = b.z1 - b.z0, beta2 = std::atan2(b.r1 - b.r0, height);
  // The side offset by c ends c (cos beta2, -sin beta2) from the top rim; the corner arc (radius c) is
  // centred on the bottom rim (r0, z0), the flat bottom c below it.
  out.push_back({Cutter::apt(b.r1 + c * std::cos(beta2), c, height + c * (1.0 - std::sin(beta2)), 0.0, beta2),
                 b.z0 - c, owner});
  if (c > 0.0 && !disc_covered(bodies, i, b.z1, b.r1, c))  // only a body sitting on this one can cover it
    out.push_back({Cutter(b.r1 + c, c), b.z1 - c, owner});
}

// Upper bounds of the mesh's height near a batch's points: square cells over the points' box grown by the
// largest reach, each holding the highest top of the index nodes overlapping it. A piece can lift the tool at a
// point only if a triangle within its reach rises above the point's floor; the cells' maxima over the squares
// around them reaching that far bound this, so most points skip a piece (a holder high above the part) with
// one lookup instead of a walk down the index.
class HeightCells {
 public:
  static constexpr double kCellsPerSide = 256;

  HeightCells(const MeshIndex& index, const double* xy, std::size_t n, double reach) {
    const auto [x0, y0, x1, y1] = drop_detail::finite_box(xy, n);
    if (!(x0 <= x1) || index.nodes().empty()) return;  // no finite point: every point walks
    x0_ = x0 - reach;
    y0_ = y0 - reach;
    side_ = std::max(std::max(x1 - x0, y1 - y0) + 2.0 * reach, 1e-9) / kCellsPerSide;
    nx_ = static_cast<std::size_t>((x1 + reach - x0_) / side_) + 1;
    ny_ = static_cast<std::size_t>((y1 + reach - y0_) / side_) + 1;
    top_.assign(nx_ * ny_, -INFINITY);
    fill(index);
  }

  bool empty() const { return top_.empty(); }
  double side() const { return side_; }

  // The maxima over squares of cells reaching `reach` around each cell (any triangle whose box comes within
  // `reach` of a point lies in the square around the point's cell).
  // into `out` (resized; `rows` is scratch: both kept by the caller from piece to piece, fresh pages cost more
  // than the pass).
  void dilate(double reach, std::vector<double>& rows, std::vector<double>& out) const {
    const auto k = static_cast<std::size_t>(std::ceil(reach / side_)) + 1;
    rows.resize(top_.size());
    out.resize(top_.size());
    WindowMax along_rows(nx_, k, 1);
    for (std::size_t j = 0; j < ny_; ++j) along_rows(&top_[j * nx_], &rows[j * nx_], nx_, 1, 1);
    constexpr std::size_t kLanes = 16;  // columns at once, row after row (no strided reads of single values)
    WindowMax along_columns(ny_, k, kLanes);
    for (std::size_t i = 0; i < nx_; i += kLanes)
      along_columns(&rows[i], &out[i], ny_, std::min(kLanes, nx_ - i), nx_);
  }

  // Do all cells whose squares come within `reach` of (x, y) stay at or below `z` (false for a point outside
  // the grid)? Finer than the dilated square around the point's cell, worth it for a few cells: row by row,
  // the run of cells the disc meets, stopping at the first cell above z.
  bool below_within(double x, double y, double reach, double z) const {
    const double fx = (x - x0_) / side_, fy = (y - y0_) / side_, fr = reach / side_;
    if (!(fx >= 0 && fy >= 0 && fx < static_cast<double>(nx_) && fy < static_cast<double>(ny_))) return false;
    const auto j0 = static_cast<std::size_t>(std::max(fy - fr, 0.0));
    const std::size_t j1 = std::min(static_cast<std::size_t>(fy + fr), ny_ - 1);
    for (std::size_t j = j0; j <= j1; ++j) {
      // The row's nearest y to the point, then the half-width of the disc there.
      const double dy = std::max({static_cast<double>(j) - fy, fy - static_cast<double>(j + 1), 0.0});
      const double half = std::sqrt(std::max(fr * fr - dy * dy, 0.0));
      const auto i0 = static_cast<std::size_t>(std::max(fx - half, 0.0));
      const std::size_t i1 = std::min(static_cast<std::size_t>(fx + half), nx_ - 1);
      const double* row = &top_[j * nx_];
      for (std::size_t i = i0; i <= i1; ++i)
        if (row[i] > z) return false;
    }
    return true;
  }

  // The cell holding (x, y), or the nearest one (a node's corner outside the grid); clamped before the cast.
  std::size_t cell(double x, double y) const {
    const double i = std::clamp((x - x0_) / side_, 0.0, static_cast<double>(nx_ - 1));
    const double j = std::clamp((y - y0_) / side_, 0.0, static_cast<double>(ny_ - 1));
    return static_cast<std::size_t>(j) * nx_ + static_cast<std::size_t>(i);
  }

 private:
  // Every node no wider than two cells raises the cells under its box to its top; a wider leaf's triangles
  // raise theirs each to the triangle's plane's highest point over the cell, if below its top (a big sloping
  // facet spans many cells, mostly far below its top). Each triangle lies under a small node or a wide leaf.
  // One pass in the nodes' order (no walk down the tree): the small nodes' descendants write again, cheaply.
  void fill(const MeshIndex& index) {
    const double x1 = x0_ + side_ * static_cast<double>(nx_), y1 = y0_ + side_ * static_cast<double>(ny_);
    for (const BvhNode& node : index.nodes()) {
      if (node.xmax < x0_ || node.ymax < y0_ || node.xmin > x1 || node.ymin > y1) continue;
      if (node.xmax - node.xmin <= 2.0 * side_ && node.ymax - node.ymin <= 2.0 * side_) {
        const std::size_t a = cell(node.xmin, node.ymin), b = cell(node.xmax, node.ymax);
        for (std::size_t j = a / nx_; j <= b / nx_; ++j)
          for (std::size_t i = a % nx_; i <= b % nx_; ++i) top_[j * nx_ + i] = std::max(top_[j * nx_ + i], node.zmax);
      } else if (node.count > 0) {
        for (int32_t t = node.first; t < node.first + node.count; ++t) raise(index.triangles()[static_cast<std::size_t>(t)]);
      }
    }
  }

  void raise(const IndexedTriangle& t) {
    const std::size_t a = cell(t.xmin, t.ymin), b = cell(t.xmax, t.ymax);
    const bool sloped = std::fabs(t.n[2]) > 1e-6;  // else only its top bounds it
    const double gx = sloped ? -t.n[0] / t.n[2] : 0.0, gy = sloped ? -t.n[1] / t.n[2] : 0.0;
    const double margin = 1e-9 * (1.0 + std::fabs(t.zmax));  // the plane's rounding
    for (std::size_t j = a / nx_; j <= b / nx_; ++j) {
      const double cy = y0_ + side_ * static_cast<double>(gy > 0 ? j + 1 : j);
      for (std::size_t i = a % nx_; i <= b % nx_; ++i) {
        double z = t.zmax;
        if (sloped) {
          const double cx = x0_ + side_ * static_cast<double>(gx > 0 ? i + 1 : i);
          z = std::min(z, t.p[0][2] + gx * (cx - t.p[0][0]) + gy * (cy - t.p[0][1]) + margin);
        }
        top_[j * nx_ + i] = std::max(top_[j * nx_ + i], z);
      }
    }
  }

  // out[i] = max(in[i - k .. i + k]) over m <= most values, each a run of `width` <= lanes contiguous lanes
  // `stride` apart (one window per lane) (van Herk / Gil-Werman: blocks of 2k + 1, a running max from each
  // block's start and from its end, two reads per value whatever k). Buffers are kept from call to call.
  class WindowMax {
   public:
    WindowMax(std::size_t most, std::size_t k, std::size_t lanes)
        : k_(k), pad_((most + 2 * k) * lanes), from_start_(pad_.size()), to_end_(pad_.size()) {}
    void operator()(const double* in, double* out, std::size_t m, std::size_t width, std::size_t stride) {
      const std::size_t w = 2 * k_ + 1, len = m + 2 * k_, W = width;
      std::fill(pad_.begin(), pad_.begin() + static_cast<std::ptrdiff_t>(len * W), -INFINITY);
      for (std::size_t i = 0; i < m; ++i) std::copy(in + i * stride, in + i * stride + W, &pad_[(i + k_) * W]);
      for (std::size_t j = 0; j < len; ++j) {
        double* f = &from_start_[j * W];
        const double* p = &pad_[j * W];
        if (j % w == 0) std::copy(p, p + W, f);
        else for (std::size_t l = 0; l < W; ++l) f[l] = std::max(f[l - W], p[l]);
      }
      for (std::size_t j = len; j-- > 0;) {
        double* t = &to_end_[j * W];
        const double* p = &pad_[j * W];
        if (j + 1 == len || (j + 1) % w == 0) std::copy(p, p + W, t);
        else for (std::size_t l = 0; l < W; ++l) t[l] = std::max(t[l + W], p[l]);
      }
      for (std::size_t i = 0; i < m; ++i)
        for (std::size_t l = 0; l < W; ++l)
          out[i * stride + l] = std::max(to_end_[i * W + l], from_start_[(i + 2 * k_) * W + l]);
    }

   private:
    std::size_t k_;
    std::vector<double> pad_, from_start_, to_end_;
  };

  double x0_ = 0, y0_ = 0, side_ = 1;
  std::size_t nx_ = 0, ny_ = 0;
  std::vector<double> top_;
};

// One body's piece over the batch, each point from its own floor `base` (the height so far + the lift). Points
// whose cells' bound is not above the floor keep it (top = base); points where the previous winner holds the
// flat bottom at the bound get the bound (rests_flat). The others are dropped with `tiles` as a batch
// (drop_batch's tile lists: a shank or neck about the cutter's size), else each by the index walk warm-started
// with the previous point's winner (a holder: its reach spans so many triangles that gathering them per tile
// costs more than the walks; measured, benchmarks/drop_assembly.py).
void drop_piece(const MeshIndex& index, const Cutter& profile, const double* xy, std::size_t n, const double* base,
                double* top, const HeightCells& cells, std::vector<double>& rows, std::vector<double>& bound,
                bool tiles, const BatchOptions& options, DropStats* stats) {
  bound.clear();
  if (!cells.empty()) cells.dilate(profile.max_radius(), rows, bound);
  auto bound_at = [&](std::size_t i) {
    const double x = xy[2 * i], y = xy[2 * i + 1];
    return !bound.empty() && std::isfinite(x) && std::isfinite(y) ? bound[cells.cell(x, y)] : INFINITY;
  };
  if (tiles) {
    std::vector<std::size_t> kept;
    std::vector<double> kxy, kbase;
    // A small piece: the cells within its reach of the point, where the dilated square is not low enough.
    const bool fine = !bound.empty() && profile.max_radius() <= kFineCells * cells.side();
    for (std::size_t i = 0; i < n; ++i) {
      if (bound_at(i) <= base[i] ||
          (fine && cells.below_within(xy[2 * i], xy[2 * i + 1], profile.max_radius(), base[i]))) {
        top[i] = base[i];
        continue;
      }
      kept.push_back(i);
      kxy.insert(kxy.end(), {xy[2 * i], xy[2 * i + 1]});
      kbase.push_back(base[i]);
    }
    std::vector<double> ktop(kept.size());
    drop_batch(index, profile, kxy.data(), kept.size(), kbase.data(), ktop.data(), options, stats);
    for (std::size_t k = 0; k < kept.size(); ++k) top[kept[k]] = ktop[k];
    return;
  }
  const auto& tris = index.triangles();
  std::atomic<std::size_t> tested{0};
  parallel_chunks(n, 512, options, [&](std::size_t begin, std::size_t end) {
    DropStats local;
    int32_t hint = -1;
    for (std::size_t i = begin; i < end; ++i) {
      const double x = xy[2 * i], y = xy[2 * i + 1], ub = bound_at(i);
      if (ub <= base[i]) {
        top[i] = base[i];
      } else if (hint >= 0 && drop_detail::rests_flat(profile, tris[static_cast<std::size_t>(hint)], x, y, ub)) {
        top[i] = ub;
      } else {
        top[i] = drop_point(index, profile, x, y, base[i], &local, &hint);
      }
    }
    tested.fetch_add(local.triangles_tested, std::memory_order_relaxed);
  });
  if (stats) stats->triangles_tested += tested.load();
}

}  // namespace

ToolAssembly::ToolAssembly(const Cutter& cutter, const std::vector<ToolBody>& bodies, double cutter_clearance)
    : cutter_(cutter), bodies_(bodies), cutter_clearance_(cutter_clearance) {
  if (!(in_range(cutter_clearance) && cutter_clearance >= 0.0)) {
    std::ostringstream msg;
    msg << "cutter clearance must be >= 0 and finite, got " << cutter_clearance;
    throw std::invalid_argument(msg.str());
  }
  check_bodies(bodies);
  add_cutter(pieces_, cutter, cutter_clearance, bodies);
  for (std::size_t i = 0; i < bodies.size(); ++i) {
    try {
      add_body(pieces_, i, bodies);
    } catch (const std::invalid_argument& e) {  // a profile the APT cutter refuses (a nearly flat cone)
      refuse_body(i, bodies[i], e.what());
    }
  }
}

bool ToolAssembly::disc_covered(std::size_t skip, double z, double radius, double clearance) const {
  return tmm::disc_covered(bodies_, skip, z, radius, clearance);
}

double drop_assembly_point(const MeshIndex& index, const ToolAssembly& tool, double x, double y, double floor_z,
                           int32_t* set_by, DropStats* stats) {
  double z = floor_z;
  int32_t by = kSetByFloor;
  for (const AssemblyPiece& p : tool.pieces()) {
    // The piece matters only where it would lift the tool: its drop starts at the height so far.
    const double base = z + p.lift;
    const double top = drop_point(index, p.profile, x, y, base, stats);
    if (top > base && top - p.lift > z) {
      z = top - p.lift;
      by = p.owner;
    }
  }
  if (set_by) *set_by = by;
  return z;
}

namespace {

// drop_assembly_floors with the bodies dropped in the cutter's tiles (FollowPieces); the points those leave open
// from some piece on are dropped from there piece after piece (drop_piece over them alone).
void drop_assembly_follow(const MeshIndex& index, const std::vector<AssemblyPiece>& pieces, const double* xy,
                          std::size_t n, const double* floors, double floor_z, double* z_out, int32_t* set_by,
                          const BatchOptions& options, DropStats* stats) {
  const std::size_t m = pieces.size();
  std::vector<int32_t> owner(set_by ? 0 : n);
  int32_t* by = set_by ? set_by : owner.data();
  std::vector<std::uint8_t> first_open(n);
  // Progress: the cutter's pass with its followers up to 0.8, the open points' passes the rest.
  BatchOptions pass = options;
  if (options.progress) pass.progress = [&options](double f) { return options.progress(0.8 * f); };
  drop_detail::drop_batch_follow(index, {pieces.data(), m, floors, floor_z, z_out, by, first_open.data()}, xy, n,
                                 z_out, pass, stats);
  std::vector<std::size_t> open;  // every point left open for some piece
  for (std::size_t i = 0; i < n; ++i)
    if (first_open[i] < m) open.push_back(i);
  if (open.empty()) {
    if (options.progress && !options.progress(1.0)) throw Cancelled();
    return;
  }
  std::vector<double> oxy, rows, bound;
  for (std::size_t i : open) oxy.insert(oxy.end(), {xy[2 * i], xy[2 * i + 1]});
  double reach = 0.0;  // of the bodies' pieces
  for (std::size_t k = 1; k < m; ++k) reach = std::max(reach, pieces[k].profile.max_radius());
  const HeightCells cells(index, oxy.data(), open.size() >= kCellsFromPoints ? open.size() : 0, reach);
  for (std::size_t k = 1; k < m; ++k) {
    const AssemblyPiece& p = pieces[k];
    // The points open for piece k lead the list as the pieces go (open ones stay open).
    std::vector<double> kxy, kbase;
    std::vector<std::size_t> at;
    for (std::size_t o = 0; o < open.size(); ++o) {
      const std::size_t i = open[o];
      if (first_open[i] > k) continue;
      at.push_back(i);
      kxy.insert(kxy.end(), {xy[2 * i], xy[2 * i + 1]});
      kbase.push_back(z_out[i] + p.lift);
    }
    if (at.empty()) continue;
    std::vector<double> ktop(at.size());
    if (options.progress)
      pass.progress = [&options, k, m](double f) {
        return options.progress(0.8 + 0.2 * (static_cast<double>(k - 1) + f) / static_cast<double>(m - 1));
      };
    drop_piece(index, p.profile, kxy.data(), at.size(), kbase.data(), ktop.data(), cells, rows, bound,
               p.profile.max_radius() <= kTilesUpTo * pieces[0].profile.max_radius(), pass, stats);
    for (std::size_t q = 0; q < at.size(); ++q) drop_detail::FollowPieces::raise(z_out[at[q]], by[at[q]], ktop[q], p);
  }
}

// drop_assembly_batch with the floor of point i = floors ? floors[i] : floor_z: the bodies in the cutter's tiles
// where each starts at or above the cutter's lift, else piece after piece over the batch.
void drop_assembly_floors(const MeshIndex& index, const ToolAssembly& tool, const double* xy, std::size_t n,
                          const double* floors, double floor_z, double* z_out, int32_t* set_by,
                          const BatchOptions& options, DropStats* stats) {
  const std::vector<AssemblyPiece>& pieces = tool.pieces();
  // Bodies in the cutter's tiles when those hold points enough for lists (a raster finer than a tile, not
  // scattered points: there every tile would leave its points open).
  const auto box = drop_detail::finite_box(xy, n);
  const double tile = drop_detail::kTileFactor * pieces[0].profile.max_radius();
  const double tiles = (std::floor((box.x1 - box.x0) / tile) + 1.0) * (std::floor((box.y1 - box.y0) / tile) + 1.0);
  bool follow = pieces.size() > 1 && pieces.size() <= 255 && box.x0 <= box.x1 &&
                static_cast<double>(n) >= static_cast<double>(drop_detail::kMinTilePoints) * tiles;
  for (std::size_t k = 1; k < pieces.size(); ++k) follow = follow && pieces[k].lift >= pieces[0].lift;
  if (follow) {
    drop_assembly_follow(index, pieces, xy, n, floors, floor_z, z_out, set_by, options, stats);
    return;
  }
  const double passes = static_cast<double>(pieces.size());
  std::vector<double> base(n), top(n), rows, bound;  // rows, bound: the cells' scratch, kept from piece to piece
  double reach = 0.0;  // of the bodies' pieces
  for (std::size_t k = 1; k < pieces.size(); ++k) reach = std::max(reach, pieces[k].profile.max_radius());
  const HeightCells cells(index, xy, pieces.size() > 1 && n >= kCellsFromPoints ? n : 0, reach);
  if (floors) std::copy(floors, floors + n, z_out);
  else std::fill(z_out, z_out + n, floor_z);
  if (set_by) std::fill(set_by, set_by + n, kSetByFloor);
  for (std::size_t k = 0; k < pieces.size(); ++k) {
    const AssemblyPiece& p = pieces[k];
    BatchOptions pass = options;  // progress over all passes
    if (options.progress)
      pass.progress = [&options, k, passes](double f) { return options.progress((static_cast<double>(k) + f) / passes); };
    for (std::size_t i = 0; i < n; ++i) base[i] = z_out[i] + p.lift;
    if (k == 0 && !floors)  // one floor: the plain batch (with no clearance, the very heights of drop_batch)
      drop_batch(index, p.profile, xy, n, floor_z + p.lift, top.data(), pass, stats);
    else if (k == 0)
      drop_batch(index, p.profile, xy, n, base.data(), top.data(), pass, stats);
    else
      drop_piece(index, p.profile, xy, n, base.data(), top.data(), cells, rows, bound,
                 p.profile.max_radius() <= kTilesUpTo * pieces[0].profile.max_radius(), pass, stats);
    for (std::size_t i = 0; i < n; ++i) {
      if (top[i] > base[i] && top[i] - p.lift > z_out[i]) {
        z_out[i] = top[i] - p.lift;
        if (set_by) set_by[i] = p.owner;
      }
    }
  }
}

}  // namespace

void drop_assembly_batch(const MeshIndex& index, const ToolAssembly& tool, const double* xy, std::size_t n,
                         double floor_z, double* z_out, int32_t* set_by, const BatchOptions& options,
                         DropStats* stats) {
  require_in_range(floor_z, "floor_z");
  drop_assembly_floors(index, tool, xy, n, nullptr, floor_z, z_out, set_by, options, stats);
}

void drop_assembly_batch(const MeshIndex& index, const ToolAssembly& tool, const double* xy, std::size_t n,
                         const double* floors, double* z_out, int32_t* set_by, const BatchOptions& options,
                         DropStats* stats) {
  for (std::size_t i = 0; i < n; ++i)
    if (std::isnan(floors[i])) throw std::invalid_argument("drop floors must not be NaN (floor " + std::to_string(i) + ")");
  drop_assembly_floors(index, tool, xy, n, floors, 0.0, z_out, set_by, options, stats);
}

}  // namespace tmm
