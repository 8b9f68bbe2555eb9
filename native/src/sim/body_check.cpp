// The body check's shared parts and its 5-axis pose test (the model: tmm/sim/body_check.hpp).
#include "body_check_band.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <sstream>
#include <stdexcept>

namespace tmm {

namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();

[[noreturn]] void refuse(const char* what, double v, const char* range) {
  std::ostringstream msg;
  msg << "body check: " << what << " must be " << range << ", got " << v;
  throw std::invalid_argument(msg.str());
}

// A body grown by its clearance, enclosed by up to three frusta (tmm/sim/body_check.hpp): below the body,
// the body widened, above it.
struct Enclosure {
  double h0, h1, rad0, rad1;
};

std::vector<Enclosure> enclosures(const ToolBody& b) {
  const double c = b.clearance, k = (b.r1 - b.r0) / (b.z1 - b.z0), g = c * (1.0 + std::fabs(k));
  std::vector<Enclosure> out{{b.z0, b.z1, b.r0 + g, b.r1 + g}};
  if (c > 0.0) {
    out.push_back({b.z0 - c, b.z0, b.r0 + g, b.r0 + g});
    out.push_back({b.z1, b.z1 + c, b.r1 + g, b.r1 + g});
  }
  return out;
}

}  // namespace

void validate(const BodyCheck& check) {
  if (!(std::isfinite(check.flute_top) && check.flute_top >= 0.0)) refuse("flute_top", check.flute_top, "finite and >= 0 mm");
  if (!(std::isfinite(check.tolerance) && check.tolerance >= 0.0)) refuse("tolerance", check.tolerance, "finite and >= 0 mm");
  if (!(std::isfinite(check.step) && check.step >= 0.0)) refuse("step", check.step, "finite and >= 0 mm (0: half a cell)");
  if (check.bodies.empty()) throw std::invalid_argument("body check: no bodies to check");
  ToolAssembly(Cutter(1.0, 0.0), check.bodies);  // the bodies' own rules, refused by name
}

std::vector<BodyCollision> merge_body_collisions(std::vector<BodyCollision> all) {
  std::sort(all.begin(), all.end(), [](const BodyCollision& a, const BodyCollision& b) {
    if (a.move != b.move) return a.move < b.move;
    if (a.piece != b.piece) return a.piece < b.piece;
    if (a.depth != b.depth) return a.depth > b.depth;
    return a.y < b.y || (a.y == b.y && a.x < b.x);  // equal depths in two bands: the same one for any split
  });
  std::vector<BodyCollision> out;
  for (const BodyCollision& c : all)
    if (out.empty() || out.back().move != c.move || out.back().piece != c.piece) out.push_back(c);
  return out;
}

// On the line, w = z - tip_z: the axial height h(w) = qa + a_z w and the squared distance from the axis
// rho^2(w) = qq - qa^2 + (1 - a_z^2) w^2 - 2 qa a_z w. rho is convex in w (the norm of an affine map) and the
// radius u + v w linear, so {rho <= radius} is an interval; with h in [h0, h1] its lowest point is the lower
// end of the h range or the smaller root of rho^2 = (u + v w)^2 with u + v w >= 0.
double frustum_lowest(const Eigen::Vector3d& tip, const Eigen::Vector3d& a, double h0, double h1, double rad0,
                      double rad1, double x, double y) {
  const double dx = x - tip.x(), dy = y - tip.y(), az = a.z();
  const double qa = dx * a.x() + dy * a.y(), qq = dx * dx + dy * dy;
  const double wlo = (h0 - qa) / az, whi = (h1 - qa) / az;
  const double k = (rad1 - rad0) / (h1 - h0);
  const double u = rad0 + k * (qa - h0), v = k * az;  // radius at w: u + v w
  const double A = (1.0 - az * az) - v * v, B = -2.0 * (qa * az + u * v), C = qq - qa * qa - u * u;
  auto f = [&](double w) { return (A * w + B) * w + C; };
  constexpr double kSlack = 1e-9;  // mm: rounding in the closed form counts as inside (conservative)
  if (u + v * wlo >= -kSlack && f(wlo) <= kSlack * std::max(1.0, std::fabs(C))) return tip.z() + wlo;
  double roots[2];
  int n = 0;
  if (std::fabs(A) < 1e-14) {
    if (B != 0.0) roots[n++] = -C / B;
  } else {
    const double disc = B * B - 4.0 * A * C;
    if (disc < 0.0) return kInf;
    const double s = std::sqrt(disc), q = -0.5 * (B + std::copysign(s, B));
    roots[n++] = q / A;
    if (q != 0.0) roots[n++] = C / q;
  }
  double best = kInf;
  for (int i = 0; i < n; ++i) {
    const double w = roots[i];
    if (w >= wlo && w <= whi + kSlack && u + v * w >= -kSlack) best = std::min(best, w);
  }
  return best == kInf ? kInf : tip.z() + best - kSlack;
}

