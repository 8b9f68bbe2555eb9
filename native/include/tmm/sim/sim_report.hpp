// What cutting a tool path into a z-map reports, for 3-axis and 5-axis moves alike.
#pragma once

#include <cstddef>
#include <cstdint>
#include <vector>

namespace tmm {

// The kind of the move from point k to point k + 1 of a tool path.
enum class MoveKind : std::uint8_t {
  Cut = 0,    // a feed move: cuts what it passes through
  Rapid = 1,  // a rapid: cuts too (the machine does), but removing material is a collision
  Jump = 2,   // no motion between the two points (a tool change, a path break): not simulated
};

struct RapidCollision {
  std::size_t move = 0;  // index k of the move k -> k + 1
  double depth = 0.0;    // deepest material the rapid removed, mm
};

// A body above the flutes (neck, shank, holder piece) closer to the stock than its clearance during a move
// (tmm/sim/body_check.hpp): the deepest cell of that move and piece.
struct BodyCollision {
  std::size_t move = 0;   // index k of the move k -> k + 1
  std::size_t piece = 0;  // index of the body in BodyCheck::bodies
  double x = 0, y = 0, z = 0;  // the deepest cell: its centre and its stock height
  double depth = 0;       // mm the stock reaches above the grown body's lowest point (>= clearance: into the body)
};

struct SimReport {
  std::size_t moves_cut = 0;      // Cut and Rapid moves simulated
  std::size_t cells_lowered = 0;  // cells whose height any move lowered
  std::vector<RapidCollision> collisions;  // rapids that removed more than the collision tolerance
  std::vector<BodyCollision> body_collisions;  // with a body check: per move and piece, sorted
};

}  // namespace tmm
