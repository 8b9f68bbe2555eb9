#include "tmm/position/options.hpp"

#include <cmath>
#include <sstream>
#include <stdexcept>
#include <string>

#include "tmm/cutter/torus_tool.hpp"
#include "tmm/util/constants.hpp"

namespace tmm {

namespace {

template <class T>
[[noreturn]] void refuse(const char* name, const std::string& rule, T value) {
  std::ostringstream msg;
  msg << name << " must be " << rule << ", got " << value;
  throw std::invalid_argument(msg.str());
}

// Grid sizes up to these bounds keep every loop counter and product in range (and the run time sane).
void check_count(const char* name, int value, int lo, int hi) {
  if (value < lo || value > hi)
    refuse(name, "a whole number in [" + std::to_string(lo) + ", " + std::to_string(hi) + "]", value);
}

}  // namespace

void validate(const MultipointOptions& o, const TorusTool& tool) {
  tool.validate();
  if (!(o.beta_max > 0.0 && o.beta_max < kPi / 2)) refuse("beta_max", "in (0, pi/2) rad", o.beta_max);
  if (!(o.tol > 0.0 && std::isfinite(o.tol))) refuse("tol", "finite and > 0 (mm)", o.tol);
  if (!(o.sample_spacing >= 0.0 && std::isfinite(o.sample_spacing)))
    refuse("sample_spacing", "0 (auto: (Ro + Ri) / 8) or finite and > 0 (mm)", o.sample_spacing);
  if (!(o.extend >= 0.0 && std::isfinite(o.extend))) refuse("extend", "finite and >= 0 (mm)", o.extend);
  check_count("divisions", o.divisions, 1, 1000);
  check_count("refinements", o.refinements, 0, 50);
  check_count("drd_divisions", o.drd_divisions, 2, 1000);
  check_count("drd_refinements", o.drd_refinements, 1, 50);
  check_count("drd_bisections", o.drd_bisections, 1, 200);
  check_count("anchor_iterations", o.anchor_iterations, 1, 1000);
  if (static_cast<int>(o.method) < 0 || static_cast<int>(o.method) > 1) refuse("method", "VCRF or DRD", static_cast<int>(o.method));
  if (static_cast<int>(o.rotation) < 0 || static_cast<int>(o.rotation) > 1)
    refuse("rotation", "PseudoInsert or GlobalX", static_cast<int>(o.rotation));
  if (static_cast<int>(o.anchor) < 0 || static_cast<int>(o.anchor) > 1) refuse("anchor", "Axis or Tip", static_cast<int>(o.anchor));
}

double sample_spacing_for(const MultipointOptions& o, const TorusTool& tool) {
  return o.sample_spacing > 0.0 ? o.sample_spacing : (tool.Ro + tool.Ri) / 8.0;
}

}  // namespace tmm
