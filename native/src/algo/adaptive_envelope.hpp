// The adaptive raster's envelope across a section (internal to src/algo): the instances of a pass that can
// be the least somewhere across a section, and the least of them at a given offset across, pruned by bounds
// that cannot change it. Split from the pass placement (adaptive_raster.cpp).
#pragma once

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <vector>

#include "tmm/cutter/cutter.hpp"
#include "tmm/util/constants.hpp"

namespace tmm {
namespace adaptive_detail {

inline constexpr double kMargin = 1e-9;  // mm: a pruning bound this far under the value cannot cut a rounding

// The cutter's profile h(rho), inf beyond its widest radius (its side wall).
struct Profile {
  const Cutter& cutter;
  double r_max;
  double operator()(double rho) const { return rho <= r_max ? cutter.height(rho) : kInf; }
};

// One pass's instance that may reach a section: its lower surface there is z + h(sqrt(dx2 + dy^2)), never
// below `bound` = z + h(|dx|) nor below z + h(|dy|).
struct Instance {
  double bound, z, dx2;
};

// The instances of a pass (tip heights z along a's x) near one section (listed nearest first) that can be
// the least somewhere across it, lowest first. An instance no lower than a nearer one (dx2 no larger) never
// is: h rises with rho, so the nearer one's z + h(sqrt(dx2 + dy^2)) is no higher at any dy. Those kept
// therefore get lower as they get farther; those whose bound is inf (farther along the pass than the tool's
// radius) never reach the section. dx2 and hdx = h(|dx|) are the same for every pass.
inline void gather(const double* z, const std::vector<std::size_t>& near, const std::vector<double>& dx2,
            const std::vector<double>& hdx, std::size_t first, std::size_t count, std::vector<Instance>& out) {
  out.clear();
  double lowest_z = kInf;
  for (std::size_t k = first; k < first + count; ++k) {
    const double zk = z[near[k]], bound = zk + hdx[k];
    if (zk < lowest_z && bound < kInf) {
      out.push_back({bound, zk, dx2[k]});
      lowest_z = zk;
    }
  }
  std::reverse(out.begin(), out.end());
}

// What lowest() needs of one dy across the section, the same for every section: dy^2, h(|dy|) and the
// bound's bend h'(|dy|) / (r_max + |dy|) (h convex and rising: h(sqrt(dx2 + dy2)) - h(|dy|) >=
// h'(|dy|) dx2 / (sqrt(dx2 + dy2) + |dy|), the root at most r_max where an instance reaches).
struct Across {
  double dy2, lift, bend;
};

inline Across across(double dy, const Profile& h) {
  const double dy2 = dy * dy, ady = std::sqrt(dy2), lift = h(ady);
  const double slope = lift < kInf ? h.cutter.slope(ady) : 0.0;
  return {dy2, lift, std::isfinite(slope) ? slope / (h.r_max + ady) : 0.0};
}

// The least over `in` of z + h(rho) at dy across the section (inf where none reaches): exactly the
// reference's min over all instances, skipping those whose bound (kMargin under it, so that no rounding can
// matter) shows they cannot go lower, and stopping where none of the rest can (they stand higher, and
// h(sqrt(dx2 + dy^2)) >= h(|dy|) in floating point too). `hint`, if given, is an
// instance tried first (the previous sample's least: its value prunes the rest); on return, this one's.
inline double lowest(const std::vector<Instance>& in, const Across& a, const Profile& h, std::size_t* hint = nullptr) {
  if (!(a.lift < kInf)) return kInf;  // beyond the tool's reach across: no instance reaches
  double best = kInf;
  std::size_t first = in.size(), won = in.size();
  if (hint && *hint < in.size()) {
    first = won = *hint;
    best = in[first].z + h(std::sqrt(in[first].dx2 + a.dy2));
  }
  for (std::size_t k = 0; k < in.size(); ++k) {
    const Instance& i = in[k];
    if (i.z + a.lift >= best) break;
    if (k == first || i.bound >= best || i.z + a.lift + a.bend * i.dx2 - kMargin >= best) continue;
    const double v = i.z + h(std::sqrt(i.dx2 + a.dy2));
    if (v < best) {
      best = v;
      won = k;
    }
  }
  if (hint) *hint = won;
  return best;
}

inline double lowest(const std::vector<Instance>& in, double dy, const Profile& h) { return lowest(in, across(dy, h), h); }

// A lower bound of lowest(in, a, h): no instance of the pass comes lower there.
inline double floor_of(const std::vector<Instance>& in, const Across& a) {
  return in.empty() ? kInf : in.front().z + a.lift;
}

}  // namespace adaptive_detail
}  // namespace tmm
