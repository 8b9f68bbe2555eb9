// DRD (seed 001 chapter 3): rays fired down from the tool onto the surface, and the surface rotated about
// the pseudo-insert axis to find the tilt.
#include <Eigen/Geometry>

#include <algorithm>
#include <cmath>
#include <optional>

#include "tmm/position/candidates.hpp"
#include "tmm/position/tilt_guess.hpp"
#include "tmm/util/bracket_1d.hpp"
#include "tmm/util/minimize_box.hpp"

namespace tmm {

using Eigen::Matrix3d;
using Eigen::Vector2d;
using Eigen::Vector3d;

DropContact drd_drop(const PatchSurface& s, const TorusTool& tool, const MultipointOptions& options,
                     double separation, double x, double y, int* evals) {
  // Rays fired down from the tool's lower surface (seed figure 3.6), on a (rho, phi) grid that zooms in on
  // the shortest ray; the tool starts above the face's bounding box.
  const double Rt = tool.radius();
  const double z_ref = s.bounds().hi.z() + 1.0;
  const double rho_lo = tool.shape == ToolShape::RoundInsert ? std::max(0.0, tool.Ro - tool.Ri) : 0.0;
  double r0 = rho_lo, r1 = Rt, p0 = 0.0, p1 = 2.0 * kPi;
  const int n = options.drd_divisions;
  double best = kInf;  // shortest ray
  double best_r = 0.0, best_p = 0.0;
  Vector2d best_uv = 0.5 * (s.lo() + s.hi());
  Vector2d guess = best_uv;
  bool have_guess = false;
  const Vector3d down(0.0, 0.0, -1.0);
  // The best few coarse rays, apart, are polished too (a far local maximum).
  SpreadLowest<Vector2d, 3> coarse(std::pow(separation, 2));
  for (int level = 0; level < options.drd_refinements; ++level) {
    for (int a = 0; a <= n; ++a) {
      const double rho = std::clamp(r0 + (r1 - r0) * a / n, rho_lo, Rt);
      const double hz = tool.profile(rho);
      for (int b = 0; b <= n; ++b) {
        const double phi = p0 + (p1 - p0) * b / n;
        const Vector3d o(x + rho * std::cos(phi), y + rho * std::sin(phi), z_ref + hz);
        std::optional<RayHit> hit;
        if (have_guess) hit = s.ray_hit_newton(o, down, guess);
        if (!hit) hit = s.ray_hit(o, down);
        if (evals) *evals += 4;
        if (!hit) continue;
        guess = hit->uv;
        have_guess = true;
        if (level == 0) coarse.offer(hit->s, hit->uv, o + hit->s * down);
        if (hit->s < best) {
          best = hit->s;
          best_r = rho;
          best_p = phi;
          best_uv = hit->uv;
        }
      }
    }
    const double dr = (r1 - r0) / n, dp = (p1 - p0) / n;
    r0 = std::max(rho_lo, best_r - dr);
    r1 = std::min(Rt, best_r + dr);
    p0 = best_p - dp;
    p1 = best_p + dp;
  }
  DropContact d;
  if (!std::isfinite(best)) return d;
  // Newton polish of the contact (the seed stops at the grid's resolution), from the zoomed ray and from
  // the other coarse candidates.
  d.ok = true;
  d.tip_z = z_ref - best;
  d.uv = best_uv;
  auto polish = [&](Vector2d uv) {  // every candidate is a true contact height: the highest wins
    const LocalModel L = minimize_box([&](const Vector2d& p) { return drop_objective(s, tool, x, y, p); }, uv,
                                      s.lo(), s.hi(), 50, evals);
    if (std::isfinite(L.f) && -L.f > d.tip_z) {
      d.tip_z = -L.f;
      d.uv = uv;
    }
  };
  polish(best_uv);
  for (const auto& c : coarse) polish(c.item);
  return d;
}

TiltGuess drd_tilt_guess(const PatchSurface& s, const TorusTool& tool, const MultipointOptions& options,
                         double separation, const PseudoInsert& frame, const Vector2d& uvP, double drop_z,
                         double x, double y, int* evals) {
  // Drop, rotate the surface about the pseudo-insert axis, drop again; bisect on beta (seed figure 3.5).
  TiltGuess g;
  g.uvQ = uvP;
  // A second contact at tilt beta: the tool dropped onto the face turned by beta sits higher.
  auto gouges = [&](double beta, Vector2d* contact) {
    const Matrix3d R = Eigen::AngleAxisd(beta, frame.u1).toRotationMatrix();
    const PatchSurface rotated = s.transformed(R, frame.O1 - R * frame.O1);
    const DropContact d2 = drd_drop(rotated, tool, options, separation, x, y, evals);
    if (d2.ok) *contact = d2.uv;
    return d2.ok && d2.tip_z > drop_z + 1e-7;
  };
  Vector2d c;
  if (!gouges(options.beta_max, &c)) return g;
  g.uvQ = c;
  g.beta = bisect(0.0, options.beta_max, options.drd_bisections, [&](double beta) {
             if (!gouges(beta, &c)) return true;
             g.uvQ = c;
             return false;
           }).bad;
  return g;
}

}  // namespace tmm
