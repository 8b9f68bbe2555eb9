// Multipoint positioning of a toroidal cutter on a Bezier/B-spline face (seed 001, Singh 2020):
// drop the tool vertically to a first contact P, then tilt it about the axis of the pseudo-insert through P
// (the minor circle of the torus, centre O1) until it touches the surface at a second point Q.
// Rotating a circle about its own axis maps it onto itself, so P stays a tangent contact while tilting.
//
// Two ways to find the tilt, both from seed 001:
//   VCRF (chapter 4): surface points fire vertical rays at the torus (drop) and circular rays about the
//        pseudo-insert axis (tilt); the first ray to reach the tool gives P, the smallest arc gives beta, Q.
//   DRD  (chapter 3): rays fired down from the tool onto the surface (drop); the surface is rotated about
//        the pseudo-insert axis and the tool dropped again, bisecting on beta until a second contact shows.
// Both end with the same Newton refinement of (beta, Q) (contacts within 1e-9 mm where it converges), and
// every position is checked for penetration (> tol -> Failed): samples of the surface under the tool, the
// lowest few polished by Newton (DRD: a scan of the samples; VCRF: the samples whose circular rays arrive
// first - a sample is inside the tool tilted by beta exactly when its ray arrives before beta - and a local
// search beside P). Where Q runs into P (the surface's curvature at P limits the tilt: sphere-like or
// convex regions), the tilt stops where the tool osculates the surface at P: one contact.
// Deviations from the seed, on purpose: the exact rotation about the pseudo-insert axis (the seed's
// pseudo-code turns the axis about global X: kept as an option to measure it); contacts refined by Newton
// beyond the seed's grids; DRD bisects a fixed number of times (the seed repeats until Q stays the same
// 10 times); a tilt limit with no second contact tilts to the limit (as the seed's bisection does).
//
// Pieces: cutter/torus_tool (the tool solid), position/pose (the pseudo-insert frame and the tilt),
// position/surface_samples, position/tilt_guess (VCRF and DRD drops and tilt guesses), position/tilt_search
// (refinement, curvature limit, gouge checks), position/gouge_check.
#pragma once

#include <Eigen/Core>

#include <cstddef>
#include <memory>

#include "tmm/cutter/torus_tool.hpp"
#include "tmm/position/multipoint_result.hpp"
#include "tmm/position/objectives.hpp"
#include "tmm/position/options.hpp"
#include "tmm/position/surface_samples.hpp"
#include "tmm/surface/bezier.hpp"
#include "tmm/util/parallel.hpp"  // Cancelled, BatchOptions

namespace tmm {

struct ToolPose;      // position/pose.hpp
struct PseudoInsert;  // position/pose.hpp
struct TiltOutcome;   // position/tilt_search.hpp

class MultipointPositioner {
 public:
  // Throws std::invalid_argument naming the first invalid tool radius or option (NaN and infinities
  // included; a sample_spacing finer than the face can be sampled at, with the finest it can).
  // progress(fraction) is called now and then from the calling thread while the surface samples are built
  // (a second for a fine spacing); false cancels: throws Cancelled.
  MultipointPositioner(std::shared_ptr<const PatchSurface> surface, TorusTool tool, MultipointOptions options,
                       const std::function<bool(double)>& progress = {});

  // Position the tool at footprint point (x, y): Axis anchor, the tool whose axis before tilting is the
  // vertical through (x, y); Tip anchor, the tool whose tilted tip lies at (x, y) (see FootprintAnchor).
  MultipointResult position(double x, double y) const;
  // The Axis anchor's position, whatever the option.
  MultipointResult position_axis(double x, double y) const;
  // Many points (x0, y0, x1, y1, ...), threads, progress/cancel (throws Cancelled).
  void position_batch(const double* xy, std::size_t n, MultipointResult* out, const BatchOptions& batch) const;

  // The surface positioned against (the extended face when extend > 0) and the real face.
  const PatchSurface& surface() const { return *surface_; }
  const PatchSurface& real_surface() const { return *real_; }
  const TorusTool& tool() const { return tool_; }
  const MultipointOptions& options() const { return opt_; }
  const SurfaceSamples& samples() const { return samples_; }

  // Pieces, public for tests and for the DRD/VCRF comparison.
  using Drop = DropContact;
  Drop drop_vcrf(double x, double y, int* evals) const;
  Drop drop_drd(const PatchSurface& s, double x, double y, int* evals) const;
  // Deepest penetration (>= 0) of the surface into the tool placed at (tip, axis), by the samples and a
  // Newton polish of the lowest ones; `where` receives its parameters.
  double penetration(const Vector3d& tip, const Vector3d& axis, Vector2d* where, int* evals) const;
  // The same against the real face (differs from penetration() only when extend > 0).
  double penetration_real(const Vector3d& tip, const Vector3d& axis, Vector2d* where, int* evals) const;
  // Signed clearance of the real face from the tool at (tip, axis) (gouge_check.hpp): negative inside,
  // positive the gap the tool leaves; what the moves between positions are checked by.
  double clearance_real(const Vector3d& tip, const Vector3d& axis, Vector2d* where, int* evals) const;

 private:
  MultipointResult position_core(double x, double y) const;
  // The endings of position_core: one contact at P (known_penetration >= 0: what the search's check found at
  // the pose), or two (the search's pose, turned about global X instead for the seed's rotation); each
  // checks the pose and fills res.
  MultipointResult finish_single(MultipointResult& res, ContactReason reason, const ToolPose& pose, double beta,
                                 double known_penetration, int& evals) const;
  MultipointResult finish_two(MultipointResult& res, const TiltOutcome& t, const PseudoInsert& frame,
                              const Vector3d& tip0, int& evals) const;
  TorusTool tool_;
  MultipointOptions opt_;
  std::shared_ptr<const PatchSurface> real_;
  std::shared_ptr<const PatchSurface> surface_;
  SurfaceSamples samples_;
  std::unique_ptr<const SurfaceSamples> real_samples_;  // extend > 0 only
};

}  // namespace tmm
