#include "tmm/position/options.hpp"

#include <stdexcept>

#include "tmm/cutter/torus_tool.hpp"
#include "tmm/util/constants.hpp"

namespace tmm {

void validate(const MultipointOptions& o, const TorusTool& tool) {
  if (!(o.beta_max > 0.0 && o.beta_max < kPi / 2)) throw std::invalid_argument("beta_max must be in (0, pi/2)");
  if (!(o.tol > 0.0)) throw std::invalid_argument("tolerance must be > 0");
  if (o.divisions < 1 || o.refinements < 0 || o.drd_divisions < 2 || o.drd_refinements < 1 ||
      o.drd_bisections < 1 || o.anchor_iterations < 1)
    throw std::invalid_argument("grid divisions / refinements / bisections / anchor iterations out of range");
  (void)tool;
}

double sample_spacing_for(const MultipointOptions& o, const TorusTool& tool) {
  return o.sample_spacing > 0.0 ? o.sample_spacing : (tool.Ro + tool.Ri) / 8.0;
}

}  // namespace tmm
