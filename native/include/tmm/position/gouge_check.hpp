// The gouge check of a tool pose: how deep the surface enters the tool.
#pragma once

#include <Eigen/Core>

#include "tmm/cutter/torus_tool.hpp"
#include "tmm/position/pose.hpp"
#include "tmm/position/surface_samples.hpp"
#include "tmm/surface/bezier.hpp"

namespace tmm {

// Deepest penetration (>= 0) of surface s into the tool at `pose`: the samples under the tool scanned,
// every discrete local minimum of the tool distance among them (in its patch's grid, and along the face's
// boundary) polished by Newton (the lowest 16 at most); `where` (if given) receives its parameters.
double penetration(const PatchSurface& s, const SurfaceSamples& samples, const TorusTool& tool,
                   const ToolPose& pose, Eigen::Vector2d* where, int* evals);

}  // namespace tmm
