// The two functions of the surface parameters (U, V) that multipoint positioning minimises by Newton
// (util/minimize_box.hpp), with their derivatives.
#pragma once

#include <Eigen/Core>

#include "tmm/cutter/torus_tool.hpp"
#include "tmm/position/pose.hpp"
#include "tmm/surface/bezier.hpp"
#include "tmm/util/minimize_box.hpp"

namespace tmm {

// The first contact of the vertical tool at (x, y): its tip height and the contact's parameters.
struct DropContact {
  bool ok = false;
  double tip_z = 0.0;
  Eigen::Vector2d uv = Eigen::Vector2d::Zero();
};

// -(tip height of the vertical tool at (x, y) touching S(U, V)): f = -(S_z - h(rho)), rho = |S_xy - (x, y)|
// (+inf beyond the tool's radius).
LocalModel drop_objective(const PatchSurface& s, const TorusTool& tool, double x, double y,
                          const Eigen::Vector2d& uv);

// Tool distance of S(U, V) for the tool at `pose`.
LocalModel distance_objective(const PatchSurface& s, const TorusTool& tool, const ToolPose& pose,
                              const Eigen::Vector2d& uv);

}  // namespace tmm
