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
// Frames and conventions (world = the surface's frame, mm):
//   tip   the lowest point of the tool on its axis (the CL point), axis a = unit tip -> spindle,
//   centre C = tip + Ri a (centre of the torus' major circle), pseudo-insert centre O1 = C + Ro e
//   (e: unit direction from the axis to P, perpendicular to a), u1 = a x e (pseudo-insert axis),
//   v1 = -e (towards the tool axis), w1 = a. Tilting by beta rotates the tool by -beta about u1 through O1:
//   the side of the tool opposite P goes down, the axis leans away from P.
//
// The tool solid (what must not enter the surface), two shapes:
//   RoundInsert  the seed's torus (eq. 20): the full lower half of the torus (inner and outer), a body
//                above the centre plane out to Ro + Ri, and an open hollow for rho < Ro - Ri below it
//                (round-insert cutters; seed 3.3.1 "a tool with a small hollow in the bottom plane").
//   BullNose     a solid end mill: flat bottom for rho <= Ro, outer quarter torus, cylinder above.
// Ro = 0 is a ball (tilting about its centre changes nothing: one contact, axis vertical);
// Ri = 0 (flat end mill) is refused: a point insert has no pseudo-insert circle to roll on.
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "tmm/surface/bezier.hpp"
#include "tmm/query/drop_cutter.hpp"  // Cancelled, BatchOptions

namespace tmm {

enum class ToolShape { RoundInsert = 0, BullNose = 1 };
enum class MultipointMethod { VCRF = 0, DRD = 1 };
// PseudoInsert: the exact rotation about u1 at O1. GlobalX: the seed's pseudo-code (4.9 / 4.12), the tool
// axis rotated about the global X axis by beta (the tip pivoting about O1), kept to measure the error.
enum class TiltRotation { PseudoInsert = 0, GlobalX = 1 };
// What the footprint point (x, y) fixes. Axis (the seed): the vertical tool axis through (x, y) before the
// drop and the tilt; the tilt about the pseudo-insert axis then moves the tip sideways (up to ~1.5 mm on the
// seed patches, towards the face's centre on a convex face, away from it on a concave one, so the passes'
// tips end up closer or wider apart than the footprint's side step). Tip: the tilted tool's tip (the CL
// point) lies at (x, y): the pre-tilt axis point is found by a fixed-point iteration (tip offset fed back),
// every iterate being a full, gouge-checked multipoint position of its own axis point.
enum class FootprintAnchor { Axis = 0, Tip = 1 };

struct TorusTool {
  double Ro = 0.0;  // major radius (centre of the pseudo-insert to the axis)
  double Ri = 0.0;  // minor radius (pseudo-insert)
  ToolShape shape = ToolShape::RoundInsert;
  // Throws std::invalid_argument for Ro < 0, Ri <= 0 (flat end mill refused) or non-finite radii.
  void validate() const;
  double radius() const { return Ro + Ri; }
  // Height of the lower cutting surface above the tip at distance rho from the axis (rho <= Ro + Ri).
  double profile(double rho) const;
};

// Signed distance from x to the tool solid (negative inside), its gradient (unit outward normal of the
// nearest tool point) and, if hess != nullptr, its Hessian (zero on flat pieces).
double tool_distance(const TorusTool& tool, const Vector3d& tip, const Vector3d& axis, const Vector3d& x,
                     Vector3d* grad = nullptr, Eigen::Matrix3d* hess = nullptr);

enum class ContactStatus { TwoContacts = 0, OneContact = 1, Failed = 2 };

// Why a position has the status it has (index into multipoint_reason_text()).
enum class ContactReason {
  Ok = 0,              // two contacts
  NoSurface,           // no surface under the tool
  Ball,                // Ro = 0: tilting about the ball's centre does not move the tool
  FlatBottom,          // P on the flat bottom (BullNose): tilting about the pseudo-insert would gouge at P
  Hollow,              // P under the hollow centre of a round-insert tool (no pseudo-insert there)
  TiltLimit,           // no second contact up to the tilt limit: tilted to the limit, one contact
  CurvatureLimit,      // Q coincides with P: the surface curvature at P limits the tilt (convex / flat)
  NotConverged,        // the refinement of the second contact did not converge
  Gouge,               // the final check found penetration above tolerance
  SeedRotation,        // GlobalX rotation: the seed's approximate tilt, contacts not kept
  Count
};
const std::vector<std::string>& multipoint_reason_text();

struct MultipointOptions {
  MultipointMethod method = MultipointMethod::VCRF;
  TiltRotation rotation = TiltRotation::PseudoInsert;
  double beta_max = 0.7853981633974483;  // tilt limit, rad (seed: pi/4, the tilt table's range)
  double tol = 1e-3;                      // contact gap and penetration tolerance, mm
  double sample_spacing = 0.0;            // surface sample spacing, mm (0: (Ro + Ri) / 8)
  // Seed grid searches around the best sample (VCRF) or over the tool's rays (DRD).
  int divisions = 6;      // VCRF: per zoom window and direction (seed 32)
  int refinements = 1;    // VCRF: zoom levels (seed 4)
  int drd_divisions = 10; // DRD: rays per direction (seed 10)
  int drd_refinements = 5;// DRD: zoom levels (seed 5)
  int drd_bisections = 16;// DRD: bisection steps on beta (seed: 10 repeats of the same Q)
  // Surface extension ("machine past the edge"): > 0 positions the tool against the face continued past
  // its boundary curves by this distance (mm; PatchSurface::extended, the polynomial continuation), so a
  // tool over the boundary rests on the continued surface instead of on the boundary curve. Every position
  // is then also checked for penetration against the real face (penetration_real). 0: the face only.
  double extend = 0.0;
  FootprintAnchor anchor = FootprintAnchor::Axis;
  int anchor_iterations = 12;  // Tip: at most this many positions per footprint point
};

struct MultipointResult {
  ContactStatus status = ContactStatus::Failed;
  ContactReason reason = ContactReason::NoSurface;
  Vector3d tip = Vector3d::Zero(), axis = Vector3d::UnitZ(), centre = Vector3d::Zero();
  Vector3d P = Vector3d::Zero(), nP = Vector3d::Zero(), Q = Vector3d::Zero(), nQ = Vector3d::Zero();
  Vector2d uvP = Vector2d::Zero(), uvQ = Vector2d::Zero();
  double beta = 0.0;          // tilt about the pseudo-insert axis, rad
  double drop_z = 0.0;        // tip height after the vertical drop
  double gap_P = 0.0, gap_Q = 0.0;  // tool distance at P and Q (0 = touching)
  double penetration = 0.0;   // deepest surface point inside the tool found by the final check (>= 0)
  Vector3d seed_axis = Vector3d::UnitZ();  // the seed's axis: Z rotated by beta about global X
  double seed_axis_angle = 0.0;            // angle between seed_axis and the exact axis, rad
  int evaluations = 0;        // surface evaluations spent (cost counter)
  Vector2d axis_xy = Vector2d::Zero();  // the pre-tilt axis point positioned (the footprint point for Axis)
  double anchor_error = 0.0;  // Tip: |tip_xy - footprint point| of the kept iterate (0 for Axis)
  double penetration_real = 0.0;  // extend > 0: penetration into the real face (else = penetration)
  bool P_extension = false, Q_extension = false;  // extend > 0: the contact lies on the extension
};

// Dense-enough samples of a surface and an XY bucket grid over them: the "rays from the surface" of VCRF
// and the candidates of the gouge check. Built once per surface and tool.
class SurfaceSamples {
 public:
  // spacing: target distance between samples (mm); cell: XY bucket size (mm).
  SurfaceSamples(const PatchSurface& surface, double spacing, double cell);
  double spacing() const { return spacing_; }
  // Calls f(index) for every sample within XY distance r of (x, y).
  template <class F>
  void within(double x, double y, double r, F&& f) const;
  const std::vector<Vector3d>& points() const { return pts_; }
  const std::vector<Vector2d>& params() const { return uv_; }
  // Parameter step of the sample grid around sample k (half-width of a zoom window).
  Vector2d step(std::size_t k) const { return step_[patch_[k]]; }

