// The first contact and the first guess of the tilt, by each of seed 001's two methods:
//   VCRF (chapter 4): surface points fire vertical rays at the torus (drop) and circular rays about the
//        pseudo-insert axis (tilt); the first ray to reach the tool gives P, the smallest arc gives beta, Q.
//   DRD  (chapter 3): rays fired down from the tool onto the surface (drop); the surface is rotated about
//        the pseudo-insert axis and the tool dropped again, bisecting on beta until a second contact shows.
#pragma once

#include <Eigen/Core>

#include <cstddef>
#include <utility>
#include <vector>

#include "tmm/cutter/torus_tool.hpp"
#include "tmm/position/objectives.hpp"
#include "tmm/position/options.hpp"
#include "tmm/position/pose.hpp"
#include "tmm/position/surface_samples.hpp"
#include "tmm/surface/bezier.hpp"
#include "tmm/util/constants.hpp"

namespace tmm {

// The tilt guess: beta (+inf: no second contact below the limit) and Q's parameters.
struct TiltGuess {
  double beta = kInf;
  Eigen::Vector2d uvQ = Eigen::Vector2d::Zero();
  // VCRF: (pseudo-angle of the circular ray, sample) of every sample whose ray reaches the tool within
  // twice the tilt limit, earliest first: the candidates of its gouge checks. Empty for DRD.
  std::vector<std::pair<double, std::size_t>> hits;
};

// VCRF drop: vertical rays from the samples to the lower tool surface, the best few refined (zoom, Newton).
DropContact vcrf_drop(const PatchSurface& s, const SurfaceSamples& samples, const TorusTool& tool,
                      const MultipointOptions& options, double x, double y, int* evals);

// VCRF circular ray (seed 4.3): the smallest angle in (0, 2 pi) at which the point with local coordinates
// (su, sv, sw) in the pseudo-insert frame {u1, v1, w1} at O1, turned counter-clockwise in (v1, w1), enters
// the tool (whose axis is the line u = 0, v = Ro). Returned as a pseudo-angle, monotonic in the angle
// (1 - cos on (0, pi], 3 + cos on (pi, 2 pi); +inf: never); pseudo_to_angle() converts it.
double circular_ray(const TorusTool& tool, double su, double sv, double sw);
double pseudo_to_angle(double p);

// VCRF tilt guess: circular rays from the samples around the tool at (x, y) (first contact uvP), the
// earliest zoomed in on.
TiltGuess vcrf_tilt_guess(const PatchSurface& s, const SurfaceSamples& samples, const TorusTool& tool,
                          const MultipointOptions& options, const PseudoInsert& frame, const Eigen::Vector2d& uvP,
                          double x, double y, int* evals);

// DRD drop onto s (any rotated copy of the face): rays fired down from the tool on a zooming (rho, phi) grid,
// the best few polished by Newton. separation: the distance that keeps coarse candidates apart.
DropContact drd_drop(const PatchSurface& s, const TorusTool& tool, const MultipointOptions& options,
                     double separation, double x, double y, int* evals);

// DRD tilt guess: the face rotated about the pseudo-insert axis by beta and the tool dropped again; the
// smallest beta at which it sits higher than drop_z (a second contact) by bisection.
TiltGuess drd_tilt_guess(const PatchSurface& s, const TorusTool& tool, const MultipointOptions& options,
                         double separation, const PseudoInsert& frame, const Eigen::Vector2d& uvP, double drop_z,
                         double x, double y, int* evals);

}  // namespace tmm
