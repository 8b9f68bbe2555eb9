// From the tilt guess to the final tilt (seed 001, refined): Newton on beta for the second contact Q, the
// gouge check of every tilt, and the stop where Q runs into P (the surface's curvature at P limits the
// tilt: sphere-like or convex regions; the tool then osculates the surface at P, one contact).
#pragma once

#include <Eigen/Core>

#include <cstddef>
#include <utility>
#include <vector>

#include "tmm/cutter/torus_tool.hpp"
#include "tmm/position/multipoint_result.hpp"
#include "tmm/position/options.hpp"
#include "tmm/position/pose.hpp"
#include "tmm/position/surface_samples.hpp"
#include "tmm/position/tilt_guess.hpp"
#include "tmm/surface/bezier.hpp"

namespace tmm {

// The tilt found. two: the pose touches at P and at Q (uvQ), `penetration` checked; else one contact at P
// for `reason`, penetration known if >= 0 (else still to check).
struct TiltOutcome {
  bool two = false;
  ContactReason reason = ContactReason::Ok;
  double beta = 0.0;
  ToolPose pose;
  Eigen::Vector2d uvQ = Eigen::Vector2d::Zero();
  double penetration = -1.0;
};

class TiltSearch {
 public:
  // The tool touching s at P = S(uvP) when vertical, about to tilt in `frame`. guess.hits: VCRF's gouge
  // candidates (empty for DRD, whose checks scan the samples). Counts surface evaluations in *evals; the
  // referenced objects must outlive the search.
  TiltSearch(const PatchSurface& s, const SurfaceSamples& samples, const TorusTool& tool,
             const MultipointOptions& options, const PseudoInsert& frame, const Eigen::Vector2d& uvP,
             const Eigen::Vector3d& P, const TiltGuess& guess, int* evals);

  // From the guess (beta0 <= beta_max, Q at uvQ).
  TiltOutcome run(double beta0, Eigen::Vector2d uvQ);

  // Pieces, public for tests.
  // Newton on beta (safeguarded by a bracket [0, hi]) for the tilt where the tool distance, minimised over
  // Q's neighbourhood, is 0; false if it does not converge. Also true when Q slides into P.
  bool refine(double& beta, Eigen::Vector2d& uv, double hi) const;
  // Depth (<= 0) of the deepest local minimum of the tool distance beside P at tilt beta.
  double local_depth(double beta);
  // Penetration (>= 0) of the tool tilted by beta; where: its parameters.
  double check(double beta, Eigen::Vector2d* where);
  // The tilt where the tool starts to cut in around P (the curvature limit), at most b.
  double curvature_limit(double b);

 private:
  // uv is P: within near_ of it and joined to it, at tilt beta, without a ridge of the tool distance.
  bool near_P(const Eigen::Vector2d& uv, double beta) const;
  TiltOutcome safe_tilt(double b, ContactReason why);
  TiltOutcome single(ContactReason why, double beta, double known_penetration = -1.0) const;

  const PatchSurface& s_;
  const SurfaceSamples& samples_;
  const TorusTool& tool_;
  const MultipointOptions& opt_;
  const PseudoInsert& frame_;
  Eigen::Vector2d uvP_;
  Eigen::Vector3d P_;
  const std::vector<std::pair<double, std::size_t>>& hits_;
  std::vector<std::size_t> chosen_;  // VCRF: the hits polished by each check, kept apart
  bool scan_;                        // DRD: checks scan the samples
  int* evals_;
  double near_;     // a contact closer than this to P (and not parted from it by a ridge) is P
  double allowed_;  // osculation, not a tolerated gouge
  // Newton starts of the local search beside P, one on each side along u1: where the last gouge was found
  // (the minimum moves little with beta). Once a side has gouged, only that side is searched.
  Eigen::Vector2d start_[2];
  int gouge_side_ = -1;
};

}  // namespace tmm
