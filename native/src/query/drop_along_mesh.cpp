// The mesh query of the drop along a direction (drop_direction.hpp): a best-first walk of the rotated index's
// hierarchy bounded by the cutter solid's lowest point and its supporting planes from below; each candidate
// triangle first given the clearance certificate (swept_clearance.hpp), then, unless it is proven clear, solved
// by the general method, both with the best travel so far as the cap (docs/drop_direction.md, "Mesh query").
// A triangle beyond the solid's plane of support at the best contact so far is missed before it (set_tangent).
#include <algorithm>
#include <atomic>
#include <cmath>
#include <memory>
#include <stdexcept>
#include <vector>

#include "tmm/query/drop_direction.hpp"
#include "tmm/query/swept_clearance.hpp"
#include "tmm/util/range.hpp"

namespace tmm {

using Eigen::Vector3d;
using direction_detail::kParallelAxisTol;
using direction_detail::require_finite_length;
using direction_detail::require_unit;

namespace {

constexpr double kInfinity = std::numeric_limits<double>::infinity();

// Best-first walk of the index's hierarchy for a cutter whose lowest point is `floor` high at best: visits
// the triangles whose XY' bounds come within `radius` of (x, y) and whose highest point is above `floor`, in
// the nodes whose highest point, lowered by rise(d, x0, x1, y0, y1, enough) (d: the box's XY' distance from
// (x, y), [x0, x1] x [y0, y1] the box less (x, y); it may stop at `enough`, which prunes the box), is above
// `floor` (boxes about (x, y) or wider than 2 `radius` by their highest point alone); `floor` may rise during
// the walk. Written over nodes() and triangles() rather than MeshIndex::walk, whose pruning is tied to the -Z profile.
template <class Rise, class Visit>
void walk_lowest(const MeshIndex& mi, double x, double y, double radius, const double& floor, Rise&& rise,
                 Visit&& visit) {
  const auto& nodes = mi.nodes();
  const auto& tris = mi.triangles();
  const double r2 = radius * radius;
  auto bound = [&](double xmin, double ymin, double xmax, double ymax, double zmax) {
    const double dx = std::max(std::max(xmin - x, x - xmax), 0.0);
    const double dy = std::max(std::max(ymin - y, y - ymax), 0.0);
    const double d2 = dx * dx + dy * dy;
    if (d2 > r2 || zmax <= floor) return -kInfinity;
    // Over a box about the tip, or wider than twice the reach, the planes' lowest corner bounds little and the
    // children are bounded again: the planes are kept for the boxes where they prune.
    if (d2 == 0.0 || (xmax - xmin) + (ymax - ymin) > 2.0 * radius) return zmax;
    return zmax - rise(std::sqrt(d2), xmin - x, xmax - x, ymin - y, ymax - y, zmax - floor);
  };
  struct Entry {
    int32_t node;
    double bound;
  };
  std::vector<Entry> stack;  // depth-first: at most ~2 entries per level
  stack.reserve(128);
  stack.push_back({0, kInfinity});
  while (!stack.empty()) {
    const Entry e = stack.back();
    stack.pop_back();
    if (e.bound <= floor) continue;
    const BvhNode& node = nodes[e.node];
    if (node.count > 0) {
      for (int32_t i = node.first, end = node.first + node.count; i < end; ++i) {
        const IndexedTriangle& t = tris[i];
        if (t.zmax <= floor) continue;
        const double xmin = std::min({t.p[0][0], t.p[1][0], t.p[2][0]}), ymin = std::min({t.p[0][1], t.p[1][1], t.p[2][1]});
        const double xmax = std::max({t.p[0][0], t.p[1][0], t.p[2][0]}), ymax = std::max({t.p[0][1], t.p[1][1], t.p[2][1]});
        const double dx = std::max(std::max(xmin - x, x - xmax), 0.0), dy = std::max(std::max(ymin - y, y - ymax), 0.0);
        // The planes under K are tested on the corners themselves by `visit`, which is tighter than on the box.
        if (dx * dx + dy * dy <= r2) visit(t, i);
      }
    } else {
      const BvhNode& l = nodes[node.first];
      const BvhNode& r = nodes[node.first + 1];
      const double bl = bound(l.xmin, l.ymin, l.xmax, l.ymax, l.zmax);
      const double br = bound(r.xmin, r.ymin, r.xmax, r.ymax, r.zmax);
      // The more promising child last, so it is popped first: its contacts prune more of the other.
      if (bl > br) {
        if (br > floor) stack.push_back({node.first + 1, br});
        if (bl > floor) stack.push_back({node.first, bl});
      } else {
        if (bl > floor) stack.push_back({node.first, bl});
        if (br > floor) stack.push_back({node.first + 1, br});
      }
    }
  }
}

// Planes under K, as directions in the tool frame at these angles from the axis (8 around it, one at 0 and 180
// degrees); those facing down in the index's frame are kept. Along the axis: the tip's end (a flat bottom);
// across it: the side, which a tilted tool leans on.
constexpr double kPlaneAngles[] = {0.0, 60.0, 90.0, 120.0, 180.0};

}  // namespace

AlongCutter::AlongCutter(const DirectionalIndex& index, const Cutter& cutter, const Vector3d& axis,
                         bool fine_planes)
    : index_(&index), cutter_(cutter), a_(index.rotation() * axis.normalized()), frame_(a_) {
  require_unit(axis, "cutter axis");
  if ((a_ - Vector3d::UnitZ()).norm() <= kParallelAxisTol)
    throw std::invalid_argument("AlongCutter is the general method: the cutter axis must not be opposite to the "
                                "drop direction (use drop_along_point)");
  require_finite_length(cutter);
  W_ = frame_.to_tool(Vector3d(0, 0, -1));
  ahead_ = direction_detail::support(cutter, W_).value;
  // Lowest point of K along Z' below the tip: no triangle whose highest point is below the cutter's lowest
  // point can touch it, so the index walks on that height in place of the tip's. An edge shared by several
  // triangles is solved by its owner only (IndexedTriangle::owned_edges): the owner's bound covers the edge
  // (the edge lies in its box and below its highest point), so when the owner is pruned so is the edge.
  lowest_ = -direction_detail::support(cutter, -frame_.to_tool(Vector3d::UnitZ())).value;
  // K's shadow on the XY' plane lies within this distance of the tip.
  axis_xy_ = std::hypot(a_.x(), a_.y());
  reach_ = (cutter.max_radius() + cutter.cutting_length() * axis_xy_) * (1 + 1e-12) + 1e-12;
  // Tighter about the axis's midpoint: a long body leaning one way reaches no farther than its radius beside it.
  const double half = 0.5 * cutter.cutting_length();
  mid_x_ = half * a_.x(), mid_y_ = half * a_.y();
  mid_reach_ = (cutter.max_radius() + half * axis_xy_) * (1 + 1e-12) + 1e-12;
  // Tighter still across the lean: X = tip + z a + r (r square to a, |r| <= max_radius) has across . (X - tip)
  // = across . r_xy (across is square to a's XY' part), at most max_radius whatever z, and the motion along
  // -Z' leaves it unchanged. A triangle whose XY' box lies off that strip is never touched from this tip; the
  // disc clips the strip's ends, the strip the disc's sides, where a tilted holder's rim reaches farthest.
  // Each start's scan tests it (not the gather: a tile's strip is wider and its test per box cost more).
  if (axis_xy_ > 0) across_x_ = -a_.y() / axis_xy_, across_y_ = a_.x() / axis_xy_;
  side_ = cutter.max_radius() * (1 + 1e-12) + 1e-12;
  // A plane under K with normal n (n.z > 0, index frame): n . X >= -h_K(-n) for X in K about the tip.
  for (const double deg : kPlaneAngles) {
    const double th = deg * M_PI / 180.0;
    const int around = (deg == 0.0 || deg == 180.0) ? 1 : 8;
    for (int k = 0; k < around; ++k) {
      const double ph = 2.0 * M_PI * k / around;
      const Vector3d n = frame_.to_world(
          Vector3d(std::sin(th) * std::cos(ph), std::sin(th) * std::sin(ph), std::cos(th)));
      if (!(n.z() > 1e-3)) continue;
      planes_.push_back(plane_under(n));
    }
  }
  if (!fine_planes) return;
  for (const Vector3d& n : {a_, Vector3d(-a_)})
    if (n.z() > 1e-3) axial_.push_back(plane_under(n));
  fine_.resize(kFineAzimuths * kFineTilts);
  for (int k = 0; k < kFineAzimuths; ++k)
    for (int j = 0; j < kFineTilts; ++j) {
      const double th = M_PI * (j + 1) / (kFineTilts + 1), ph = 2.0 * M_PI * k / kFineAzimuths;
      const Vector3d n = frame_.to_world(
          Vector3d(std::sin(th) * std::cos(ph), std::sin(th) * std::sin(ph), std::cos(th)));
      fine_[k * kFineTilts + j] = n.z() > 1e-3 ? plane_under(n) : Plane{-kInfinity, 0.0, 0.0};
    }
}

AlongCutter::Plane AlongCutter::plane_under(const Vector3d& n) const {
  const double h = direction_detail::support(cutter_, frame_.to_tool(-n)).value;
  return {-h / n.z(), n.x() / n.z(), n.y() / n.z()};
}

inline void AlongCutter::across_range(double xmin, double xmax, double ymin, double ymax, double& lo,
                                      double& hi) const {
  lo = std::min(across_x_ * xmin, across_x_ * xmax) + std::min(across_y_ * ymin, across_y_ * ymax);
  hi = std::max(across_x_ * xmin, across_x_ * xmax) + std::max(across_y_ * ymin, across_y_ * ymax);
}

double AlongCutter::rise(double d, double x0, double x1, double y0, double y1, double enough) const {
  const double margin = 1e-9 * (1.0 + std::fabs(lowest_));  // against rounding
  enough += margin;
  double r = 0.0;
  // A point X = z a + r of K (|r| <= rmax, r perpendicular to a, z >= 0) at horizontal distance >= d from the
  // tip has z >= (d - rmax) / ah, so its height is at least a.z (d - rmax) / ah - rmax ah (axis leaning up):
  // boxes far from the tip can only meet the cutter's higher parts.
  const double rmax = cutter_.max_radius(), ah = axis_xy_;
  if (a_.z() > 0 && ah > 0 && d > rmax) r = a_.z() * (d - rmax) / ah - rmax * ah - lowest_;
  // Over the box K is no lower than any plane under it at the box's corner where that plane is lowest.
  for (std::size_t k = 0; k < planes_.size() && r < enough; ++k) {
    const Plane& p = planes_[k];
    const double low = p.c - std::max(p.gx * x0, p.gx * x1) - std::max(p.gy * y0, p.gy * y1);
    r = std::max(r, low - lowest_ - 1e-9 * std::fabs(low));
  }
  return std::max(0.0, r - margin);
}

bool AlongCutter::below(const Plane& p, const IndexedTriangle& t, double x, double y, double top) {
  for (int k = 0; k < 3; ++k) {
    const double lim = top + p.c - p.gx * (t.p[k][0] - x) - p.gy * (t.p[k][1] - y);
    if (!(t.p[k][2] < lim - 1e-9 * (1.0 + std::fabs(lim)))) return false;  // margin against rounding
  }
  return true;
}

inline int AlongCutter::azimuth(const Vector3d& c) const {
  const double ph = std::atan2(frame_.e2.dot(c), frame_.e1.dot(c));
  return static_cast<int>(std::lround(ph * (kFineAzimuths / (2.0 * M_PI)))) & (kFineAzimuths - 1);
}

bool AlongCutter::below_a_plane(const IndexedTriangle& t, double x, double y, double top) const {
  if (fine_.empty()) {
    for (const Plane& p : planes_)
      if (below(p, t, x, y, top)) return true;
    return false;
  }
  for (const Plane& p : axial_)
    if (below(p, t, x, y, top)) return true;
  // The planes leaning away from the triangle's centre, seen from the axis (K lies beyond each plane).
  const int k = azimuth(Vector3d(x, y, top) - (Vector3d(t.p[0]) + Vector3d(t.p[1]) + Vector3d(t.p[2])) / 3.0);
  for (int j = 0; j < kFineTilts; ++j)
    if (below(fine_[k * kFineTilts + j], t, x, y, top)) return true;
  return false;
}

AlongCutter::Search AlongCutter::search(const Vector3d& start, double max_travel) const {
  Search q;
  q.s = index_->rotation() * start;
  q.best = max_travel;
  q.floor = q.s.z() - max_travel + lowest_ - 1e-9;  // margin against rounding
  return q;
}

// Every corner of t beyond the plane of support at q's best contact: t is missed before it.
inline bool AlongCutter::beyond(const Search& q, const IndexedTriangle& t) {
  return q.tangent.dot(Vector3d(t.p[0])) >= q.level && q.tangent.dot(Vector3d(t.p[1])) >= q.level &&
         q.tangent.dot(Vector3d(t.p[2])) >= q.level;
}

inline void AlongCutter::consider(Search& q, const IndexedTriangle& t, int32_t i, Vector3d* plane,
                                  bool certify) const {
  // Most candidates are not touched before the best contact so far: a plane under K that has the whole
  // triangle below it proves it in a few products; else the plane that cleared the triangle from a nearby
  // start (one support point), else a separating plane found by the clearance certificate, at a fraction of
  // the cost of the triangle's pieces.
  if (beyond(q, t)) return;
  if (q.best < kNoTravel && below_a_plane(t, q.s.x(), q.s.y(), q.s.z() - q.best)) return;
  ++q.tested;
  const Vector3d q0 = frame_.to_tool(Vector3d(t.p[0]) - q.s), q1 = frame_.to_tool(Vector3d(t.p[1]) - q.s),
                 q2 = frame_.to_tool(Vector3d(t.p[2]) - q.s);
  if (q.best < kNoTravel) {
    const double t0 = std::min({q0.dot(W_), q1.dot(W_), q2.dot(W_)}) - ahead_;
    if (t0 >= q.best) return;
    const double low = t0 - 1e-9 * (1 + std::fabs(t0));
    // A corner, the centre or an edge's midpoint inside K at the best or touching it (a tie at a touched
    // vertex): no plane separates the triangle from K by the proofs' margin, or only after many steps of
    // the certificate, so it goes straight to its contact.
    if (inside_at(q0, q.best) || inside_at(q1, q.best) || inside_at(q2, q.best) ||
        inside_at((q0 + q1 + q2) / 3.0, q.best) || inside_at(0.5 * (q0 + q1), q.best) ||
        inside_at(0.5 * (q1 + q2), q.best) || inside_at(0.5 * (q2 + q0), q.best))
      certify = false, plane = nullptr;
    if (plane && direction_detail::plane_clears(cutter_, q0, q1, q2, W_, low, q.best, *plane)) return;
    if (certify && direction_detail::triangle_clear(cutter_, q0, q1, q2, W_, low, q.best, plane)) return;
  }
  Vector3d n;
  const double tr = direction_detail::triangle_travel(cutter_, q0, q1, q2, W_, q.best, t.owned_edges, &n);
  if (tr < q.best) {
    q.best = tr;
    q.winner = i;
    q.floor = q.s.z() - tr + lowest_ - 1e-9;
    set_tangent(q, n);
  }
}

// Whether the point p (tool frame, the start at the origin) lies inside K moved by `travel` or within `near` of
// its surface (the profile tested at the point's radius, at most K's).
inline bool AlongCutter::inside_at(const Vector3d& p, double travel) const {
  constexpr double near = 1e-6;  // mm
  const double z = p.z() - travel * W_.z(), x = p.x() - travel * W_.x(), y = p.y() - travel * W_.y();
  const double rho2 = x * x + y * y, rmax = cutter_.max_radius();
  if (!(z > -near && z < cutter_.cutting_length() + near && rho2 < (rmax + near) * (rmax + near))) return false;
  return cutter_.height(std::min(std::sqrt(rho2), rmax)) < z + near;
}

void AlongCutter::set_tangent(Search& q, const Vector3d& n) const {
  // K at travel t lies within n . X <= h_K(n) + t n . W (tool frame, the start at the origin): below the level
  // at the best for every earlier travel when n . W > 0. A plane nearly along the motion proves little and
  // would turn rounding into travel: none then.
  const double len = n.norm();
  q.level = kInfinity;
  if (!(len > 0) || !(n.dot(W_) > 0.05 * len)) return;
  const Vector3d u = n / len;
  q.tangent = frame_.to_world(u);
  q.level = direction_detail::support(cutter_, u).value + q.best * u.dot(W_) + q.tangent.dot(q.s);
}

double AlongCutter::drop(const Vector3d& start, double max_travel, DropStats* stats, int32_t* hint) const {
  Search q = search(start, max_travel);
  const auto& tris = index_->index().triangles();
  if (hint && *hint >= 0 && static_cast<std::size_t>(*hint) < tris.size()) consider(q, tris[*hint], *hint);
  const int32_t skip = hint ? *hint : -1;
  walk_lowest(
      index_->index(), q.s.x(), q.s.y(), reach_, q.floor,
      [&](double d, double x0, double x1, double y0, double y1, double enough) {
        return rise(d, x0, x1, y0, y1, enough);
      },
      [&](const IndexedTriangle& t, int32_t i) {
        if (i != skip) consider(q, t, i);
      });
  if (stats) stats->triangles_tested += q.tested;
  if (hint) *hint = q.winner;
  return q.best;
}

double AlongCutter::drop_on(const Vector3d& start, double max_travel, int32_t tri, DropStats* stats,
                            Eigen::Vector4d* tangent) const {
  Search q = search(start, max_travel);
  consider(q, index_->index().triangles()[static_cast<std::size_t>(tri)], tri);
  if (stats) stats->triangles_tested += q.tested;
  if (tangent) *tangent << q.tangent, q.level;
  return q.best;
}

double AlongCutter::drop_listed(const Vector3d& start, double max_travel, Candidates& cands, DropStats* stats,
                                int32_t* hint, int32_t known, const Eigen::Vector4d* tangent) const {
  Search q = search(start, max_travel);
  if (tangent) q.tangent = tangent->head<3>(), q.level = (*tangent)[3];  // proves no contact before a later travel
  const auto& tris = index_->index().triangles();
  // The last start's winner comes close again: its clearance certificate would nearly always fail before the
  // exact contact (the holder's on sphere_on_plate: at 1,728 of 1,738 starts), so it is solved at once.
  if (hint && *hint >= 0 && *hint != known && static_cast<std::size_t>(*hint) < tris.size())
    consider(q, tris[*hint], *hint, nullptr, false);
  const int32_t skip = hint ? *hint : -1;
  const double r2 = mid_reach_ * mid_reach_, mx = q.s.x() + mid_x_, my = q.s.y() + mid_y_;
  // The strip about this tip across the lean (two comparisons an entry).
  const double tw = across_x_ * q.s.x() + across_y_ * q.s.y();
  const double slack = side_ + 1e-9 * (1.0 + 2.0 * std::fabs(tw));  // against rounding
  const double w_lo = tw - slack, w_hi = tw + slack;
  const Plane& kp = cands.key_plane;
  // Below one of the gather's planes at this start's tip (below_everywhere for one start): missed before the
  // best. Each plane also bounds the travel from below (s.z + g . s.xy - h).
  auto under = [&](double h, double gx, double gy) {
    const double lim = q.s.z() - q.best + gx * q.s.x() + gy * q.s.y();
    return lim - h > 1e-9 * (1.0 + std::fabs(lim) + std::fabs(h));
  };
  auto cleared = [&](const Candidate& c) {
    return under(c.h[0], c.gx[0], c.gy[0]) || under(c.h[1], c.gx[1], c.gy[1]);
  };
  // A plane of support set by the hint just now, at the best: K at travel t lies below level + (t - best) n.W
  // along it, so a triangle's corners nearest that plane bound its travel (tight about the contact, where the
  // next winner lies).
  const bool local = q.winner >= 0 && q.level < kInfinity;
  const double nw = -q.tangent.z();  // n.W, the motion along -Z in the index frame
  auto& open = cands.open;  // the candidates left, by their bound
  open.clear();
  for (const Candidates::Run& run : cands.runs) {
    for (std::size_t e = run.begin; e < run.end; ++e) {
      Candidate& c = cands.list[e];
      // By decreasing h[1]: once one lies below the run's plane at this start, so do the rest of the run (the
      // margin grows slower than the gap).
      if (under(c.h[1], run.gx, run.gy)) break;
      if (c.zmax <= q.floor || under(c.key, kp.gx, kp.gy)) continue;
      if (c.wlo > w_hi || c.whi < w_lo) continue;
      const double dx = std::max(std::max(c.xmin - mx, mx - c.xmax), 0.0);
      const double dy = std::max(std::max(c.ymin - my, my - c.ymax), 0.0);
      if (dx * dx + dy * dy > r2 || c.tri == skip || c.tri == known || under(c.h[0], c.gx[0], c.gy[0])) continue;
      double nearest = -kInfinity;  // the corners' lowest level along the local plane
      if (local) {
        const IndexedTriangle& t = tris[c.tri];
        nearest = std::min({q.tangent.dot(Vector3d(t.p[0])), q.tangent.dot(Vector3d(t.p[1])),
                            q.tangent.dot(Vector3d(t.p[2]))});
        if (nearest >= q.level) continue;  // beyond the plane: missed before the best
      } else if (q.level < kInfinity && beyond(q, tris[c.tri])) {
        continue;
      }
      double bound = q.s.z() + kp.gx * q.s.x() + kp.gy * q.s.y() - c.key;
      for (int w = 0; w < 2; ++w) bound = std::max(bound, q.s.z() + c.gx[w] * q.s.x() + c.gy[w] * q.s.y() - c.h[w]);
      if (local) bound = std::max(bound, q.best + (nearest - q.level) / nw);
      open.emplace_back(bound, &c);
    }
  }
  // The likely first contacts first: each lowers the best, which clears more of the rest on their planes.
  std::sort(open.begin(), open.end(), [](const auto& a, const auto& b) {
    return a.first != b.first ? a.first < b.first : a.second->tri < b.second->tri;
  });
  for (const auto& [bound, c] : open)
    if (!under(c->key, kp.gx, kp.gy) && !cleared(*c)) consider(q, tris[c->tri], c->tri, &c->plane);
  if (stats) stats->triangles_tested += q.tested;
  if (hint) *hint = q.winner;
  return q.best;
}

// Over a group of starts, a plane under K sits at each start's tip at its cap; `offsets` holds per plane the
// lowest of top + g . tip over the starts, so that a point X lies below the plane at every start when
// X.z + g . X.xy < c + offset (the per-start test of below(), the tip's terms gathered).
bool AlongCutter::below_everywhere(const IndexedTriangle& t, Candidates& g, Candidate& best) const {
  const double* offsets = g.offsets.data();
  double slack[2] = {-kInfinity, -kInfinity};  // at the worst start, at the centre
  best.h[0] = best.h[1] = kInfinity;  // no plane: never below
  best.gx[0] = best.gx[1] = best.gy[0] = best.gy[1] = 0.0;
  auto try_plane = [&](const Plane& p, double offset) {
    if (!(p.c > -kInfinity)) return false;
    double h = -kInfinity;
    for (int k = 0; k < 3; ++k) h = std::max(h, t.p[k][2] + p.gx * t.p[k][0] + p.gy * t.p[k][1]);
    const double lim = p.c + offset, s = lim - h;
    if (s > 1e-9 * (1.0 + std::fabs(lim) + std::fabs(h))) return true;  // margin against rounding
    const double sc = p.c + g.centre.z() + p.gx * g.centre.x() + p.gy * g.centre.y() - h;
    for (int w = 0; w < 2; ++w)
      if ((w == 0 ? s : sc) > slack[w]) {
        slack[w] = w == 0 ? s : sc;
        best.h[w] = h - p.c, best.gx[w] = p.gx, best.gy[w] = p.gy;
      }
    return false;
  };
  std::size_t k = 0;
  if (fine_.empty()) {
    for (const Plane& p : planes_)
      if (try_plane(p, offsets[k++])) return true;
  } else {
    k = planes_.size();  // the coarse planes (fine ones at a few azimuths) are left to the node bounds
  }
  for (const Plane& p : axial_)
    if (try_plane(p, offsets[k++])) return true;
  if (fine_.empty()) return false;
  // The fine planes leaning away from the triangle, seen from the starts' centre (found only for a triangle
  // the flat end's plane leaves).
  const int fine_azimuth =
      azimuth(g.centre - (Vector3d(t.p[0]) + Vector3d(t.p[1]) + Vector3d(t.p[2])) / 3.0);
  if (!g.fine_done[fine_azimuth]) {  // the azimuth's offsets, once a gather needs them
    g.fine_done[fine_azimuth] = 1;
    for (int j = 0; j < kFineTilts; ++j) {
      const Plane& p = fine_[fine_azimuth * kFineTilts + j];
      double& o = g.offsets[k + fine_azimuth * kFineTilts + j];
      for (const Vector3d& tip : g.tips) o = std::min(o, tip.z() + p.gx * tip.x() + p.gy * tip.y());
    }
  }
  for (int j = 0; j < kFineTilts; ++j) {
    const std::size_t f = static_cast<std::size_t>(fine_azimuth * kFineTilts + j);
    if (try_plane(fine_[f], offsets[k + f])) return true;
  }
  return false;
}

bool AlongCutter::gather(const Vector3d* starts, const double* caps, std::size_t m, Candidates& out,
                         std::size_t limit) const {
  out.list.clear();
  out.runs.clear();
  if (m == 0) return true;
  const std::size_t coarse = planes_.size() + axial_.size();
  out.offsets.assign(coarse + fine_.size(), kInfinity);
  double x0 = kInfinity, x1 = -kInfinity, y0 = kInfinity, y1 = -kInfinity, floor = kInfinity;
  out.fine_done.assign(kFineAzimuths, 0);
  out.tips.clear();
  Vector3d centre = Vector3d::Zero();
  for (std::size_t j = 0; j < m; ++j) {
    const Vector3d s = index_->rotation() * starts[j];
    const double top = s.z() - caps[j];
    floor = std::min(floor, top + lowest_ - 1e-9);  // as search()'s, the margin against rounding
    const double mx = s.x() + mid_x_, my = s.y() + mid_y_;
    x0 = std::min(x0, mx), x1 = std::max(x1, mx), y0 = std::min(y0, my), y1 = std::max(y1, my);
    out.tips.emplace_back(s.x(), s.y(), top);
    out.centre = centre += out.tips.back() / static_cast<double>(m);
    std::size_t k = 0;
    for (const auto* set : {&planes_, &axial_})
      for (const Plane& p : *set) {
        out.offsets[k] = std::min(out.offsets[k], top + p.gx * s.x() + p.gy * s.y());
        ++k;
      }
  }
  const double r2 = mid_reach_ * mid_reach_;
  // Off every start's disc about its axis's midpoint. (The strip across the lean about every tip, tested here
  // too, cost more than it saved: each start's scan tests its own, tighter one.)
  auto far = [&](double xmin, double ymin, double xmax, double ymax) {
    const double dx = std::max(std::max(xmin - x1, x0 - xmax), 0.0), dy = std::max(std::max(ymin - y1, y0 - ymax), 0.0);
    return dx * dx + dy * dy > r2;
  };
  // A box whose highest corner under a plane's slope is below that plane at every start.
  auto box_below = [&](const BvhNode& b) {
    std::size_t k = 0;
    for (const auto* set : {&planes_, &axial_})
      for (const Plane& p : *set) {
        const double hi = b.zmax + std::max(p.gx * b.xmin, p.gx * b.xmax) + std::max(p.gy * b.ymin, p.gy * b.ymax);
        const double lim = p.c + out.offsets[k++];
        if (hi < lim - 1e-9 * (1.0 + std::fabs(lim))) return true;
      }
    return false;
  };
  // The key plane: K's flat end along the axis where it faces down, else its lowest point.
  const Plane kp = out.key_plane = axial_.empty() ? Plane{lowest_, 0.0, 0.0} : axial_.front();
  const MeshIndex& mi = index_->index();
  const auto& nodes = mi.nodes();
  const auto& tris = mi.triangles();
  std::vector<int32_t> stack{0};
  while (!stack.empty()) {
    const BvhNode& node = nodes[stack.back()];
    stack.pop_back();
    if (node.zmax <= floor || far(node.xmin, node.ymin, node.xmax, node.ymax) || box_below(node)) continue;
    if (node.count == 0) {
      stack.push_back(node.first);
      stack.push_back(node.first + 1);
      continue;
    }
    for (int32_t i = node.first, end = node.first + node.count; i < end; ++i) {
      const IndexedTriangle& t = tris[i];
      if (t.zmax <= floor || far(t.xmin, t.ymin, t.xmax, t.ymax)) continue;
      Candidate c{i, t.zmax, t.xmin, t.xmax, t.ymin, t.ymax, {}, {}, {}, 0.0, 0.0, 0.0, Vector3d::Zero()};
      if (below_everywhere(t, out, c)) continue;
      across_range(t.xmin, t.xmax, t.ymin, t.ymax, c.wlo, c.whi);
      if (out.list.size() == limit) return false;
      double h = -kInfinity;
      for (int k = 0; k < 3; ++k) h = std::max(h, t.p[k][2] + kp.gx * t.p[k][0] + kp.gy * t.p[k][1]);
      c.key = h - kp.c;
      out.list.push_back(c);
    }
  }
  // Runs of one centre plane, each by decreasing h[1] (an entry without one first in the run of slope 0:
  // no start leaves a run before it).
  std::sort(out.list.begin(), out.list.end(), [](const Candidate& a, const Candidate& b) {
    if (a.gx[1] != b.gx[1]) return a.gx[1] < b.gx[1];
    if (a.gy[1] != b.gy[1]) return a.gy[1] < b.gy[1];
    return a.h[1] != b.h[1] ? a.h[1] > b.h[1] : a.tri < b.tri;
  });
  out.runs.clear();
  for (std::size_t e = 0; e < out.list.size(); ++e) {
    const Candidate& c = out.list[e];
    if (e == 0 || c.gx[1] != out.runs.back().gx || c.gy[1] != out.runs.back().gy)
      out.runs.push_back({c.gx[1], c.gy[1], e, e});
    out.runs.back().end = e + 1;
  }
  return true;
}

double drop_along_point(const DirectionalIndex& index, const Cutter& cutter, const Vector3d& start,
                        const Vector3d& axis, double max_travel, DropStats* stats, int32_t* hint) {
  require_unit(axis, "cutter axis");
  const Vector3d s = index.rotation() * start;
  const Vector3d a = index.rotation() * axis.normalized();
  if ((a - Vector3d::UnitZ()).norm() <= kParallelAxisTol) {
    // V = -axis: the fast -Z drop-cutter in the rotated frame.
    const double floor_z = s.z() - max_travel;
    const double z = drop_point(index.index(), cutter, s.x(), s.y(), floor_z, stats, hint);
    return z <= floor_z ? max_travel : s.z() - z;
  }
  return AlongCutter(index, cutter, axis).drop(start, max_travel, stats, hint);
}

void drop_along_batch(const DirectionalIndex& index, const Cutter& cutter, const double* starts,
                      const double* axes, bool axes_per_point, std::size_t n, double max_travel,
                      double* travel_out, const BatchOptions& options, DropStats* stats) {
  // Validate up front: workers must not throw.
  require_rows_in_range(starts, n, 3, "start points");
  if (!(in_range(max_travel) || max_travel == kInfinity)) require_in_range(max_travel, "max_travel");
  for (std::size_t i = 0; i < (axes_per_point ? n : std::size_t{1}); ++i) {
    const Vector3d ax(axes[3 * i], axes[3 * i + 1], axes[3 * i + 2]);
    require_unit(ax, "cutter axis");
    if ((index.rotation() * ax.normalized() - Vector3d::UnitZ()).norm() > kParallelAxisTol)
      require_finite_length(cutter);
  }
  if (!axes_per_point && n > 0) {
    const Vector3d a = index.rotation() * Vector3d(axes[0], axes[1], axes[2]).normalized();
    if ((a - Vector3d::UnitZ()).norm() <= kParallelAxisTol) {
      // V = -axis for every point: the tiled -Z batch in the rotated frame, each point's floor max_travel
      // below its start (as drop_along_point's fast path, point by point).
      const direction_detail::RotatedStarts s(index, starts, n, max_travel);
      std::vector<double> z(n);
      drop_batch(index.index(), cutter, s.xy.data(), n, s.floors.data(), z.data(), options, stats);
      for (std::size_t i = 0; i < n; ++i) travel_out[i] = s.travel(i, z[i], max_travel);
      return;
    }
  }
  std::unique_ptr<AlongCutter> shared;  // one axis for all: its set-up once
  if (!axes_per_point && n > 0) shared = std::make_unique<AlongCutter>(index, cutter, Vector3d(axes[0], axes[1], axes[2]), true);
  std::atomic<std::size_t> tested{0};
  // The hint starts afresh with each chunk, so results do not depend on the thread count.
  parallel_chunks(n, 128, options, [&](std::size_t begin, std::size_t end) {
    DropStats local;
    int32_t hint = -1;
    for (std::size_t i = begin; i < end; ++i) {
      const double* ax = axes + (axes_per_point ? 3 * i : 0);
      const Vector3d start(starts[3 * i], starts[3 * i + 1], starts[3 * i + 2]);
      travel_out[i] = shared ? shared->drop(start, max_travel, &local, &hint)
                             : drop_along_point(index, cutter, start, Vector3d(ax[0], ax[1], ax[2]), max_travel,
                                                &local, &hint);
    }
    tested.fetch_add(local.triangles_tested);
  });
  if (stats) stats->triangles_tested += tested.load();
}

}  // namespace tmm
