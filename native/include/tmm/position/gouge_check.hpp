// The gouge check of a tool pose: how deep the surface enters the tool.
#pragma once

#include <Eigen/Core>

#include "tmm/cutter/torus_tool.hpp"
#include "tmm/position/pose.hpp"
#include "tmm/position/surface_samples.hpp"
#include "tmm/surface/bezier.hpp"

namespace tmm {

// Signed clearance of surface s from the tool at `pose`: the smallest signed distance from the surface to
// the tool solid (negative: the surface is inside the tool by that much). The samples under the tool
// scanned, every discrete local minimum of the tool distance among them within Ri of the tool (in its
// patch's grid, and along the face's boundary) polished by Newton (the lowest 16 at most); `where` (if
// given) receives its parameters. With no minimum within Ri: the smallest sampled distance (a tool
// standing clear by more than Ri), +inf where no sample lies under the tool.
double clearance(const PatchSurface& s, const SurfaceSamples& samples, const TorusTool& tool,
                 const ToolPose& pose, Eigen::Vector2d* where, int* evals);

// Deepest penetration (>= 0) of surface s into the tool at `pose`: max(0, -clearance).
double penetration(const PatchSurface& s, const SurfaceSamples& samples, const TorusTool& tool,
                   const ToolPose& pose, Eigen::Vector2d* where, int* evals);

}  // namespace tmm
