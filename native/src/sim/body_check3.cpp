// The body check of a 3-axis move (the model: tmm/sim/body_check.hpp): the move's poses in order, each stamping
// the cutter into a scratch copy of the band's stock (only where the flutes reach the material's top) and then
// testing the grown bodies, exactly, over the cells whose tile may reach them.
#include "body_check_band.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

namespace tmm {
namespace body_detail {

namespace {
// Squared distance from the tile centre to the move's XY segment: the centre is at -(ex, ey) from its start,
// (dx, dy) its travel.
double seg_dist2(double ex, double ey, double dx, double dy) {
  const double L2 = dx * dx + dy * dy;
  const double t = L2 > 0.0 ? std::clamp(-(ex * dx + ey * dy) / L2, 0.0, 1.0) : 0.0;
  const double x = ex + t * dx, y = ey + t * dy;
  return x * x + y * y;
}
constexpr double kInf = std::numeric_limits<double>::infinity();
constexpr double kBoundSlack = 1e-6;  // mm: a tile's bound from the scratch also bounds the exact cut after it
}  // namespace

double BodyBand3::reach(const Cutter& cutter, const BodyCheck& check) {
  double r = 0.0;
  const ToolAssembly assembly(cutter, check.bodies);
  for (const AssemblyPiece& p : assembly.pieces())
    if (p.owner >= 0) r = std::max(r, p.profile.max_radius());
  return r;
}

BodyBand3::BodyBand3(ZMap& stock, const Cutter& cutter, const BodyCheck& check, std::size_t j0, std::size_t j1)
    : z_(stock), cutter_(cutter), check_(check), assembly_(cutter, check.bodies),
      off_(j0 * stock.nx()), tiles_(stock, j0, j1), scratch_((j1 - j0 + 1) * stock.nx()), gen_(scratch_.size(), 0),
      worst_(check.bodies.size()) {
  reach_ = reach(cutter, check);
  lowest_ = kInf;
  for (const AssemblyPiece& p : assembly_.pieces())
    if (p.owner >= 0) lowest_ = std::min(lowest_, p.lift);
  step_ = check.step > 0.0 ? check.step : 0.5 * stock.cell();
}

double BodyBand3::lowest(double d2, std::size_t& owner) const {
  double best = kInf;
  const double d = std::sqrt(d2);
  for (const AssemblyPiece& p : assembly_.pieces()) {
    if (p.owner < 0 || d > p.profile.max_radius()) continue;
    const double h = p.lift + p.profile.height(d);
    if (h < best) best = h, owner = static_cast<std::size_t>(p.owner);
  }
  return best;
}

bool BodyBand3::may_deepen(double near2, double top) const {
  const double d = std::sqrt(near2);
  for (const AssemblyPiece& p : assembly_.pieces()) {  // a piece reaching the tile that could go deeper
    if (p.owner < 0 || d > p.profile.max_radius()) continue;
    const double depth = top - (p.lift + p.profile.height(d));  // its lowest over the tile is at the nearest point
    if (depth > 0.0 && depth > worst_.depth(static_cast<std::size_t>(p.owner))) return true;
  }
  return false;
}

void BodyBand3::move(std::size_t k, const double* a, const double* b, std::vector<BodyCollision>& out) {
  // The tiles the move's bodies can reach and whose material may stand above their lowest point.
  const double zlow = std::min(a[2], b[2]) + lowest_, R = reach_, R2 = R * R;
  std::size_t t0, t1, u0, u1;
  if (!tiles_.tiles_in(std::min(a[0], b[0]) - R, std::max(a[0], b[0]) + R, std::min(a[1], b[1]) - R,
                       std::max(a[1], b[1]) + R, t0, t1, u0, u1))
    return;
  candidates_.clear();
  for (std::size_t ty = u0; ty <= u1; ++ty)
    for (std::size_t tx = t0; tx <= t1; ++tx)
      if (tiles_.bound(tx, ty) > zlow) candidates_.push_back(ty * tiles_.tiles_x() + tx);
  if (candidates_.empty()) return;

  ++move_gen_;  // a fresh scratch: every cell reads the stock before the move
  worst_.start(k);
  const double dx = b[0] - a[0], dy = b[1] - a[1], dz = b[2] - a[2];
  const auto poses = static_cast<std::size_t>(std::max(1.0, std::ceil(std::sqrt(dx * dx + dy * dy + dz * dz) / step_)));
  const double Rc = cutter_.max_radius(), Rc2 = Rc * Rc, reach = std::max(R, Rc);
  const double half_diag = z_.cell() * kTile * 0.7072;
  // Tile by tile (a cell's scratch depends only on the stamps on it, so the tiles are independent), each over
  // the poses that come near it, in order.
  for (const std::size_t id : candidates_) {
    const std::size_t tx = id % tiles_.tiles_x(), ty = id / tiles_.tiles_x();
    std::size_t i0, i1, ja, jb;
    tiles_.cells(tx, ty, i0, i1, ja, jb);
    // The poses within reach of the tile's centre grown by its half diagonal: |a + t d - c| <= reach + half_diag.
    const double ex = a[0] - 0.5 * (z_.cx(i0) + z_.cx(i1 - 1)), ey = a[1] - 0.5 * (z_.cy(ja) + z_.cy(jb - 1));
    const double qa = dx * dx + dy * dy, qb = 2.0 * (ex * dx + ey * dy);
    const double qc = ex * ex + ey * ey - (reach + half_diag) * (reach + half_diag);
    double tlo = 0.0, thi = 1.0;
    if (qa > 0.0) {
      const double disc = qb * qb - 4.0 * qa * qc;
      if (disc < 0.0) continue;
      const double sq = std::sqrt(disc);
      tlo = std::max(0.0, (-qb - sq) / (2.0 * qa)), thi = std::min(1.0, (-qb + sq) / (2.0 * qa));
    } else if (qc > 0.0) {
      continue;
    }
    if (tlo > thi) continue;
    // Nothing over the whole move can deepen the report here (a tile is only stamped to be tested): skip it.
    const double seg_d = std::max(0.0, std::sqrt(std::max(0.0, seg_dist2(ex, ey, dx, dy))) - half_diag);
    if (!may_deepen(seg_d * seg_d, tiles_.bound(tx, ty) - std::min(a[2], b[2]))) continue;
    const double n = static_cast<double>(poses);
    const auto first = static_cast<std::size_t>(std::max(0.0, std::floor(tlo * n) - 1.0));
    const auto last = static_cast<std::size_t>(std::min(n, std::ceil(thi * n) + 1.0));
    double& bound = tiles_.bound(tx, ty);
    for (std::size_t i = first; i <= last; ++i) {
      const double t = static_cast<double>(i) / n;
      const double px = a[0] + t * dx, py = a[1] + t * dy, pz = a[2] + t * dz;
      const double near2 = tiles_.dist2(tx, ty, px, py);
      if (near2 > R2 && near2 > Rc2) continue;
      const double cut_top = pz + check_.flute_top, body_low = pz + lowest_;
      const bool test = near2 <= R2 && bound > body_low && may_deepen(near2, bound - pz);
      const bool stamp = near2 <= Rc2;
      if (!test && !stamp) continue;
      double top = -kInf;
      for (std::size_t j = ja; j < jb; ++j) {
        const double ddy = z_.cy(j) - py;
        for (std::size_t ii = i0; ii < i1; ++ii) {
          const std::size_t c = j * z_.nx() + ii;
          const double ddx = z_.cx(ii) - px, d2 = ddx * ddx + ddy * ddy;
          double zc = read(c);
          if (stamp && d2 <= Rc2 && zc <= cut_top) {  // the flutes reach the material's top: they cut it
            const double zh = pz + cutter_.height(std::sqrt(d2));
            if (zh < zc) write(c, zh), zc = zh;
          }
          top = std::max(top, zc);
          if (!test || d2 > R2 || zc <= body_low) continue;
          std::size_t owner = 0;
          const double zb = pz + lowest(d2, owner);
          if (zc > zb) worst_.offer(owner, z_.cx(ii), z_.cy(j), zc, zc - zb);
        }
      }
      bound = std::min(bound, top + kBoundSlack);  // both bound the heights: keep the tighter
    }
  }
  worst_.finish(check_.tolerance, out);
}

}  // namespace body_detail
}  // namespace tmm
