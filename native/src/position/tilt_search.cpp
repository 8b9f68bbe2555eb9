#include "tmm/position/tilt_search.hpp"

#include <Eigen/Dense>

#include <algorithm>
#include <cmath>

#include "tmm/position/candidates.hpp"
#include "tmm/position/gouge_check.hpp"
#include "tmm/position/objectives.hpp"
#include "tmm/util/bracket_1d.hpp"
#include "tmm/util/constants.hpp"
#include "tmm/util/minimize_box.hpp"

namespace tmm {

using Eigen::Vector2d;
using Eigen::Vector3d;

TiltSearch::TiltSearch(const PatchSurface& s, const SurfaceSamples& samples, const TorusTool& tool,
                       const MultipointOptions& options, const PseudoInsert& frame, const Vector2d& uvP,
                       const Vector3d& P, const TiltGuess& guess, int* evals)
    : s_(s),
      samples_(samples),
      tool_(tool),
      opt_(options),
      frame_(frame),
      uvP_(uvP),
      P_(P),
      hits_(guess.hits),
      scan_(options.method == MultipointMethod::DRD),
      evals_(evals),
      near_(std::max(0.1 * tool.Ri, 2.0 * samples.spacing())),
      allowed_(std::min(1e-6, 0.25 * options.tol)) {
  if (!scan_) chosen_ = pick_apart(hits_, samples_.points(), std::pow(2.0 * samples_.spacing(), 2), 6);
  // Where a tilted ring first dips below a curved surface: beside P along the pseudo-insert axis.
  const SurfacePoint sp = s_.eval(uvP_.x(), uvP_.y(), 1);
  Eigen::Matrix<double, 3, 2> J;
  J << sp.Su, sp.Sv;
  Vector2d side = (J.transpose() * J).ldlt().solve(J.transpose() * frame_.u1);
  side *= std::max(0.05 * tool_.Ri, samples_.spacing());
  start_[0] = uvP_ + side;
  start_[1] = uvP_ - side;
}

bool TiltSearch::near_P(const Vector2d& uv, double beta) const {
  if ((s_.point(uv.x(), uv.y()) - P_).norm() >= near_) return false;
  // Close to P, but in a basin of its own? (found on a face: a second contact on the face's edge 2.6 mm from P,
  // inside near_, was taken for P.) Along the parameter segment P -> uv the tool distance at this tilt
  // rises above both ends by more than the osculation allowance: a ridge parts them, uv is not P.
  const ToolPose pose = frame_.tilted(beta);
  const double f = tool_distance(tool_, pose.tip, pose.axis, s_.point(uv.x(), uv.y()));
  const double level = std::max(f, 0.0) + allowed_;
  constexpr int kSteps = 16;
  for (int i = 1; i < kSteps; ++i) {
    const Vector2d w = uvP_ + (uv - uvP_) * (static_cast<double>(i) / kSteps);
    ++*evals_;
    if (tool_distance(tool_, pose.tip, pose.axis, s_.point(w.x(), w.y())) > level) return false;
  }
  return true;
}

bool TiltSearch::refine(double& beta, Vector2d& uv, double hi) const {
  double lo = 0.0;
  for (int it = 0; it < 60; ++it) {
    const ToolPose pose = frame_.tilted(beta);
    const LocalModel L = minimize_box([&](const Vector2d& p) { return distance_objective(s_, tool_, pose, p); },
                                      uv, s_.lo(), s_.hi(), 40, evals_);
    const double m = L.f;
    if (std::abs(m) < 1e-10) return true;
    if (near_P(uv, beta)) return true;  // slid into P: the caller decides
    if (m > 0.0) lo = std::max(lo, beta);
    else hi = std::min(hi, beta);
    Vector3d g;
    const Vector3d X = s_.point(uv.x(), uv.y());
    tool_distance(tool_, pose.tip, pose.axis, X, &g);
    const double dm = g.dot(frame_.u1.cross(X - frame_.O1));  // d(distance)/d(beta): the point turns about u1
    double next = (dm < 0.0) ? beta - m / dm : kInf;
    if (!(next > lo && next < hi)) next = std::isfinite(hi) ? 0.5 * (lo + hi) : std::max(2.0 * beta, beta + 1e-3);
    if (!std::isfinite(hi) && next > 1.5 * opt_.beta_max) return false;
    if (std::isfinite(hi) && hi - lo < 1e-14) return std::abs(m) < 1e-3 * opt_.tol;
    beta = next;
  }
  return false;
}

double TiltSearch::local_depth(double beta) {
  // Newton from the two starts beside P finds a negative minimum if the tool cuts in around P.
  const ToolPose pose = frame_.tilted(beta);
  double depth = 0.0;
  for (int k = 0; k < 2; ++k) {
    if (gouge_side_ >= 0 && k != gouge_side_) continue;
    Vector2d uv = start_[k];
    const LocalModel L = minimize_box([&](const Vector2d& p) { return distance_objective(s_, tool_, pose, p); },
                                      uv, s_.lo(), s_.hi(), 10, evals_);
    if (L.f < depth) depth = L.f;
    if (L.f < -0.5 * allowed_ && (uv - uvP_).norm() > 1e-9) {
      start_[k] = uv;
      gouge_side_ = k;
    }
  }
  return depth;
}

double TiltSearch::check(double beta, Vector2d* where) {
  const ToolPose pose = frame_.tilted(beta);
  // DRD scans the samples (its own, independent check).
  if (scan_) return penetration(s_, samples_, tool_, pose, where, evals_);
  // VCRF: a sample is inside the tool tilted by beta exactly when its circular ray arrives before beta, so
  // the samples nearest to arriving (lowest ray angles, kept apart) are the candidates that Newton polishes.
  const auto& pts = samples_.points();
  double best = kInf;
  for (const std::size_t k : chosen_) {
    Vector2d uv = samples_.params()[k];
    const double d0 = tool_distance(tool_, pose.tip, pose.axis, pts[k]);
    const LocalModel L = minimize_box([&](const Vector2d& p) { return distance_objective(s_, tool_, pose, p); },
                                      uv, s_.lo(), s_.hi(), 30, evals_);
    const double d = std::min(L.f, d0);
    if (d < best) {
      best = d;
      if (where) *where = L.f <= d0 ? uv : samples_.params()[k];
    }
  }
  // Next to P (its own samples were left out: they touch): the local search beside P.
  const double around_P = local_depth(beta);
  if (around_P < best) {
    best = around_P;
    if (where) *where = start_[gouge_side_ >= 0 ? gouge_side_ : 0];
  }
  return std::isfinite(best) ? std::max(0.0, -best) : 0.0;
}

double TiltSearch::curvature_limit(double b) {
  // The tilt where the Hessian of the tool distance over (U, V) at P stops being positive semidefinite (P
  // stays a contact, so the second-order term decides): regula falsi on its smallest eigenvalue.
  auto lowest_eigenvalue = [&](double t) {
    const LocalModel L = distance_objective(s_, tool_, frame_.tilted(t), uvP_);
    ++*evals_;
    const double h0 = L.H(0, 0), h1 = L.H(0, 1), h2 = L.H(1, 1);
    return 0.5 * (h0 + h2) - std::sqrt(0.25 * (h0 - h2) * (h0 - h2) + h1 * h1);
  };
  double a = 0.0;
  const double fa = lowest_eigenvalue(a), fb = lowest_eigenvalue(b);
  if (fa >= 0.0 && fb < 0.0) a = illinois(a, b, fa, fb, 60, 1e-11, lowest_eigenvalue).good;
  else a = b;  // no sign change: the local depth search below decides over [0, b]
  // Third-order terms put the limit a little below the second-order one: regula falsi on the local depth
  // beside P reaching -allowed / 2 (it is 0 below the limit and falls smoothly past it).
  const double target = -0.5 * allowed_;
  const double fu = local_depth(a) - target;
  if (fu < 0.0) a = illinois(0.0, a, -target, fu, 24, 1e-8, [&](double t) { return local_depth(t) - target; }).good;
  return a;
}

TiltOutcome TiltSearch::single(ContactReason why, double beta, double known_penetration) const {
  TiltOutcome o;
  o.reason = why;
  o.beta = beta;
  o.pose = frame_.tilted(beta);
  o.penetration = known_penetration;
  return o;
}

TiltOutcome TiltSearch::safe_tilt(double b, ContactReason why) {
  // Keep what is safe: the largest tilt the full check accepts below b.
  const double a = bisect(0.0, b, 20, [&](double t) {
                     return penetration(s_, samples_, tool_, frame_.tilted(t), nullptr, evals_) <= allowed_;
                   }).good;
  return single(why, a);
}

TiltOutcome TiltSearch::run(const double beta0, Vector2d uvQ) {
  double beta = beta0, hi = kInf;
  for (int attempt = 0; attempt < 6; ++attempt) {
    if (near_P(uvQ, beta)) {
      // The second contact runs into P: tilt until the tool osculates the surface at P. If the full check
      // then finds a contact elsewhere, that one is refined.
      const double a = curvature_limit(std::min({beta, hi, opt_.beta_max}));
      Vector2d where;
      const double pen = check(a, &where);
      if (pen <= allowed_) return single(ContactReason::CurvatureLimit, a, pen);
      if (near_P(where, a)) return safe_tilt(a, ContactReason::CurvatureLimit);
      hi = a;
      beta = a;
      uvQ = where;
      continue;
    }
    if (!refine(beta, uvQ, hi)) return safe_tilt(std::min({beta0, hi, opt_.beta_max}), ContactReason::NotConverged);
    if (near_P(uvQ, beta)) continue;
    if (beta > opt_.beta_max) return single(ContactReason::TiltLimit, opt_.beta_max);
    Vector2d where;
    const double pen = check(beta, &where);
    if (pen <= allowed_) {
      TiltOutcome o = single(ContactReason::Ok, beta, pen);
      o.two = true;
      o.uvQ = uvQ;
      return o;
    }
    // Another point touches first (the guess was a later contact): go on from the deepest point.
    hi = beta;
    uvQ = where;
  }
  return safe_tilt(std::min({beta0, hi, opt_.beta_max}), ContactReason::NotConverged);
}

}  // namespace tmm