 private:
  std::vector<Vector3d> pts_;
  std::vector<Vector2d> uv_;
  std::vector<int> patch_;
  std::vector<Vector2d> step_;
  double spacing_ = 1, x0_ = 0, y0_ = 0, cell_ = 1;
  int nx_ = 1, ny_ = 1;
  std::vector<int> start_;   // bucket -> first entry in order_
  std::vector<int> order_;   // sample indices by bucket
};

class MultipointPositioner {
 public:
  // Throws std::invalid_argument on an invalid tool or options.
  MultipointPositioner(std::shared_ptr<const PatchSurface> surface, TorusTool tool, MultipointOptions options);

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
  struct Drop {
    bool ok = false;
    double tip_z = 0.0;
    Vector2d uv = Vector2d::Zero();
  };
  Drop drop_vcrf(double x, double y, int* evals) const;
  Drop drop_drd(const PatchSurface& s, double x, double y, int* evals) const;
  // Deepest penetration (>= 0) of the surface into the tool placed at (tip, axis), by the samples and a
  // Newton polish of the lowest ones; `where` receives its parameters.
  double penetration(const Vector3d& tip, const Vector3d& axis, Vector2d* where, int* evals) const;
  // The same against the real face (differs from penetration() only when extend > 0).
  double penetration_real(const Vector3d& tip, const Vector3d& axis, Vector2d* where, int* evals) const;

 private:
  MultipointResult position_core(double x, double y) const;
  double penetration_on(const PatchSurface& s, const SurfaceSamples& samples, const Vector3d& tip,
                        const Vector3d& axis, Vector2d* where, int* evals) const;
  std::shared_ptr<const PatchSurface> real_;
  std::shared_ptr<const PatchSurface> surface_;
  TorusTool tool_;
  MultipointOptions opt_;
  SurfaceSamples samples_;
  std::unique_ptr<SurfaceSamples> real_samples_;  // extend > 0 only
};

template <class F>
void SurfaceSamples::within(double x, double y, double r, F&& f) const {
  const int i0 = std::max(0, static_cast<int>(std::floor((x - r - x0_) / cell_)));
  const int i1 = std::min(nx_ - 1, static_cast<int>(std::floor((x + r - x0_) / cell_)));
  const int j0 = std::max(0, static_cast<int>(std::floor((y - r - y0_) / cell_)));
  const int j1 = std::min(ny_ - 1, static_cast<int>(std::floor((y + r - y0_) / cell_)));
  const double r2 = r * r;
  for (int j = j0; j <= j1; ++j) {
    for (int i = i0; i <= i1; ++i) {
      const int b = j * nx_ + i;
      for (int k = start_[b]; k < start_[b + 1]; ++k) {
        const int s = order_[k];
        const double dx = pts_[s].x() - x, dy = pts_[s].y() - y;
        if (dx * dx + dy * dy <= r2) f(static_cast<std::size_t>(s));
      }
    }
  }
}

}  // namespace tmm
