// The tool assembly's drop: the grown cutter and bodies as shifted APT cutters (drop_assembly.hpp), dropped
// one after another, each from the height so far.
#include "tmm/query/drop_assembly.hpp"

#include <algorithm>
#include <cmath>
#include <sstream>
#include <stdexcept>
#include <string>

#include "tmm/util/range.hpp"

namespace tmm {

namespace {

[[noreturn]] void refuse_body(std::size_t i, const ToolBody& b, const std::string& why) {
  std::ostringstream msg;
  msg << "tool body " << i << " (z0 " << b.z0 << ", z1 " << b.z1 << ", r0 " << b.r0 << ", r1 " << b.r1
      << ", clearance " << b.clearance << "): " << why;
  throw std::invalid_argument(msg.str());
}

void check_bodies(const std::vector<ToolBody>& bodies) {
  for (std::size_t i = 0; i < bodies.size(); ++i) {
    const ToolBody& b = bodies[i];
    for (double v : {b.z0, b.z1, b.r0, b.r1, b.clearance})
      if (!in_range(v)) refuse_body(i, b, "a value " + out_of_range_text());
    if (b.z0 < 0.0) refuse_body(i, b, "z0 must be >= 0 (bodies are given in tip coordinates, above the tip)");
    if (!(b.z1 > b.z0)) refuse_body(i, b, "z1 must be above z0");
    if (b.r0 < 0.0 || b.r1 < 0.0) refuse_body(i, b, "radii must be >= 0");
    if (b.clearance < 0.0) refuse_body(i, b, "clearance must be >= 0");
    if (!(std::max(b.r0, b.r1) + b.clearance > 0.0))
      refuse_body(i, b, "a body needs a positive radius or a positive clearance");
    if (i > 0 && b.z0 < bodies[i - 1].z1) {
      std::ostringstream why;
      why << "bodies must be sorted from the tip up with z ranges not overlapping: z0 is below the previous "
             "body's z1 = "
          << bodies[i - 1].z1;
      refuse_body(i, b, why.str());
    }
  }
}

constexpr std::size_t kNoBody = ~std::size_t{0};

// Does a body other than `skip`, grown by its clearance, hold the disc of radius `radius` at height `z` grown
// by `clearance`? Then that disc's piece (a top rim) can never set the height and is left out.
bool disc_covered(const std::vector<ToolBody>& bodies, std::size_t skip, double z, double radius,
                  double clearance) {
  for (std::size_t j = 0; j < bodies.size(); ++j) {
    const ToolBody& b = bodies[j];
    if (j == skip || b.z0 > z || b.z1 < z || b.clearance < clearance) continue;
    const double at = b.r0 + (b.r1 - b.r0) * (z - b.z0) / (b.z1 - b.z0);
    if (at >= radius) return true;
  }
  return false;
}

// The cutter grown by c. A flat-bottomed APT profile offset by c is one again: the corner radius grows by c
// about the same centre, the taper moves out by c along its normal (cos beta2, -sin beta2), the tip down by c.
// A widening taper ends at the cutter's top rim (R, L_C), whose ball the top disc's bull-nose adds.
void add_cutter(std::vector<AssemblyPiece>& out, const Cutter& k, double c, const std::vector<ToolBody>& bodies) {
  if (c == 0.0) {
    out.push_back({k, 0.0, kSetByCutter});
    return;
  }
  if (k.beta1() != 0.0)
    throw std::invalid_argument(
        "a cutter clearance needs a flat-bottomed cutter (bottom angle beta1 = 0): a conical bottom grown by a "
        "clearance is no APT profile; give the clearance to the bodies above it instead");
  const double r = k.corner_radius() + c, Lc = k.cutting_length();
  if (!std::isfinite(Lc)) {
    out.push_back({Cutter(k.radius() + c, r), -c, kSetByCutter});
    return;
  }
  const double b2 = k.beta2();
  out.push_back({Cutter::apt(k.radius() + c * std::cos(b2), r, Lc + c * (1.0 - std::sin(b2)), 0.0, b2), -c,
                 kSetByCutter});
  if (b2 > 0.0 && !disc_covered(bodies, kNoBody, Lc, k.radius(), c))
    out.push_back({Cutter(k.radius() + c, c), Lc - c, kSetByCutter});
}

// Body i grown by its clearance (see drop_assembly.hpp for the geometry).
void add_body(std::vector<AssemblyPiece>& out, std::size_t i, const std::vector<ToolBody>& bodies) {
  const ToolBody& b = bodies[i];
  const double c = b.clearance;
  const auto owner = static_cast<int32_t>(i);
  if (b.r1 <= b.r0) {  // the bottom disc shadows the rest
    out.push_back({Cutter(b.r0 + c, c), b.z0 - c, owner});
    return;
  }
  const double height = b.z1 - b.z0, beta2 = std::atan2(b.r1 - b.r0, height);
  // The side offset by c ends c (cos beta2, -sin beta2) from the top rim; the corner arc (radius c) is
  // centred on the bottom rim (r0, z0), the flat bottom c below it.
  out.push_back({Cutter::apt(b.r1 + c * std::cos(beta2), c, height + c * (1.0 - std::sin(beta2)), 0.0, beta2),
                 b.z0 - c, owner});
  if (c > 0.0 && !disc_covered(bodies, i, b.z1, b.r1, c))  // only a body sitting on this one can cover it
    out.push_back({Cutter(b.r1 + c, c), b.z1 - c, owner});
}

}  // namespace

ToolAssembly::ToolAssembly(const Cutter& cutter, const std::vector<ToolBody>& bodies, double cutter_clearance)
    : body_count_(bodies.size()) {
  if (!(in_range(cutter_clearance) && cutter_clearance >= 0.0)) {
    std::ostringstream msg;
    msg << "cutter clearance must be >= 0 and finite, got " << cutter_clearance;
    throw std::invalid_argument(msg.str());
  }
  check_bodies(bodies);
  add_cutter(pieces_, cutter, cutter_clearance, bodies);
  for (std::size_t i = 0; i < bodies.size(); ++i) {
    try {
      add_body(pieces_, i, bodies);
    } catch (const std::invalid_argument& e) {  // a profile the APT cutter refuses (a nearly flat cone)
      refuse_body(i, bodies[i], e.what());
    }
  }
}

double drop_assembly_point(const MeshIndex& index, const ToolAssembly& tool, double x, double y, double floor_z,
                           int32_t* set_by, DropStats* stats) {
  double z = floor_z;
  int32_t by = kSetByFloor;
  for (const AssemblyPiece& p : tool.pieces()) {
    // The piece matters only where it would lift the tool: its drop starts at the height so far.
    const double base = z + p.lift;
    const double top = drop_point(index, p.profile, x, y, base, stats);
    if (top > base && top - p.lift > z) {
      z = top - p.lift;
      by = p.owner;
    }
  }
  if (set_by) *set_by = by;
  return z;
}

void drop_assembly_batch(const MeshIndex& index, const ToolAssembly& tool, const double* xy, std::size_t n,
                         double floor_z, double* z_out, int32_t* set_by, const BatchOptions& options,
                         DropStats* stats) {
  require_in_range(floor_z, "floor_z");
  const std::vector<AssemblyPiece>& pieces = tool.pieces();
  const double passes = static_cast<double>(pieces.size());
  std::vector<double> base(n), top(n);
  std::fill(z_out, z_out + n, floor_z);
  if (set_by) std::fill(set_by, set_by + n, kSetByFloor);
  for (std::size_t k = 0; k < pieces.size(); ++k) {
    const AssemblyPiece& p = pieces[k];
    BatchOptions pass = options;  // progress over all passes
    if (options.progress)
      pass.progress = [&options, k, passes](double f) { return options.progress((static_cast<double>(k) + f) / passes); };
    for (std::size_t i = 0; i < n; ++i) base[i] = z_out[i] + p.lift;
    if (k == 0)  // one floor: the plain batch (with no clearance, the very heights of drop_batch)
      drop_batch(index, p.profile, xy, n, floor_z + p.lift, top.data(), pass, stats);
    else
      drop_batch(index, p.profile, xy, n, base.data(), top.data(), pass, stats);
    for (std::size_t i = 0; i < n; ++i) {
      if (top[i] > base[i] && top[i] - p.lift > z_out[i]) {
        z_out[i] = top[i] - p.lift;
        if (set_by) set_by[i] = p.owner;
      }
    }
  }
}

}  // namespace tmm
