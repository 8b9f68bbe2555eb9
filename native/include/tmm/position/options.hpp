// The options of multipoint positioning (seed 001), checked in one place.
#pragma once

namespace tmm {

struct TorusTool;

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

// Throws std::invalid_argument naming the first option out of range (NaN and infinities included).
void validate(const MultipointOptions& options, const TorusTool& tool);

// The sample spacing the positioner uses for the tool: the option, or (Ro + Ri) / 8 for 0.
double sample_spacing_for(const MultipointOptions& options, const TorusTool& tool);

}  // namespace tmm
