// Fast marching of the 3D offset's arrival-time field: see tmm/algo/arrival_field.hpp.
#include "tmm/algo/arrival_field.hpp"

#include <algorithm>
#include <cmath>
#include <functional>
#include <limits>
#include <queue>
#include <stdexcept>
#include <string>
#include <utility>

#include "tmm/util/constants.hpp"
#include "tmm/util/range.hpp"

namespace tmm {

void check_arrival_inputs(const ArrivalGrid& g, const std::vector<double>& z, const StepRuleTable& r) {
  if (g.nx < 2 || g.ny < 2) throw std::invalid_argument("arrival field: the grid needs at least 2 x 2 nodes");
  if (!(std::isfinite(g.cell) && g.cell > 0)) throw std::invalid_argument("arrival field: cell must be > 0 mm");
  if (z.size() != static_cast<std::size_t>(g.nx) * static_cast<std::size_t>(g.ny))
    throw std::invalid_argument("arrival field: z must have nx * ny heights");
  for (double v : z)
    if (!std::isfinite(v)) throw std::invalid_argument("arrival field: every CL height must be finite");
  require_in_range(g.cell * std::max(g.nx, g.ny), "arrival field: the grid's extent cell * max(nx, ny)");
  for (std::size_t k = 0; k < z.size(); ++k)
    if (!in_range(z[k])) require_in_range(z[k], "arrival field: CL height " + std::to_string(k));
  for (double s : r.steps) require_in_range(s, "arrival field: tabulated step");
  require_in_range(r.radius, "arrival field: radius");
  require_in_range(r.probe, "arrival field: probe");
  if (r.steps.empty()) throw std::invalid_argument("arrival field: the step table is empty");
  for (double s : r.steps)
    if (!(std::isfinite(s) && s > 0)) throw std::invalid_argument("arrival field: every tabulated step must be > 0");
  if (!(std::isfinite(r.dslope) && r.dslope > 0)) throw std::invalid_argument("arrival field: dslope must be > 0");
  if (!(std::isfinite(r.radius) && r.radius >= 0)) throw std::invalid_argument("arrival field: radius must be >= 0");
  if (!(std::isfinite(r.probe) && r.probe > 0)) throw std::invalid_argument("arrival field: probe must be > 0 mm");
  if (!(std::isfinite(r.min_step) && r.min_step > 0))
    throw std::invalid_argument("arrival field: min_step must be > 0 mm");
}

namespace {

// Bilinear z at (x, y) mm, clamped to the grid.
double height(const ArrivalGrid& g, const std::vector<double>& z, double x, double y) {
  const double fx = std::clamp(x / g.cell, 0.0, g.nx - 1.0), fy = std::clamp(y / g.cell, 0.0, g.ny - 1.0);
  const int i = std::min(static_cast<int>(fx), g.nx - 2), j = std::min(static_cast<int>(fy), g.ny - 2);
  const double a = fx - i, b = fy - j;
  const std::size_t k = static_cast<std::size_t>(j) * g.nx + i;
  return (1 - b) * ((1 - a) * z[k] + a * z[k + 1]) + b * ((1 - a) * z[k + g.nx] + a * z[k + g.nx + 1]);
}

}  // namespace

double arrival_step(const ArrivalGrid& g, const std::vector<double>& z, const StepRuleTable& r, double x, double y,
                    double ux, double uy) {
  const double n = std::hypot(ux, uy);
  if (n > 0) {
    ux /= n;
    uy /= n;
  } else {
    ux = 1;
    uy = 0;
  }
  const double a = r.probe;
  const double z0 = height(g, z, x, y), zf = height(g, z, x + a * ux, y + a * uy),
               zb = height(g, z, x - a * ux, y - a * uy);
  const double rise = std::max(std::abs(zf - z0), std::abs(z0 - zb));
  const double t = std::atan2(rise, a) / r.dslope;
  const std::size_t last = r.steps.size() - 1;
  double step;
  if (t >= static_cast<double>(last)) {
    step = r.steps[last];
  } else {
    const std::size_t k = static_cast<std::size_t>(t);
    step = r.steps[k] + (r.steps[k + 1] - r.steps[k]) * (t - static_cast<double>(k));
  }
  const double grad = (zf - zb) / (2 * a);
  const double curvature = (zf - 2 * z0 + zb) / (a * a) / std::pow(1 + grad * grad, 1.5);
  if (curvature > 0) step /= std::sqrt(1 + r.radius * curvature);
  return std::max(step, r.min_step);
}

std::vector<double> arrival_field(const ArrivalGrid& g, const std::vector<double>& z,
                                  const std::vector<std::uint8_t>& active, const std::vector<double>& start,
                                  const StepRuleTable& r, const BatchOptions& batch) {
  check_arrival_inputs(g, z, r);
  const std::size_t n = z.size();
  if (active.size() != n || start.size() != n)
    throw std::invalid_argument("arrival field: active and start must have nx * ny entries");
  std::vector<double> T(n, kInf);
  std::vector<std::uint8_t> done(n, 0);
  using Item = std::pair<double, std::size_t>;
  std::priority_queue<Item, std::vector<Item>, std::greater<Item>> heap;
  bool any = false;
  for (std::size_t k = 0; k < n; ++k)
    if (!std::isnan(start[k])) {
      if (!std::isfinite(start[k])) throw std::invalid_argument("arrival field: start values must be finite or NaN");
      T[k] = start[k];
      done[k] = 1;
      any = true;
    }
  if (!any) throw std::invalid_argument("arrival field: the start set is empty");
  const double h = g.cell;

  // the upwind solution at node k from its accepted neighbours, its speed taken along the front's direction
  auto update = [&](int i, int j) {
    const std::size_t k = static_cast<std::size_t>(j) * g.nx + i;
    double tx = kInf, ty = kInf, sx = 0, sy = 0;
    if (i > 0 && done[k - 1] && T[k - 1] < tx) tx = T[k - 1], sx = 1;
    if (i + 1 < g.nx && done[k + 1] && T[k + 1] < tx) tx = T[k + 1], sx = -1;
    if (j > 0 && done[k - g.nx] && T[k - g.nx] < ty) ty = T[k - g.nx], sy = 1;
    if (j + 1 < g.ny && done[k + g.nx] && T[k + g.nx] < ty) ty = T[k + g.nx], sy = -1;
    if (tx == kInf && ty == kInf) return;
    const double x = i * h, y = j * h;
    double ux = sx, uy = sy;  // the first guess: the diagonal of the upwind neighbours (or the one axis)
    if (tx == kInf) ux = 0;
    if (ty == kInf) uy = 0;
    double t = kInf;
    for (int round = 0; round < kDirectionRounds; ++round) {
      const double f = h / arrival_step(g, z, r, x, y, ux, uy);
      const double lo = std::min(tx, ty);
      if (std::abs(tx - ty) >= f) {  // one neighbour only (or the other too far behind to count)
        t = lo + f;
        ux = tx <= ty ? sx : 0;
        uy = tx <= ty ? 0 : sy;
      } else {
        t = 0.5 * (tx + ty + std::sqrt(2 * f * f - (tx - ty) * (tx - ty)));
        ux = sx * (t - tx);
        uy = sy * (t - ty);
      }
    }
    if (t < T[k]) {
      T[k] = t;
      heap.emplace(t, k);
    }
  };
  auto neighbours = [&](std::size_t k) {
    const int i = static_cast<int>(k % g.nx), j = static_cast<int>(k / g.nx);
    const int di[4] = {-1, 1, 0, 0}, dj[4] = {0, 0, -1, 1};
    for (int m = 0; m < 4; ++m) {
      const int a = i + di[m], b = j + dj[m];
      if (a < 0 || b < 0 || a >= g.nx || b >= g.ny) continue;
      const std::size_t q = static_cast<std::size_t>(b) * g.nx + a;
      if (!done[q] && active[q]) update(a, b);
    }
  };
  for (std::size_t k = 0; k < n; ++k)
    if (done[k]) neighbours(k);
  SerialProgress progress(batch.progress);
  std::size_t accepted = 0;
  while (!heap.empty()) {
    const auto [t, k] = heap.top();
    heap.pop();
    if (done[k] || t > T[k]) continue;  // a stale entry
    done[k] = 1;
    neighbours(k);
    progress.tick(static_cast<double>(++accepted) / static_cast<double>(n));
  }
  for (std::size_t k = 0; k < n; ++k)
    if (!done[k]) T[k] = kInf;
  return T;
}

}  // namespace tmm
