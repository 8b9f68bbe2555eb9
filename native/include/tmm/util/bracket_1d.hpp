// One-dimensional searches for the boundary between the "good" and the "bad" part of an interval, where
// the good part [lo, t] is an interval starting at lo (e.g. the tilts a tool can take without gouging).
#pragma once

#include "tmm/util/constants.hpp"

namespace tmm {

struct Bracket {
  double good;  // the largest point known good
  double bad;   // the smallest point known bad
};

// Bisection: `steps` halvings of [good, bad]; good(t) says on which side t lies.
template <class Good>
Bracket bisect(double good, double bad, int steps, Good&& is_good) {
  for (int k = 0; k < steps; ++k) {
    const double mid = 0.5 * (good + bad);
    if (is_good(mid)) good = mid;
    else bad = mid;
  }
  return {good, bad};
}

// Regula falsi (Illinois variant) for the sign change of a continuous f, good where f >= 0: f(a) = fa >= 0,
// f(b) = fb < 0. Stops after max_iter evaluations or when the bracket is narrower than width.
template <class F>
Bracket illinois(double a, double b, double fa, double fb, int max_iter, double width, F&& f) {
  int side = 0;
  for (int k = 0; k < max_iter && b - a > width; ++k) {
    const double c = (a * fb - b * fa) / (fb - fa);
    const double m = (c > a && c < b) ? c : 0.5 * (a + b);
    const double fm = f(m);
    if (fm >= 0.0) {
      a = m;
      fa = fm;
      if (side == -1) fb *= 0.5;
      side = -1;
    } else {
      b = m;
      fb = fm;
      if (side == 1) fa *= 0.5;
      side = 1;
    }
  }
  return {a, b};
}

}  // namespace tmm
