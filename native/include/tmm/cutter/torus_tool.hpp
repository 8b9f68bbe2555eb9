// The toroidal cutter of multipoint positioning (seed 001) as a solid: what must not enter the surface.
//   RoundInsert  the seed's torus (eq. 20): the full lower half of the torus (inner and outer), a body
//                above the centre plane out to Ro + Ri, and an open hollow for rho < Ro - Ri below it
//                (round-insert cutters; seed 3.3.1 "a tool with a small hollow in the bottom plane").
//   BullNose     a solid end mill: flat bottom for rho <= Ro, outer quarter torus, cylinder above.
// Ro = 0 is a ball; Ri = 0 (flat end mill) is refused by validate(): a point insert has no pseudo-insert circle
// to roll on. As a solid (the 5-axis simulation, validate_solid()) the bull-nose with Ri = 0 is the flat end mill
// exactly: the flat bottom out to Ro, the cylinder above, the torus shrunk to the rim circle.
// Placed by its tip (the lowest point on its axis) and its unit axis (tip -> spindle).
#pragma once

#include <Eigen/Core>

namespace tmm {

enum class ToolShape { RoundInsert = 0, BullNose = 1 };

struct TorusTool {
  double Ro = 0.0;  // major radius (centre of the pseudo-insert to the axis)
  double Ri = 0.0;  // minor radius (pseudo-insert)
  ToolShape shape = ToolShape::RoundInsert;
  // Throws std::invalid_argument for Ro < 0, Ri <= 0 (flat end mill refused) or non-finite radii.
  void validate() const;
  // The same for the tool as a solid: also takes the flat end mill (BullNose, Ro > 0, Ri = 0).
  void validate_solid() const;
  double radius() const { return Ro + Ri; }
  // Height of the lower cutting surface above the tip at distance rho from the axis (rho <= Ro + Ri).
  double profile(double rho) const;
};

// Signed distance from x to the tool solid (negative inside), its gradient (unit outward normal of the
// nearest tool point) and, if hess != nullptr, its Hessian (zero on flat pieces).
double tool_distance(const TorusTool& tool, const Eigen::Vector3d& tip, const Eigen::Vector3d& axis,
                     const Eigen::Vector3d& x, Eigen::Vector3d* grad = nullptr, Eigen::Matrix3d* hess = nullptr);

}  // namespace tmm