namespace body_detail {

TileBounds::TileBounds(const ZMap& stock, std::size_t j0, std::size_t j1)
    : z_(stock), j0_(j0), j1_(j1), tx_((stock.nx() + kTile - 1) / kTile), ty_((j1 - j0 + kTile) / kTile),
      max_(tx_ * ty_, -kInf) {
  const std::size_t nx = stock.nx();
  for (std::size_t j = j0; j <= j1; ++j)
    for (std::size_t i = 0; i < nx; ++i) {
      double& m = bound(i / kTile, (j - j0) / kTile);
      m = std::max(m, stock.at(i, j));
    }
}

void TileBounds::cells(std::size_t tx, std::size_t ty, std::size_t& i0, std::size_t& i1, std::size_t& j0,
                       std::size_t& j1) const {
  i0 = tx * kTile, i1 = std::min(z_.nx(), i0 + kTile);
  j0 = j0_ + ty * kTile, j1 = std::min(j1_ + 1, j0 + kTile);
}

double TileBounds::dist2(std::size_t tx, std::size_t ty, double x, double y) const {
  std::size_t i0, i1, j0, j1;
  cells(tx, ty, i0, i1, j0, j1);
  const double dx = std::max({z_.cx(i0) - x, 0.0, x - z_.cx(i1 - 1)});
  const double dy = std::max({z_.cy(j0) - y, 0.0, y - z_.cy(j1 - 1)});
  return dx * dx + dy * dy;
}

bool TileBounds::tiles_in(double xlo, double xhi, double ylo, double yhi, std::size_t& t0, std::size_t& t1,
                          std::size_t& u0, std::size_t& u1) const {
  const CellRange r = z_.cells_in(xlo, xhi, std::max(ylo, z_.cy(j0_)), std::min(yhi, z_.cy(j1_)));
  if (r.empty() || r.j1 < j0_ || r.j0 > j1_) return false;
  t0 = r.i0 / kTile, t1 = r.i1 / kTile;
  u0 = (std::max(r.j0, j0_) - j0_) / kTile, u1 = (std::min(r.j1, j1_) - j0_) / kTile;
  return true;
}

void MoveWorst::start(std::size_t move) {
  for (std::size_t p = 0; p < worst_.size(); ++p) {
    worst_[p] = BodyCollision{};
    worst_[p].move = move, worst_[p].piece = p, worst_[p].depth = -kInf;
  }
}

void MoveWorst::finish(double tolerance, std::vector<BodyCollision>& out) const {
  for (const BodyCollision& w : worst_)
    if (w.depth > tolerance) out.push_back(w);
}

BodyBand5::BodyBand5(ZMap& stock, const BodyCheck& check, std::size_t j0, std::size_t j1)
    : z_(stock), check_(check), tiles_(stock, j0, j1), worst_(check.bodies.size()) {}

void BodyBand5::y_range(const BodyCheck& check, const Eigen::Vector3d& tip, const Eigen::Vector3d& axis,
                        double& ylo, double& yhi) {
  for (const ToolBody& b : check.bodies)
    for (const Enclosure& e : enclosures(b))
      for (const auto& [h, rad] : {std::pair{e.h0, e.rad0}, std::pair{e.h1, e.rad1}}) {
        const double y = tip.y() + h * axis.y();
        ylo = std::min(ylo, y - rad), yhi = std::max(yhi, y + rad);
      }
}

void BodyBand5::pose(const Eigen::Vector3d& tip, const Eigen::Vector3d& axis) {
  const double sin_b = std::sqrt(std::max(0.0, 1.0 - axis.z() * axis.z()));
  for (std::size_t p = 0; p < check_.bodies.size(); ++p) {
    const std::vector<Enclosure> parts = enclosures(check_.bodies[p]);
    // The XY box and the lowest point of the enclosing frusta (their rims: a disc tilted by b drops rad sin b).
    double xlo = kInf, xhi = -kInf, ylo = kInf, yhi = -kInf, zlow = kInf;
    for (const Enclosure& e : parts)
      for (const auto& [h, rad] : {std::pair{e.h0, e.rad0}, std::pair{e.h1, e.rad1}}) {
        const Eigen::Vector3d c = tip + h * axis;
        xlo = std::min(xlo, c.x() - rad), xhi = std::max(xhi, c.x() + rad);
        ylo = std::min(ylo, c.y() - rad), yhi = std::max(yhi, c.y() + rad);
        zlow = std::min(zlow, c.z() - rad * sin_b);
      }
    std::size_t t0, t1, u0, u1;
    if (!tiles_.tiles_in(xlo, xhi, ylo, yhi, t0, t1, u0, u1)) continue;
    for (std::size_t ty = u0; ty <= u1; ++ty)
      for (std::size_t tx = t0; tx <= t1; ++tx) {
        double& bound = tiles_.bound(tx, ty);
        // No cell here reaches deeper than bound - zlow into this body: skip unless that beats its worst.
        if (bound <= zlow || bound - zlow <= worst_.depth(p)) continue;
        std::size_t i0, i1, ja, jb;
        tiles_.cells(tx, ty, i0, i1, ja, jb);
        double top = -kInf;
        for (std::size_t j = ja; j < jb; ++j)
          for (std::size_t i = i0; i < i1; ++i) {
            const double zc = z_.at(i, j);
            top = std::max(top, zc);
            if (zc <= zlow) continue;
            double low = kInf;
            for (const Enclosure& e : parts)
              low = std::min(low, frustum_lowest(tip, axis, e.h0, e.h1, e.rad0, e.rad1, z_.cx(i), z_.cy(j)));
            if (zc - low > 0.0) worst_.offer(p, z_.cx(i), z_.cy(j), zc, zc - low);
          }
        bound = top;
      }
  }
}

}  // namespace body_detail
}  // namespace tmm
