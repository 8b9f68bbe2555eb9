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

struct SimReport {
  std::size_t moves_cut = 0;      // Cut and Rapid moves simulated
  std::size_t cells_lowered = 0;  // cells whose height any move lowered
  std::vector<RapidCollision> collisions;  // rapids that removed more than the collision tolerance
};

}  // namespace tmm
