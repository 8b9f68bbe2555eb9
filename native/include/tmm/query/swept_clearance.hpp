// A certificate that a triangle cannot touch a convex cutter solid before a given travel, far cheaper than
// the contact itself (docs/drop_direction.md, "Clearance certificate"). Used by the drop along a direction to
// reject the many candidate triangles that lie near a solid's reach but are not touched before the best
// contact so far: a tool body's wide solid, above all, meets them by the hundred per start.
#pragma once

#include <Eigen/Core>

#include "tmm/cutter/cutter.hpp"

namespace tmm::direction_detail {

// In the tool frame of drop_direction (K = {h(rho) <= z <= L_C} with its tip at the origin, moving along W):
// true when a plane is found that separates the triangle q0 q1 q2 from K swept over the travels [t0, cap],
// by more than 1e-9 mm, so that the triangle's first contact is later than cap. t0 must be a lower bound of
// that contact (e.g. min q . W - max_K X . W). Searched by GJK on the Minkowski difference (a few support
// points of K), from `plane` where it is given and not zero (e.g. the plane that cleared the triangle from a
// nearby start), else from W; false when it is not found in 20 steps (touching, too close or degenerate),
// and always for an unbounded K or sweep: the caller then solves the contact. Every true answer is checked on
// the separating plane itself, so it never depends on the search converging. `plane` (or null): set to that
// plane's normal when the answer is true.
bool triangle_clear(const Cutter& c, const Eigen::Vector3d& q0, const Eigen::Vector3d& q1,
                    const Eigen::Vector3d& q2, const Eigen::Vector3d& W, double t0, double cap,
                    Eigen::Vector3d* plane = nullptr);
// The same proof on one given plane normal v (e.g. the one that cleared the same triangle from a nearby
// start): one support point of K; false when v is zero or does not separate by more than 1e-9 mm.
bool plane_clears(const Cutter& c, const Eigen::Vector3d& q0, const Eigen::Vector3d& q1,
                  const Eigen::Vector3d& q2, const Eigen::Vector3d& W, double t0, double cap,
                  const Eigen::Vector3d& v);

}  // namespace tmm::direction_detail
