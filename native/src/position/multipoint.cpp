#include "tmm/position/multipoint.hpp"

#include <Eigen/Geometry>

#include <algorithm>
#include <cmath>
#include <sstream>
#include <stdexcept>
#include <utility>

#include "tmm/position/gouge_check.hpp"
#include "tmm/position/pose.hpp"
#include "tmm/position/tilt_guess.hpp"
#include "tmm/position/tilt_search.hpp"
#include "tmm/util/constants.hpp"

namespace tmm {

using Eigen::Matrix3d;

const std::vector<std::string>& multipoint_reason_text() {
  static const std::vector<std::string> text = {
      "two contacts",
      "no surface under the tool",
      "ball end mill (Ro = 0): tilting about the centre does not move the tool",
      "first contact on the flat bottom: tilting about the pseudo-insert would gouge, axis kept vertical",
      "first contact under the hollow centre of the round-insert tool: no pseudo-insert, axis kept vertical",
      "no second contact up to the tilt limit: tilted to the limit, one contact",
      "second contact coincides with the first: the surface curvature at P limits the tilt (convex or flat "
      "region), one contact",
      "refinement of the second contact did not converge",
      "gouge: the final check found the surface inside the tool beyond tolerance",
      "seed's rotation about global X: approximate tilt, contacts not kept",
  };
  return text;
}

namespace {

std::shared_ptr<const PatchSurface> extended_or_same(const std::shared_ptr<const PatchSurface>& s, double d) {
  if (!s) throw std::invalid_argument("no surface");
  if (d == 0.0) return s;
  return std::make_shared<const PatchSurface>(s->extended(d));
}

// The XY bucket size of the samples: half the tool's diameter.
double bucket_size(const TorusTool& tool) { return std::max((tool.Ro + tool.Ri) * 0.5, 1e-3); }

const MultipointOptions& checked(const MultipointOptions& options, const TorusTool& tool) {
  validate(options, tool);
  return options;
}

// The sample spacing for the face: the option, if the face can be sampled that finely (else refused), or
// (Ro + Ri) / 8, widened if the face needs too many samples.
double checked_spacing(const PatchSurface& s, const MultipointOptions& options, const TorusTool& tool) {
  const double spacing = sample_spacing_for(options, tool);
  if (options.sample_spacing == 0.0) return spacing;
  bool capped = false;
  if (SurfaceSamples::planned_spacing(s, spacing, &capped) == spacing && !capped) return spacing;
  std::ostringstream msg;
  msg << "sample_spacing " << spacing << " mm is finer than this face can be sampled at (at most "
      << SurfaceSamples::kMaxSamples << " samples, " << SurfaceSamples::kMaxSide
      << " per patch side): it must be 0 (auto: (Ro + Ri) / 8 = " << (tool.Ro + tool.Ri) / 8.0
      << " mm) or >= " << SurfaceSamples::finest_spacing(s, spacing) << " mm";
  throw std::invalid_argument(msg.str());
}

}  // namespace

// The samples are most of the construction: with an extended face, two sets of about the same size.
MultipointPositioner::MultipointPositioner(std::shared_ptr<const PatchSurface> surface, TorusTool tool,
                                           MultipointOptions options, const std::function<bool(double)>& progress)
    : tool_(tool),
      opt_(checked(options, tool_)),
      real_(std::move(surface)),
      surface_(extended_or_same(real_, opt_.extend)),
      samples_(*surface_, checked_spacing(*surface_, opt_, tool_), bucket_size(tool_),
               progress_phase(progress, 0.0, opt_.extend > 0.0 ? 0.5 : 1.0)) {
  if (opt_.extend > 0.0)
    real_samples_ = std::make_unique<const SurfaceSamples>(*real_, samples_.spacing(), bucket_size(tool_),
                                                           progress_phase(progress, 0.5, 1.0));
}

MultipointPositioner::Drop MultipointPositioner::drop_vcrf(double x, double y, int* evals) const {
  return vcrf_drop(*surface_, samples_, tool_, opt_, x, y, evals);
}

MultipointPositioner::Drop MultipointPositioner::drop_drd(const PatchSurface& s, double x, double y,
                                                          int* evals) const {
  return drd_drop(s, tool_, opt_, 2.0 * samples_.spacing(), x, y, evals);
}

double MultipointPositioner::penetration(const Vector3d& tip, const Vector3d& axis, Vector2d* where,
                                         int* evals) const {
  return tmm::penetration(*surface_, samples_, tool_, {tip, axis}, where, evals);
}

double MultipointPositioner::penetration_real(const Vector3d& tip, const Vector3d& axis, Vector2d* where,
                                              int* evals) const {
  if (!real_samples_) return penetration(tip, axis, where, evals);
  return tmm::penetration(*real_, *real_samples_, tool_, {tip, axis}, where, evals);
}

double MultipointPositioner::clearance_real(const Vector3d& tip, const Vector3d& axis, Vector2d* where,
                                            int* evals) const {
  return tmm::clearance(*real_, real_samples_ ? *real_samples_ : samples_, tool_, {tip, axis}, where, evals);
}

MultipointResult MultipointPositioner::finish_single(MultipointResult& res, ContactReason reason,
                                                     const ToolPose& pose, double beta, double known_penetration,
                                                     int& evals) const {
  const bool drd = opt_.method == MultipointMethod::DRD;
  res.status = ContactStatus::OneContact;
  res.reason = reason;
  res.tip = pose.tip;
  res.axis = pose.axis;
  res.beta = beta;
  res.centre = pose.tip + tool_.Ri * pose.axis;
  res.Q = res.P;
  res.nQ = res.nP;
  res.uvQ = res.uvP;
  res.gap_P = res.gap_Q = tool_distance(tool_, pose.tip, pose.axis, res.P);
  // The full check, unless the search ran it (DRD): VCRF's own check is partial (its earliest circular
  // rays and beside P), its finding is kept if deeper.
  res.penetration = (drd && known_penetration >= 0.0)
                        ? known_penetration
                        : std::max(known_penetration, penetration(pose.tip, pose.axis, nullptr, &evals));
  if (res.penetration > opt_.tol) {
    res.status = ContactStatus::Failed;
    res.reason = ContactReason::Gouge;
  }
  res.evaluations = evals;
  return res;
}

MultipointResult MultipointPositioner::finish_two(MultipointResult& res, const TiltOutcome& t,
                                                  const PseudoInsert& frame, const Vector3d& tip0,
                                                  int& evals) const {
  const PatchSurface& s = *surface_;
  const Vector3d Z = Vector3d::UnitZ();
  const bool drd = opt_.method == MultipointMethod::DRD;
  const double beta = t.beta;
  Vector3d tip = t.pose.tip, axis = t.pose.axis;
  res.penetration = t.penetration;
  res.beta = beta;
  res.uvQ = t.uvQ;
  {
    const SurfacePoint sq = s.eval(t.uvQ.x(), t.uvQ.y(), 1);
    res.Q = sq.S;
    res.nQ = sq.normal();
    if (res.nQ.z() < 0.0) res.nQ = -res.nQ;
  }
  // The seed's axis: Z turned about global X by beta, the sign that leans the same way in Y.
  const Vector3d sx1 = Eigen::AngleAxisd(beta, Vector3d::UnitX()) * Z;
  const Vector3d sx2 = Eigen::AngleAxisd(-beta, Vector3d::UnitX()) * Z;
  const double sign = sx1.dot(axis) >= sx2.dot(axis) ? 1.0 : -1.0;
  res.seed_axis = sign > 0 ? sx1 : sx2;
  res.seed_axis_angle = std::acos(std::clamp(res.seed_axis.dot(axis), -1.0, 1.0));
  res.status = ContactStatus::TwoContacts;
  res.reason = ContactReason::Ok;
  if (opt_.rotation == TiltRotation::GlobalX) {
    const Matrix3d Rx = Eigen::AngleAxisd(sign * beta, Vector3d::UnitX()).toRotationMatrix();
    tip = frame.O1 + Rx * (tip0 - frame.O1);
    axis = res.seed_axis;
    res.reason = ContactReason::SeedRotation;
    res.penetration = penetration(tip, axis, nullptr, &evals);
  }
  if (opt_.rotation == TiltRotation::PseudoInsert && !drd)  // DRD's search already ran the full check
    res.penetration = std::max(res.penetration, penetration(tip, axis, nullptr, &evals));
  res.tip = tip;
  res.axis = axis;
  res.centre = tip + tool_.Ri * axis;
  res.gap_P = tool_distance(tool_, tip, axis, res.P);
  res.gap_Q = tool_distance(tool_, tip, axis, res.Q);
  if (opt_.rotation == TiltRotation::PseudoInsert &&
      (res.penetration > opt_.tol || std::abs(res.gap_P) > opt_.tol || std::abs(res.gap_Q) > opt_.tol)) {
    res.status = ContactStatus::Failed;
    res.reason = res.penetration > opt_.tol ? ContactReason::Gouge : ContactReason::NotConverged;
  }
  if (opt_.rotation == TiltRotation::GlobalX && res.penetration > opt_.tol) res.status = ContactStatus::Failed;
  res.evaluations = evals;
  return res;
}

MultipointResult MultipointPositioner::position_core(double x, double y) const {
  MultipointResult res;
  const PatchSurface& s = *surface_;
  int evals = 0;
  const Vector3d Z = Vector3d::UnitZ();
  const double Ro = tool_.Ro, Ri = tool_.Ri;
  const bool drd = opt_.method == MultipointMethod::DRD;

  const Drop drop = drd ? drop_drd(s, x, y, &evals) : drop_vcrf(x, y, &evals);
  if (!drop.ok) {
    res.status = ContactStatus::Failed;
    res.reason = ContactReason::NoSurface;
    res.tip = Vector3d(x, y, s.bounds().hi.z());
    res.centre = res.tip + Ri * Z;
    res.evaluations = evals;
    return res;
  }
  const Vector3d tip0(x, y, drop.tip_z);
  const Vector3d C0 = tip0 + Ri * Z;
  res.drop_z = drop.tip_z;
  res.uvP = drop.uv;
  {
    const SurfacePoint sp = s.eval(drop.uv.x(), drop.uv.y(), 1);
    res.P = sp.S;
    res.nP = sp.normal();
    if (res.nP.z() < 0.0) res.nP = -res.nP;
  }

  const Vector3d dP = res.P - C0;
  const Vector3d q = dP - dP.dot(Z) * Z;
  const double rhoP = q.norm();
  const ToolPose vertical{tip0, Z};
  if (Ro == 0.0) return finish_single(res, ContactReason::Ball, vertical, 0.0, -1.0, evals);
  const double eps = 1e-9 * (1.0 + Ro + Ri);
  if (tool_.shape == ToolShape::BullNose && rhoP <= Ro + eps)
    return finish_single(res, ContactReason::FlatBottom, vertical, 0.0, -1.0, evals);
  if (tool_.shape == ToolShape::RoundInsert && rhoP < Ro - Ri + eps)
    return finish_single(res, ContactReason::Hollow, vertical, 0.0, -1.0, evals);

  // Pseudo-insert frame (seed eqs. 24-27): e from the axis to P.
  const PseudoInsert frame(tip0, q / rhoP, tool_);
  const TiltGuess guess =
      drd ? drd_tilt_guess(s, tool_, opt_, 2.0 * samples_.spacing(), frame, res.uvP, drop.tip_z, x, y, &evals)
          : vcrf_tilt_guess(s, samples_, tool_, opt_, frame, res.uvP, x, y, &evals);
  if (!(guess.beta <= opt_.beta_max))
    return finish_single(res, ContactReason::TiltLimit, frame.tilted(opt_.beta_max), opt_.beta_max, -1.0, evals);

  TiltSearch search(s, samples_, tool_, opt_, frame, res.uvP, res.P, guess, &evals);
  const TiltOutcome t = search.run(guess.beta, guess.uvQ);
  if (!t.two) return finish_single(res, t.reason, t.pose, t.beta, t.penetration, evals);
  return finish_two(res, t, frame, tip0, evals);
}

MultipointResult MultipointPositioner::position_axis(double x, double y) const {
  MultipointResult r = position_core(x, y);
  r.axis_xy = Vector2d(x, y);
  r.penetration_real = r.penetration;
  if (real_samples_ && r.status != ContactStatus::Failed) {
    // Positioned against the extended face, which holds the real one: the real face is checked on its own
    // (its samples and Newton), a position that enters it beyond tolerance fails.
    int evals = 0;
    r.penetration_real = penetration_real(r.tip, r.axis, nullptr, &evals);
    r.evaluations += evals;
    if (r.penetration_real > opt_.tol) {
      r.status = ContactStatus::Failed;
      r.reason = ContactReason::Gouge;
    }
  }
  if (real_samples_) {
    const Vector2d lo = real_->lo(), hi = real_->hi();
    auto outside = [&](const Vector2d& uv) {
      return uv.x() < lo.x() || uv.x() > hi.x() || uv.y() < lo.y() || uv.y() > hi.y();
    };
    r.P_extension = outside(r.uvP);
    r.Q_extension = outside(r.uvQ);
  }
  return r;
}

MultipointResult MultipointPositioner::position(double x, double y) const {
  if (opt_.anchor == FootprintAnchor::Axis) return position_axis(x, y);
  // Tip anchor: find the pre-tilt axis point q whose tilted tip lands on (x, y). The tip moves with q almost
  // by translation (the tilt changes slowly along the face), so q += (target - tip_xy) converges in a few
  // steps; where the position switches between one and two contacts the map jumps and the iteration may
  // cycle: the iterate nearest the target is kept (anchor_error says how near). Failed iterates are not
  // kept; the step is halved back from them.
  const Vector2d target(x, y);
  Vector2d q = target, last_step = Vector2d::Zero();
  MultipointResult best;
  bool have = false;
  double best_err = kInf;
  int evals = 0;
  const double goal = std::min(opt_.tol, 1e-3);
  for (int k = 0; k < opt_.anchor_iterations; ++k) {
    MultipointResult r = position_axis(q.x(), q.y());
    evals += r.evaluations;
    if (r.status == ContactStatus::Failed) {
      if (!have && k == 0) best = r;
      if (last_step.norm() < 1e-9) break;
      last_step *= 0.5;
      q -= last_step;
      continue;
    }
    const Vector2d err = target - r.tip.head<2>();
    const double e = err.norm();
    if (e < best_err) {
      best_err = e;
      best = r;
      have = true;
    }
    if (e <= goal) break;
    last_step = err;
    q += err;
  }
  best.anchor_error = have ? best_err : 0.0;
  best.evaluations = evals;
  return best;
}

void MultipointPositioner::position_batch(const double* xy, std::size_t n, MultipointResult* out,
                                          const BatchOptions& options) const {
  const std::size_t chunk = opt_.method == MultipointMethod::DRD ? 1 : 16;  // DRD points are slow: balance
  parallel_chunks(n, chunk, options, [&](std::size_t begin, std::size_t end) {
    for (std::size_t i = begin; i < end; ++i) out[i] = position(xy[2 * i], xy[2 * i + 1]);
  });
}

}  // namespace tmm
