#include "tmm/query/waterline.hpp"

#include <algorithm>
#include <atomic>
#include <cmath>
#include <limits>
#include <sstream>
#include <stdexcept>
#include <unordered_map>

#include "tmm/query/drop_cutter.hpp"
#include "tmm/util/bracket_1d.hpp"

namespace tmm {

double WaterlineLoop::area() const {
  const std::size_t n = size();
  double a = 0;
  for (std::size_t i = 0, j = n - 1; i < n; j = i++) a += xy[2 * j] * xy[2 * i + 1] - xy[2 * i] * xy[2 * j + 1];
  return 0.5 * a;
}

namespace {

constexpr int kIllinoisSteps = 16;  // then bisection: h can jump (a flat end mill at a vertical wall)

void check_options(const WaterlineOptions& o) {
  auto fail = [](const char* what, double v, const char* allowed) {
    std::ostringstream msg;
    msg << "waterline " << what << " must be " << allowed << ", got " << v;
    throw std::invalid_argument(msg.str());
  };
  for (double v : {o.xmin, o.ymin, o.xmax, o.ymax})
    if (!std::isfinite(v)) fail("bounds", v, "finite");
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

struct Point {
  double x, y;
  bool contact;
};

// The shared grid of drop heights, padded by one ring of free nodes (height -inf).
struct Grid {
  std::size_t NX = 0, NY = 0;  // padded node counts
  double x0 = 0, y0 = 0;       // position of padded node (1, 1), the bounds' corner
  double dx = 0, dy = 0;
  std::vector<double> h;       // NX * NY heights
  std::vector<double> row_lo, row_hi;  // per cell row J: lowest and highest height of rows J and J + 1
  // Adaptive grid: cells refined are sampled on a lattice k times finer (k = 1: no refinement). Fine node
  // (X, Y) lies at coarse (X / k, Y / k); band: the cutter's lift over a cell, h(cell diagonal / sqrt 2).
  std::size_t k = 1;
  double band = 0;

  double x(std::size_t I) const { return x0 + (static_cast<double>(I) - 1.0) * dx; }
  double y(std::size_t J) const { return y0 + (static_cast<double>(J) - 1.0) * dy; }
  bool ring(std::size_t I, std::size_t J) const { return I == 0 || J == 0 || I + 1 == NX || J + 1 == NY; }
};

// One level: marching squares, exact crossings, loops, refinement. Drops from one thread, with hints.
class Level {
 public:
  Level(const MeshIndex& index, const Cutter& cutter, const Grid& grid, const WaterlineOptions& o, double z)
      : index_(index), cutter_(cutter), g_(grid), o_(o), z_(z),
        eval_floor_(z - 2.0 * std::max({cutter.max_radius(), grid.dx, grid.dy})) {}

  std::vector<WaterlineLoop> loops();
  std::size_t drops() const { return drops_; }
  std::size_t refined_cells() const { return refined_count_; }

 private:
  bool blocked(double x, double y) {
    ++drops_;
    return drop_point(index_, cutter_, x, y, z_, nullptr, &hint_) > z_;
  }
  // z - h, h clamped to a floor below z (Illinois needs finite values where nothing is under the tool).
  double clearance(double x, double y) {
    ++drops_;
    return z_ - drop_point(index_, cutter_, x, y, eval_floor_, nullptr, &hint_);
  }
  // The boundary on the segment from a free point f (clearance cf >= 0) to a blocked point b (cb < 0): the
  // free end of a bracket narrower than o_.bracket.
  Point crossing(Point f, Point b, double cf, double cb);
  Point edge_crossing(uint64_t edge);

  // The fine lattice (g_.k per coarse cell; with k = 1 it is the coarse grid). Edge keys: the edge from
  // node (X, Y) along X (vertical = 0) or Y, one fine step long or (coarse) one coarse cell long.
  uint64_t NXf() const { return static_cast<uint64_t>((g_.NX - 1) * g_.k + 1); }
  uint64_t key(std::size_t X, std::size_t Y, bool vertical, bool coarse) const {
    return ((static_cast<uint64_t>(Y) * NXf() + X) * 2 + (vertical ? 1 : 0)) * 2 + (coarse ? 1 : 0);
  }
  double fx(std::size_t X) const { return g_.x0 + (static_cast<double>(X) / static_cast<double>(g_.k) - 1.0) * g_.dx; }
  double fy(std::size_t Y) const { return g_.y0 + (static_cast<double>(Y) / static_cast<double>(g_.k) - 1.0) * g_.dy; }
  bool fine_ring(std::size_t X, std::size_t Y) const {
    const std::size_t k = g_.k;
    return X < k || Y < k || X > (g_.NX - 2) * k || Y > (g_.NY - 2) * k;
  }
  bool coarse_node(std::size_t X, std::size_t Y) const { return X % g_.k == 0 && Y % g_.k == 0; }
  bool state(std::size_t X, std::size_t Y);  // blocked (h > z) at a lattice node; ring nodes are free
  double node_clearance(std::size_t X, std::size_t Y);  // z - h at a lattice node
  bool cell_refined(std::size_t I, std::size_t J) const {
    return !refined_.empty() && refined_[J * (g_.NX - 1) + I] != 0;
  }
  // Whether a triangle can hold the tool above z somewhere over the rectangle (the drop's own pruning).
  bool may_block(double x0, double y0, double x1, double y1) const;
  void refine_cells();
  // The key of coarse cell (I, J)'s edge from its corner (X, Y) = (I k, J k) (vertical or not) as both of
  // its cells see it: the fine step that holds its one crossing when a refined cell shares it.
  uint64_t shared_edge(std::size_t X, std::size_t Y, bool vertical, bool fine);
  // Marching squares on one cell: corner states c (counter-clockwise from the lower left), edge keys e
  // (bottom, right, top, left), the centre for a saddle.
  void march(const bool c[4], const uint64_t e[4], double cx, double cy);
  // Whether the exact loop crosses the perpendicular through p + t (q - p) farther than chord_tol from the
  // chord (inside the bounds); c: that crossing.
  bool off_chord(const Point& p, const Point& q, double t, Point& c);
  void refine(const Point& p, const Point& q, int depth, std::vector<Point>& out);

  const MeshIndex& index_;
  const Cutter& cutter_;
  const Grid& g_;
  const WaterlineOptions& o_;
  const double z_, eval_floor_;
  int32_t hint_ = -1;
  std::size_t drops_ = 0;
  std::unordered_map<uint64_t, uint8_t> fine_;  // states of fine nodes sampled (not coarse ones)
  std::vector<uint8_t> refined_;                 // per coarse cell (adaptive grid only)
  std::vector<std::size_t> row_refined_;         // refined cells per cell row
  std::size_t refined_count_ = 0;
  std::unordered_map<uint64_t, uint64_t> next_;  // marching segments, blocked on the left: edge -> edge
  std::vector<uint64_t> starts_;                 // their start edges in scan order (the loops' order)
};

Point Level::crossing(Point f, Point b, double cf, double cb) {
  const double length = std::hypot(b.x - f.x, b.y - f.y);
  const double width = o_.bracket / length;  // in t
  auto at = [&](double t) { return Point{f.x + t * (b.x - f.x), f.y + t * (b.y - f.y), true}; };
  auto good = [&](double t) {
    const Point p = at(t);
    return !blocked(p.x, p.y);
  };
  // Illinois regula falsi on z - h over [a, c] (a free, c blocked). Once the secant puts the root within the
  // bracket width of a new point, one predicate drop on the other side closes the bracket (h is smooth
  // almost everywhere: the usual case ends in a few drops). Steps that do not halve the bracket are
  // followed by a bisection: h can jump (a flat end mill reaching a vertical wall).
  double a = 0.0, c = 1.0, fa = std::min(cf, z_ - eval_floor_), fc = cb;
  int side = 0;
  for (int k = 0; k < kIllinoisSteps && c - a > width; ++k) {
    const double before = c - a;
    double m = (a * fc - c * fa) / (fc - fa);
    if (!(m > a && m < c)) m = 0.5 * (a + c);
    const Point p = at(m);
    const double fm = clearance(p.x, p.y);
    const double slope = (fc - fa) / (c - a);  // < 0
    if (fm >= 0.0) {
      a = m;
      fa = fm;
      if (side == -1) fc *= 0.5;
      side = -1;
      if (fm < -slope * width && m + width < c && !good(m + width)) c = m + width;
    } else {
      c = m;
      fc = fm;
      if (side == 1) fa *= 0.5;
      side = 1;
      if (-fm < -slope * width && m - width > a && good(m - width)) a = m - width;
    }
    if (c - a > 0.5 * before && c - a > width) {
      const double mid = 0.5 * (a + c);
      const Point q = at(mid);
      const double fq = clearance(q.x, q.y);
      if (fq >= 0.0) {
        a = mid;
        fa = fq;
      } else {
        c = mid;
        fc = fq;
      }
      side = 0;
    }
  }
  if (c - a > width) {
    const int steps = static_cast<int>(std::ceil(std::log2((c - a) / width)));
    a = bisect(a, c, steps, good).good;
  }
  return at(a);
}

bool Level::state(std::size_t X, std::size_t Y) {
  if (coarse_node(X, Y)) return g_.h[(Y / g_.k) * g_.NX + X / g_.k] > z_;
  if (fine_ring(X, Y)) return false;
  const uint64_t id = static_cast<uint64_t>(Y) * NXf() + X;
  const auto it = fine_.find(id);
  if (it != fine_.end()) return it->second != 0;
  const bool b = blocked(fx(X), fy(Y));
  fine_.emplace(id, b ? 1 : 0);
  return b;
}

double Level::node_clearance(std::size_t X, std::size_t Y) {
  if (coarse_node(X, Y)) return z_ - g_.h[(Y / g_.k) * g_.NX + X / g_.k];
  return clearance(fx(X), fy(Y));
}

Point Level::edge_crossing(uint64_t edge) {
  const bool coarse = edge & 1u, vertical = (edge >> 1) & 1u;
  const uint64_t node = edge >> 2;
  const std::size_t X = static_cast<std::size_t>(node % NXf()), Y = static_cast<std::size_t>(node / NXf());
  const std::size_t L = coarse ? g_.k : 1;
  const std::size_t X2 = vertical ? X : X + L, Y2 = vertical ? Y + L : Y;
  const Point a{fx(X), fy(Y), true}, b{fx(X2), fy(Y2), true};
  // A ring node stands for "outside the bounds": the crossing is the bound itself, not a contact.
  if (fine_ring(X, Y)) return Point{b.x, b.y, false};
  if (fine_ring(X2, Y2)) return Point{a.x, a.y, false};
  // The states decided the marching; the clearances only start the search (kept on their sides).
  double ca = node_clearance(X, Y), cb = node_clearance(X2, Y2);
  if (state(X, Y)) {
    ca = std::min(ca, -1e-300);
    cb = std::max(cb, 0.0);
    return crossing(b, a, cb, ca);
  }
  ca = std::max(ca, 0.0);
  cb = std::min(cb, -1e-300);
  return crossing(a, b, ca, cb);
}

bool Level::may_block(double x0, double y0, double x1, double y1) const {
  bool any = false;
  index_.near_rect(x0, y0, x1, y1, cutter_.max_radius(), z_, [&](const IndexedTriangle& t, int32_t) {
    if (any) return;
    const double dx = std::max({t.xmin - x1, x0 - t.xmax, 0.0});
    const double dy = std::max({t.ymin - y1, y0 - t.ymax, 0.0});
    any = dx * dx + dy * dy < cutter_.reach2(t.zmax - z_);
  });
  return any;
}

void Level::refine_cells() {
  const std::size_t NX = g_.NX, NY = g_.NY, CX = NX - 1, CY = NY - 1, k = g_.k;
  refined_.assign(CX * CY, 0);
  row_refined_.assign(CY, 0);
  std::vector<std::size_t> work;
  auto add = [&](std::size_t I, std::size_t J) {
    uint8_t& r = refined_[J * CX + I];
    if (r) return;
    r = 1;
    ++row_refined_[J];
    ++refined_count_;
    work.push_back(J * CX + I);
    if (static_cast<double>(refined_count_) * static_cast<double>((k + 1) * (k + 1)) >
        static_cast<double>(kMaxWaterlineFineNodes)) {
      std::ostringstream msg;
      msg << "waterline minimum step refines more than " << refined_count_ << " cells of " << k << " x " << k
          << " at level z " << z_ << ", over the kernel's limit of " << kMaxWaterlineFineNodes
          << " fine nodes a level; use a larger minimum step or sample step";
      throw std::invalid_argument(msg.str());
    }
  };
  const double band = g_.band;
  for (std::size_t J = 0; J < CY; ++J) {
    if (z_ - band >= g_.row_hi[J] || z_ < g_.row_lo[J] - band) continue;
    for (std::size_t I = 0; I < CX; ++I) {
      const double h[4] = {g_.h[J * NX + I], g_.h[J * NX + I + 1], g_.h[(J + 1) * NX + I + 1],
                           g_.h[(J + 1) * NX + I]};
      int blocked_corners = 0;
      bool near = false;  // a node within the band of z (ring nodes are -inf: never)
      for (double v : h) {
        blocked_corners += v > z_;
        near = near || std::abs(v - z_) < band;
      }
      if (blocked_corners == 4) continue;
      if (blocked_corners == 2 && (h[0] > z_) == (h[2] > z_)) {  // a saddle
        add(I, J);
        continue;
      }
      if (!near) continue;
      // All free: a blocked piece between the nodes needs triangles that lift the tool above z over it.
      if (blocked_corners == 0 && !may_block(g_.x(I), g_.y(J), g_.x(I + 1), g_.y(J + 1))) continue;
      add(I, J);
    }
  }
  // Closure: an unrefined neighbour must see at most one crossing on the edge it shares with a refined cell.
  while (!work.empty()) {
    const std::size_t cell = work.back();
    work.pop_back();
    const std::size_t I = cell % CX, J = cell / CX, X = I * k, Y = J * k;
    for (std::size_t b = 0; b <= k; ++b)
      for (std::size_t a = 0; a <= k; ++a) state(X + a, Y + b);
    auto changes = [&](std::size_t X0, std::size_t Y0, bool vertical) {
      int n = 0;
      for (std::size_t t = 0; t < k; ++t) {
        const bool s0 = vertical ? state(X0, Y0 + t) : state(X0 + t, Y0);
        const bool s1 = vertical ? state(X0, Y0 + t + 1) : state(X0 + t + 1, Y0);
        n += s0 != s1;
      }
      return n;
    };
    if (J > 0 && !cell_refined(I, J - 1) && changes(X, Y, false) > 1) add(I, J - 1);
    if (J + 1 < CY && !cell_refined(I, J + 1) && changes(X, Y + k, false) > 1) add(I, J + 1);
    if (I > 0 && !cell_refined(I - 1, J) && changes(X, Y, true) > 1) add(I - 1, J);
    if (I + 1 < CX && !cell_refined(I + 1, J) && changes(X + k, Y, true) > 1) add(I + 1, J);
  }
}

uint64_t Level::shared_edge(std::size_t X, std::size_t Y, bool vertical, bool fine) {
  if (!fine) return key(X, Y, vertical, true);
  for (std::size_t t = 0; t < g_.k; ++t) {
    const std::size_t Xa = vertical ? X : X + t, Ya = vertical ? Y + t : Y;
    const std::size_t Xb = vertical ? X : X + t + 1, Yb = vertical ? Y + t + 1 : Y;
    if (state(Xa, Ya) != state(Xb, Yb)) return key(Xa, Ya, vertical, false);
  }
  return key(X, Y, vertical, true);  // no crossing (not asked for)
}

void Level::march(const bool c[4], const uint64_t e[4], double cx, double cy) {
  const int k = c[0] + c[1] + c[2] + c[3];
  if (k == 0 || k == 4) return;
  auto add = [&](int from, int to) {
    next_.emplace(e[from], e[to]);
    starts_.push_back(e[from]);
  };
  if (k == 2 && c[0] == c[2]) {  // a saddle: the centre decides whether the blocked corners join
    const bool centre = blocked(cx, cy);
    const int first = c[0] ? 0 : 1;  // the blocked -> free edges are first and first + 2
    for (int f : {first, first + 2}) add(f, centre ? (f + 1) % 4 : (f + 3) % 4);
    return;
  }
  int from = -1, to = -1;
  for (int q = 0; q < 4; ++q) {
    if (c[q] && !c[(q + 1) % 4]) from = q;
    if (!c[q] && c[(q + 1) % 4]) to = q;
  }
  add(from, to);
}

bool Level::off_chord(const Point& p, const Point& q, double t, Point& c) {
  const double dx = q.x - p.x, dy = q.y - p.y, length = std::hypot(dx, dy);
  const double nx = -dy / length, ny = dx / length;  // left normal: the blocked side
  const Point m{p.x + t * dx, p.y + t * dy, true};
  const bool m_blocked = blocked(m.x, m.y);
  // The boundary lies towards the free side of m (right if m is blocked, left if free): within chord_tol
  // when the state changes there already.
  const double sign = m_blocked ? -1.0 : 1.0;
  auto along = [&](double s) { return Point{m.x + sign * s * nx, m.y + sign * s * ny, true}; };
  double s_in = 0.0, s_out = o_.chord_tol;
  Point out_pt = along(s_out);
  while (blocked(out_pt.x, out_pt.y) == m_blocked) {
    s_in = s_out;
    s_out *= 2.0;
    if (s_out > length) return false;  // no boundary within a chord length: leave the chord
    out_pt = along(s_out);
  }
  if (s_in == 0.0) return false;  // the exact loop is within chord_tol of the chord here
  const Point in_pt = along(s_in);
  const Point& f = m_blocked ? out_pt : in_pt;
  const Point& b = m_blocked ? in_pt : out_pt;
  const double cf = clearance(f.x, f.y), cb = clearance(b.x, b.y);
  c = cb < 0.0 ? crossing(f, b, cf, cb) : f;  // (cb >= 0 cannot be: b is blocked)
  const double slack = 1e-9;
  return c.x >= o_.xmin - slack && c.x <= o_.xmax + slack && c.y >= o_.ymin - slack && c.y <= o_.ymax + slack;
}

void Level::refine(const Point& p, const Point& q, int depth, std::vector<Point>& out) {
  if (depth >= o_.max_depth || std::hypot(q.x - p.x, q.y - p.y) < o_.min_segment) return;
  // The midpoint, then the quarters: on a faceted mesh the loop's curvature changes along a chord, so its
  // farthest point need not lie at the middle.
  Point c;
  for (double t : {0.5, 0.25, 0.75}) {
    if (!off_chord(p, q, t, c)) continue;
    refine(p, c, depth + 1, out);
    out.push_back(c);
    refine(c, q, depth + 1, out);
    return;
  }
}

std::vector<WaterlineLoop> Level::loops() {
  const std::size_t NX = g_.NX, NY = g_.NY, k = g_.k;
  if (k > 1) refine_cells();
  auto s = [&](std::size_t I, std::size_t J) { return g_.h[J * NX + I] > z_; };
  for (std::size_t J = 0; J + 1 < NY; ++J) {
    const bool row_refined = !row_refined_.empty() && row_refined_[J] > 0;
    if (!row_refined && (z_ >= g_.row_hi[J] || z_ < g_.row_lo[J])) continue;  // all free or all blocked
    for (std::size_t I = 0; I + 1 < NX; ++I) {
      const std::size_t X = I * k, Y = J * k;
      if (cell_refined(I, J)) {
        for (std::size_t b = 0; b < k; ++b)
          for (std::size_t a = 0; a < k; ++a) {
            const std::size_t x = X + a, y = Y + b;
            const bool c[4] = {state(x, y), state(x + 1, y), state(x + 1, y + 1), state(x, y + 1)};
            const uint64_t e[4] = {key(x, y, false, false), key(x + 1, y, true, false), key(x, y + 1, false, false),
                                   key(x, y, true, false)};
            march(c, e, 0.5 * (fx(x) + fx(x + 1)), 0.5 * (fy(y) + fy(y + 1)));
          }
        continue;
      }
      const bool c[4] = {s(I, J), s(I + 1, J), s(I + 1, J + 1), s(I, J + 1)};
      const int n = c[0] + c[1] + c[2] + c[3];
      if (n == 0 || n == 4) continue;
      // edge e between corners e and e + 1 (counter-clockwise): bottom, right, top, left
      const uint64_t e[4] = {
          c[0] != c[1] ? shared_edge(X, Y, false, J > 0 && cell_refined(I, J - 1)) : 0,
          c[1] != c[2] ? shared_edge(X + k, Y, true, I + 2 < NX && cell_refined(I + 1, J)) : 0,
          c[3] != c[2] ? shared_edge(X, Y + k, false, J + 2 < NY && cell_refined(I, J + 1)) : 0,
          c[0] != c[3] ? shared_edge(X, Y, true, I > 0 && cell_refined(I - 1, J)) : 0};
      march(c, e, 0.5 * (g_.x(I) + g_.x(I + 1)), 0.5 * (g_.y(J) + g_.y(J + 1)));
    }
  }
  const auto& next = next_;
  const auto& starts = starts_;
  std::vector<WaterlineLoop> result;
  std::unordered_map<uint64_t, bool> done;
  done.reserve(starts.size());
  for (uint64_t first : starts) {
    if (done.count(first)) continue;
    std::vector<Point> pts;
    for (uint64_t e = first;;) {
      done.emplace(e, true);
      const Point p = edge_crossing(e);
      if (pts.empty() || p.x != pts.back().x || p.y != pts.back().y) pts.push_back(p);
      else pts.back().contact = pts.back().contact && p.contact;
      e = next.at(e);
      if (e == first) break;
    }
    while (pts.size() > 1 && pts.front().x == pts.back().x && pts.front().y == pts.back().y) {
      pts.front().contact = pts.front().contact && pts.back().contact;
      pts.pop_back();
    }
    if (pts.size() < 3) continue;  // a degenerate loop (a blocked node touching the bounds' corner only)
    WaterlineLoop loop;
    loop.z = z_;
    const std::size_t n = pts.size();
    std::vector<Point> fine;
    fine.reserve(n);
    for (std::size_t i = 0; i < n; ++i) {
      const Point& p = pts[i];
      const Point& q = pts[(i + 1) % n];
      fine.push_back(p);
      if (p.contact && q.contact) refine(p, q, 0, fine);
    }
    loop.xy.reserve(2 * fine.size());
    loop.contact.reserve(fine.size());
    for (const Point& p : fine) {
      loop.xy.push_back(p.x);
      loop.xy.push_back(p.y);
      loop.contact.push_back(p.contact ? 1 : 0);
    }
    result.push_back(std::move(loop));
  }
  return result;
}

}  // namespace

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

std::vector<std::vector<WaterlineLoop>> waterline(const MeshIndex& index, const Cutter& cutter,
                                                  const std::vector<double>& zs, const WaterlineOptions& o,
                                                  const BatchOptions& batch, WaterlineStats* stats) {
  std::size_t nx = 0, ny = 0;
  waterline_grid_size(o, nx, ny);
  double zlow = kInf;
  for (double z : zs) {
    if (!std::isfinite(z)) {
      std::ostringstream msg;
      msg << "waterline level z must be finite, got " << z;
      throw std::invalid_argument(msg.str());
    }
    zlow = std::min(zlow, z);
  }
  std::vector<std::vector<WaterlineLoop>> result(zs.size());
  if (zs.empty()) return result;

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
    g.band = cutter.height(std::min(cell, cutter.max_radius()));
  }
  // Progress: the grid's share of the work by a rough count of drops (a level costs some 30 drops per
  // crossing, a few crossings per grid line).
  const double grid_work = static_cast<double>(nx * ny);
  const double level_work = static_cast<double>(zs.size()) * 60.0 * static_cast<double>(nx + ny);
  const double grid_share = grid_work / (grid_work + level_work);
  BatchOptions grid_batch{batch.threads, {}};
  if (batch.progress)
    grid_batch.progress = [&](double f) { return batch.progress(f * grid_share); };
  {
    std::vector<double> xy(2 * nx * ny), z(nx * ny);
    for (std::size_t j = 0; j < ny; ++j)
      for (std::size_t i = 0; i < nx; ++i) {
        xy[2 * (j * nx + i)] = g.x(i + 1);
        xy[2 * (j * nx + i) + 1] = g.y(j + 1);
      }
    // Any floor below the lowest level: a height at the floor is free at every level.
    drop_batch(index, cutter, xy.data(), nx * ny, zlow - 1.0, z.data(), grid_batch);
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

  std::atomic<std::size_t> drops{0}, refined{0};
  BatchOptions level_batch{batch.threads, {}};
  if (batch.progress)
    level_batch.progress = [&](double f) { return batch.progress(grid_share + f * (1.0 - grid_share)); };
  parallel_chunks(zs.size(), 1, level_batch, [&](std::size_t begin, std::size_t end) {
    for (std::size_t k = begin; k < end; ++k) {
      Level level(index, cutter, g, o, zs[k]);
      result[k] = level.loops();
      drops += level.drops();
      refined += level.refined_cells();
    }
  });
  if (stats) {
    stats->grid_nodes = nx * ny;
    stats->drops = drops.load();
    stats->refined_cells = refined.load();
  }
  return result;
}

}  // namespace tmm
