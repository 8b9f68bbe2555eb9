// Drop of the whole tool assembly along -Z: the cutter, then the shank, neck and holder above it, each kept at
// least its clearance away from the mesh. At each (x, y): the lowest tip height (CL point) such that no piece
// comes closer to the mesh than its clearance.
//
// Each body above the cutter is a frustum coaxial with the tool, given in tip coordinates. Grown by its
// clearance c (the Minkowski sum with a ball of radius c) it is again convex and of revolution, and a drop
// along -Z meets only its lower envelope, so each maps exactly onto generalized APT cutter drops (seed 000,
// section 3.5.2.2), shifted along the axis:
//   cylinder, or narrowing cone (r1 <= r0): its bottom disc touches first: a bull-nose of radius r0 + c and
//     corner c whose tip is c below z0;
//   widening cone (r1 > r0): an APT cutter with a flat bottom of radius r0, corner radius c and the side
//     offset by c, up to where the side's offset meets the top rim's ball; beyond it (r1 + c sin(phi) to
//     r1 + c, phi the side's angle from the horizontal) the envelope is the top rim grown by c, which the
//     body's top disc grown by c (a bull-nose of radius r1 + c, corner c, tip at z1 - c) gives exactly.
//     That piece is left out when the next body sits on this one and covers it (see ToolAssembly).
// A top face faces up and never meets the mesh first in a drop from above. The assembly is dropped from
// above: a mesh point over a piece's footprint counts even above that piece's top (an overhang over the
// holder stops the tool as the spindle above it would).
#pragma once

#include <cstddef>
#include <cstdint>
#include <vector>

#include "tmm/cutter/cutter.hpp"
#include "tmm/mesh/mesh_index.hpp"
#include "tmm/query/drop_cutter.hpp"
#include "tmm/util/parallel.hpp"

namespace tmm {

// A frustum coaxial with the tool: radius r0 at height z0 above the tip, r1 at z1 (a cylinder when equal),
// kept `clearance` away from the mesh.
struct ToolBody {
  double z0 = 0, z1 = 0, r0 = 0, r1 = 0, clearance = 0;
};

// What set a drop's height: the cutter, a body (its position in the list), or nothing above the floor.
constexpr int32_t kSetByCutter = -1;
constexpr int32_t kSetByFloor = -2;

// One convex piece of the grown assembly: a cutter profile whose tip sits `lift` above the tool's tip.
struct AssemblyPiece {
  Cutter profile;
  double lift;
  int32_t owner;  // kSetByCutter or the body's position
};

class ToolAssembly {
 public:
  // bodies: sorted from the tip up, z ranges not overlapping (one may start where the last ends), each with
  // z0 >= 0, z1 > z0, radii >= 0, a positive radius or clearance, clearance >= 0, all finite and within the
  // kernel's range. cutter_clearance >= 0; with a positive one the cutter must have a flat bottom
  // (beta1 = 0): a grown conical bottom is no APT profile. Throws std::invalid_argument naming the body and
  // the value.
  ToolAssembly(const Cutter& cutter, const std::vector<ToolBody>& bodies, double cutter_clearance = 0.0);

  // The grown cutter first (with no clearance the cutter itself, lift 0), then the bodies' pieces from the
  // lowest up: the order the drop raises the height in.
  const std::vector<AssemblyPiece>& pieces() const { return pieces_; }
  std::size_t body_count() const { return bodies_.size(); }
  const Cutter& cutter() const { return cutter_; }
  const std::vector<ToolBody>& bodies() const { return bodies_; }
  double cutter_clearance() const { return cutter_clearance_; }

  // Does a body other than `skip` (kNoBody: none skipped), grown by its clearance, hold the disc of radius
  // `radius` at height `z` grown by `clearance`? Then that disc's grown piece never touches first.
  static constexpr std::size_t kNoBody = ~std::size_t{0};
  bool disc_covered(std::size_t skip, double z, double radius, double clearance) const;

 private:
  Cutter cutter_;
  std::vector<ToolBody> bodies_;
  double cutter_clearance_ = 0;
  std::vector<AssemblyPiece> pieces_;
};

// One point: the tip height, never below floor_z. `set_by` (may be null) receives kSetByCutter, the body or
// kSetByFloor. With no bodies and no clearance: exactly drop_point(index, cutter, ...).
double drop_assembly_point(const MeshIndex& index, const ToolAssembly& tool, double x, double y, double floor_z,
                           int32_t* set_by = nullptr, DropStats* stats = nullptr);

// xy: n points (x0, y0, x1, y1, ...); z_out: n tip heights; set_by (may be null): n codes as above. The cutter
// is dropped first (drop_batch), then each body's pieces from the lowest up, each starting from the height so
// far (a per-point floor): a point skips a piece when a grid of the mesh's heights near the points, dilated by
// the piece's reach, stays below the tip height so far + the piece's lift (a holder high above the part: one
// lookup), and the drops that remain skip every index subtree whose top is below that floor. With no bodies
// and no clearance the heights are exactly drop_batch's. Throws as drop_batch (Cancelled, a floor out of
// range).
void drop_assembly_batch(const MeshIndex& index, const ToolAssembly& tool, const double* xy, std::size_t n,
                         double floor_z, double* z_out, int32_t* set_by, const BatchOptions& options,
                         DropStats* stats = nullptr);

// As above with a floor per point (floors: n heights, -inf allowed), e.g. starts at different heights: with
// every floor equal to floor_z the very heights of the one-floor batch.
void drop_assembly_batch(const MeshIndex& index, const ToolAssembly& tool, const double* xy, std::size_t n,
                         const double* floors, double* z_out, int32_t* set_by, const BatchOptions& options,
                         DropStats* stats = nullptr);

}  // namespace tmm
