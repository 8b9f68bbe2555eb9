// The tilted torus tool (seed 001 eqs. 24-27): a pose, and the pseudo-insert frame it tilts about.
// Frames and conventions (world = the surface's frame, mm):
//   tip   the lowest point of the tool on its axis (the CL point), axis a = unit tip -> spindle,
//   centre C = tip + Ri a (centre of the torus' major circle), pseudo-insert centre O1 = C + Ro e
//   (e: unit direction from the axis to P, perpendicular to a), u1 = a x e (pseudo-insert axis),
//   v1 = -e (towards the tool axis), w1 = a. Tilting by beta rotates the tool by -beta about u1 through O1:
//   the side of the tool opposite P goes down, the axis leans away from P.
#pragma once

#include <Eigen/Core>

#include "tmm/cutter/torus_tool.hpp"

namespace tmm {

struct ToolPose {
  Eigen::Vector3d tip = Eigen::Vector3d::Zero();
  Eigen::Vector3d axis = Eigen::Vector3d::UnitZ();
};

// The pseudo-insert through the first contact of the vertical tool whose tip is tip0.
struct PseudoInsert {
  // e: unit horizontal direction from the tool axis towards the first contact P.
  PseudoInsert(const Eigen::Vector3d& tip0, const Eigen::Vector3d& e, const TorusTool& tool);
  // The vertical tool tilted by beta about u1 through O1 (the exact rotation: P stays a contact).
  ToolPose tilted(double beta) const;
  // Local coordinates of a point in the frame {u1, v1, w1 = Z} at O1.
  Eigen::Vector3d local(const Eigen::Vector3d& p) const;

  Eigen::Vector3d tip0, e, u1, v1, O1;
};

}  // namespace tmm
