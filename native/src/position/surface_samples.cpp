#include "tmm/position/surface_samples.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <utility>

#include "tmm/util/parallel.hpp"

namespace tmm {

namespace {

// The control polygon lengths of each patch in u and v (they bound the curve lengths), patch by patch.
std::vector<std::pair<double, double>> polygon_lengths(const PatchSurface& surface) {
  std::vector<std::pair<double, double>> lengths;
  for (int i = 0; i < surface.nu(); ++i) {
    for (int j = 0; j < surface.nv(); ++j) {
      const BezierPatch& p = surface.patch(i, j);
      double lu = 0.0, lv = 0.0;
      for (int b = 0; b <= p.degree_v(); ++b) {
        double l = 0.0;
        for (int a = 0; a < p.degree_u(); ++a) l += (p.pole(a + 1, b) - p.pole(a, b)).norm();
        lu = std::max(lu, l);
      }
      for (int a = 0; a <= p.degree_u(); ++a) {
        double l = 0.0;
        for (int b = 0; b < p.degree_v(); ++b) l += (p.pole(a, b + 1) - p.pole(a, b)).norm();
        lv = std::max(lv, l);
      }
      lengths.emplace_back(lu, lv);
    }
  }
  return lengths;
}

// Grid intervals along a patch side of the given length: ceil(length / spacing) within [2, kMaxSide],
// clamped before the conversion (a huge quotient does not fit an int).
int intervals(double length, double spacing, bool* capped) {
  const double n = std::ceil(length / spacing);
  if (n > SurfaceSamples::kMaxSide) {
    *capped = true;
    return SurfaceSamples::kMaxSide;
  }
  return n >= 2.0 ? static_cast<int>(n) : 2;
}

struct Plan {
  double spacing;
  bool capped = false;
  std::vector<std::pair<int, int>> counts;  // per patch
};

// The spacing, widened by steps of 1.5 until the face needs at most kMaxSamples samples.
Plan plan_for(const std::vector<std::pair<double, double>>& lengths, double spacing) {
  Plan plan{spacing, false, {}};
  for (;;) {
    plan.counts.clear();
    plan.capped = false;
    std::size_t total = 0;
    for (const auto& [lu, lv] : lengths) {
      const int mu = intervals(lu, plan.spacing, &plan.capped);
      const int mv = intervals(lv, plan.spacing, &plan.capped);
      plan.counts.emplace_back(mu, mv);
      total += static_cast<std::size_t>(mu + 1) * static_cast<std::size_t>(mv + 1);
    }
    if (total <= SurfaceSamples::kMaxSamples) return plan;
    plan.spacing *= 1.5;
  }
}

}  // namespace

double SurfaceSamples::planned_spacing(const PatchSurface& surface, double spacing, bool* capped) {
  if (!(spacing > 0.0) || !std::isfinite(spacing)) throw std::invalid_argument("sample spacing must be finite and > 0");
  const Plan p = plan_for(polygon_lengths(surface), spacing);
  if (capped) *capped = p.capped;
  return p.spacing;
}

double SurfaceSamples::finest_spacing(const PatchSurface& surface, double spacing) {
  const auto lengths = polygon_lengths(surface);
  double longest = 0.0;
  for (const auto& [lu, lv] : lengths) longest = std::max({longest, lu, lv});
  // Below longest / kMaxSide a side would be capped; a little above it, rounding cannot tip it over.
  return plan_for(lengths, std::max(spacing, longest / (kMaxSide - 1))).spacing;
}

SurfaceSamples::SurfaceSamples(const PatchSurface& surface, double spacing, double cell,
                               const std::function<bool(double)>& progress) {
  if (!(spacing > 0.0) || !std::isfinite(spacing) || !(cell > 0.0) || !std::isfinite(cell))
    throw std::invalid_argument("sample spacing and bucket size must be finite and > 0");
  const Plan plan = plan_for(polygon_lengths(surface), spacing);
  const std::vector<std::pair<int, int>>& counts = plan.counts;
  spacing = plan.spacing;
  spacing_ = spacing;
  std::size_t total = 0;
  for (const auto& [mu, mv] : counts) total += static_cast<std::size_t>(mu + 1) * static_cast<std::size_t>(mv + 1);
  pts_.reserve(total);
  uv_.reserve(total);
  patch_.reserve(total);
  // Parts by their measured share of the time: evaluating the patches is most of it.
  SerialProgress reporter(progress);
  reporter.part(0.0, 0.85);
  Box3 box;
  int k = 0;
  for (int i = 0; i < surface.nu(); ++i) {
    for (int j = 0; j < surface.nv(); ++j, ++k) {
      const auto [mu, mv] = counts[static_cast<std::size_t>(k)];
      const double U0 = surface.breaks_u()[i], U1 = surface.breaks_u()[i + 1];
      const double V0 = surface.breaks_v()[j], V1 = surface.breaks_v()[j + 1];
      step_.emplace_back((U1 - U0) / mu, (V1 - V0) / mv);
      grid_.push_back({static_cast<int>(pts_.size()), mu, mv, i == 0, i == surface.nu() - 1, j == 0,
                       j == surface.nv() - 1});
      const BezierPatch& p = surface.patch(i, j);
      for (int a = 0; a <= mu; ++a) {
        for (int b = 0; b <= mv; ++b) {
          reporter.tick(pts_.size(), total);
          const double u = static_cast<double>(a) / mu, v = static_cast<double>(b) / mv;
          pts_.push_back(p.point(u, v));
          uv_.emplace_back(U0 + u * (U1 - U0), V0 + v * (V1 - V0));
          patch_.push_back(k);
          box.extend(pts_.back());
        }
      }
    }
  }
  reporter.part(0.85, 1.0);
  build_buckets(box, cell, reporter);
  reporter.finish();
}

// The XY bucket grid over the samples of `box`: buckets `cell` wide, coarser for a huge face.
void SurfaceSamples::build_buckets(const Box3& box, double cell, SerialProgress& progress) {
  cell_ = cell;
  x0_ = box.lo.x();
  y0_ = box.lo.y();
  // Bucket counts in double first: a wide face over small buckets does not fit an int.
  const double wx = std::ceil((box.hi.x() - x0_) / cell_) + 1.0, wy = std::ceil((box.hi.y() - y0_) / cell_) + 1.0;
  if (wx * wy > 4e6) {  // huge face, tiny tool: coarser buckets (at most 1001 a side)
    cell_ = std::max(box.hi.x() - x0_, box.hi.y() - y0_) / 1000.0;
    nx_ = static_cast<int>(std::ceil((box.hi.x() - x0_) / cell_)) + 1;
    ny_ = static_cast<int>(std::ceil((box.hi.y() - y0_) / cell_)) + 1;
  } else {
    nx_ = std::max(1, static_cast<int>(wx));
    ny_ = std::max(1, static_cast<int>(wy));
  }
  std::vector<int> bucket(pts_.size());
  start_.assign(static_cast<std::size_t>(nx_ * ny_ + 1), 0);
  for (std::size_t s = 0; s < pts_.size(); ++s) {
    progress.tick(s, 2 * pts_.size());
    // Clamped in double before the cast (a zero-width face divides 0 by 0: bucket 0).
    auto index = [&](double d, int n) { return d > 0.0 ? static_cast<int>(std::min(d / cell_, n - 1.0)) : 0; };
    const int i = index(pts_[s].x() - x0_, nx_), j = index(pts_[s].y() - y0_, ny_);
    bucket[s] = j * nx_ + i;
    ++start_[static_cast<std::size_t>(bucket[s] + 1)];
  }
  for (std::size_t b = 1; b < start_.size(); ++b) start_[b] += start_[b - 1];
  order_.resize(pts_.size());
  std::vector<int> fill(start_.begin(), start_.end() - 1);
  for (std::size_t s = 0; s < pts_.size(); ++s) {
    progress.tick(pts_.size() + s, 2 * pts_.size());
    order_[static_cast<std::size_t>(fill[bucket[s]]++)] = static_cast<int>(s);
  }
}

}  // namespace tmm
