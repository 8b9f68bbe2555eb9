// What one multipoint position reports.
#pragma once

#include <Eigen/Core>

#include <string>
#include <vector>

namespace tmm {

using Eigen::Vector2d;
using Eigen::Vector3d;

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

}  // namespace tmm
