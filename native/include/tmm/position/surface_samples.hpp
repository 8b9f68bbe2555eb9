// Samples of a face on a grid per Bezier patch, bucketed in XY: the "rays from the surface" of VCRF and the
// candidates of the gouge check.
#pragma once

#include <Eigen/Core>

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <functional>
#include <vector>

#include "tmm/surface/bezier.hpp"

namespace tmm {

class SerialProgress;

// Dense-enough samples of a surface and an XY bucket grid over them: the "rays from the surface" of VCRF
// and the candidates of the gouge check. Built once per surface and tool.
class SurfaceSamples {
 public:
  // spacing: target distance between samples (mm); cell: XY bucket size (mm). progress(fraction) is
  // called now and then (tmm::SerialProgress); false cancels: throws tmm::Cancelled (millions of samples
  // take a second).
  SurfaceSamples(const PatchSurface& surface, double spacing, double cell,
                 const std::function<bool(double)>& progress = {});
  // The largest number of samples kept: beyond it the spacing is widened (spacing() tells by how much);
  // at most kMaxSide intervals along a patch side (beyond it the side is sampled coarser).
  static constexpr std::size_t kMaxSamples = 4000000;
  static constexpr int kMaxSide = 4000;
  // The spacing the samples take for a requested one: widened by steps of 1.5 until the face needs at
  // most kMaxSamples; *capped: some patch side would need more than kMaxSide intervals.
  static double planned_spacing(const PatchSurface& surface, double spacing, bool* capped = nullptr);
  // The finest spacing, from `spacing` up, that this face is sampled at exactly (no widening, no cap).
  static double finest_spacing(const PatchSurface& surface, double spacing);
  double spacing() const { return spacing_; }
  // Calls f(index) for every sample within XY distance r of (x, y).
  template <class F>
  void within(double x, double y, double r, F&& f) const;
  const std::vector<Vector3d>& points() const { return pts_; }
  const std::vector<Vector2d>& params() const { return uv_; }
  // Parameter step of the sample grid around sample k (half-width of a zoom window).
  Vector2d step(std::size_t k) const { return step_[patch_[k]]; }
  // Calls f(index) for the (up to 4) samples next to k in its patch's grid (across a patch seam: none).
  template <class F>
  void grid_neighbours(std::size_t k, F&& f) const;
  // Whether k lies on the face's outer boundary; and f(index) for its neighbours along that boundary
  // (the face's edge curves sampled in their own right: a minimum of the tool distance there is a minimum
  // on the edge, which the 2D grid neighbourhood does not show).
  bool on_boundary(std::size_t k) const;
  template <class F>
  void boundary_neighbours(std::size_t k, F&& f) const;

 private:
  void build_buckets(const Box3& box, double cell, SerialProgress& progress);
  std::vector<Vector3d> pts_;
  std::vector<Vector2d> uv_;
  std::vector<int> patch_;
  std::vector<Vector2d> step_;
  struct Grid {
    int base = 0, mu = 0, mv = 0;
    bool u0 = false, u1 = false, v0 = false, v1 = false;  // the grid's side lies on the face's boundary
  };
  std::vector<Grid> grid_;  // per patch
  double spacing_ = 1, x0_ = 0, y0_ = 0, cell_ = 1;
  int nx_ = 1, ny_ = 1;
  std::vector<int> start_;   // bucket -> first entry in order_
  std::vector<int> order_;   // sample indices by bucket
};

template <class F>
void SurfaceSamples::within(double x, double y, double r, F&& f) const {
  // Bucket of coordinate t, clamped to [-1, n] before the conversion (NaN: -1, an empty range).
  auto bucket = [](double t, int n) {
    const double b = std::floor(t);
    if (!(b >= -1.0)) return -1;
    return b > n ? n : static_cast<int>(b);
  };
  const int i0 = std::max(0, bucket((x - r - x0_) / cell_, nx_));
  const int i1 = std::min(nx_ - 1, bucket((x + r - x0_) / cell_, nx_));
  const int j0 = std::max(0, bucket((y - r - y0_) / cell_, ny_));
  const int j1 = std::min(ny_ - 1, bucket((y + r - y0_) / cell_, ny_));
  const double r2 = r * r;
  for (int j = j0; j <= j1; ++j) {
    for (int i = i0; i <= i1; ++i) {
      const int b = j * nx_ + i;
      for (int k = start_[b]; k < start_[b + 1]; ++k) {
        const int s = order_[k];
        const double dx = pts_[s].x() - x, dy = pts_[s].y() - y;
        if (dx * dx + dy * dy <= r2) f(static_cast<std::size_t>(s));
      }
    }
  }
}

template <class F>
void SurfaceSamples::grid_neighbours(std::size_t k, F&& f) const {
  const Grid& g = grid_[patch_[k]];
  const int r = static_cast<int>(k) - g.base, a = r / (g.mv + 1), b = r % (g.mv + 1);
  if (a > 0) f(static_cast<std::size_t>(k - (g.mv + 1)));
  if (a < g.mu) f(static_cast<std::size_t>(k + (g.mv + 1)));
  if (b > 0) f(k - 1);
  if (b < g.mv) f(k + 1);
}

inline bool SurfaceSamples::on_boundary(std::size_t k) const {
  const Grid& g = grid_[patch_[k]];
  const int r = static_cast<int>(k) - g.base, a = r / (g.mv + 1), b = r % (g.mv + 1);
  return (g.u0 && a == 0) || (g.u1 && a == g.mu) || (g.v0 && b == 0) || (g.v1 && b == g.mv);
}

template <class F>
void SurfaceSamples::boundary_neighbours(std::size_t k, F&& f) const {
  const Grid& g = grid_[patch_[k]];
  const int r = static_cast<int>(k) - g.base, a = r / (g.mv + 1), b = r % (g.mv + 1);
  if ((g.u0 && a == 0) || (g.u1 && a == g.mu)) {  // along an edge of constant U: neighbours in V
    if (b > 0) f(k - 1);
    if (b < g.mv) f(k + 1);
  }
  if ((g.v0 && b == 0) || (g.v1 && b == g.mv)) {  // along an edge of constant V: neighbours in U
    if (a > 0) f(static_cast<std::size_t>(k - (g.mv + 1)));
    if (a < g.mu) f(static_cast<std::size_t>(k + (g.mv + 1)));
  }
}

}  // namespace tmm
