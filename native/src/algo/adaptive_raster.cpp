// Adaptive raster: see the header and tests/core/adaptive_raster_reference.py (the numpy reference, step for step: the
// same samples, the same bracketing, the same search; only the least over a pass's instances is pruned, which
// does not change it).
#include "tmm/algo/adaptive_raster.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <limits>
#include <optional>
#include <sstream>
#include <stdexcept>
#include <string>
#include <utility>

#include "adaptive_envelope.hpp"
#include "tmm/query/drop_cutter.hpp"
#include "tmm/util/constants.hpp"
#include "tmm/util/range.hpp"

namespace tmm {

namespace {

using namespace adaptive_detail;  // NOLINT: the envelope split off from this file

constexpr double kSafety = 0.95;       // aim a little under the tolerance (the reference's _SAFETY)
constexpr int kRounds = 6;             // step evaluations per pass
constexpr double kSpacing = 0.05;      // mm between samples across a section
constexpr int kRidgeHalvings = 12;     // the ridge within a sample spacing / 4096
constexpr int kDense = 8;              // envelope passes between two passes: kDense - 1 of them, then b
constexpr std::size_t kSectionChunk = 8;

void require(bool ok, const std::string& what) {
  if (!ok) throw std::invalid_argument(what);
}

std::string num(double v) {
  std::ostringstream s;
  s << v;
  return s.str();
}

struct Frame {
  double dx, dy, nx, ny;  // along the passes, across them
};

// The part of the line p + t d inside the rectangle (Liang-Barsky; core.footprint.raster.clip_line_to_rect).
bool clip_line(double px, double py, double dx, double dy, const AdaptiveRasterOptions& o,
               std::array<double, 4>& seg) {
  double t0 = -kInf, t1 = kInf;
  const double p[2] = {px, py}, d[2] = {dx, dy};
  const double lo[2] = {o.xmin, o.ymin}, hi[2] = {o.xmax, o.ymax};
  for (int k = 0; k < 2; ++k) {
    if (std::abs(d[k]) < 1e-15) {
      if (p[k] < lo[k] - 1e-9 || p[k] > hi[k] + 1e-9) return false;
      continue;
    }
    const double ta = (lo[k] - p[k]) / d[k], tb = (hi[k] - p[k]) / d[k];
    t0 = std::max(t0, std::min(ta, tb));
    t1 = std::min(t1, std::max(ta, tb));
  }
  if (t1 - t0 <= 1e-9) return false;
  seg = {px + t0 * dx, py + t0 * dy, px + t1 * dx, py + t1 * dy};
  return true;
}

class Placer {
 public:
  Placer(const MeshIndex& index, const Cutter& tool, const Cutter& cutter, const AdaptiveRasterOptions& o,
         const BatchOptions& batch, AdaptiveRasterResult& out)
      : index_(index), tool_(tool), o_(o), h_{cutter, cutter.max_radius()}, out_(out),
        needle_(o.stock_to_leave == 0 ? Cutter(1e-4, 0.0) : Cutter(o.stock_to_leave, o.stock_to_leave)) {
    threads_.threads = batch.threads;
    // a pass's batches report the pass's start (how many evaluations it takes is not known before), so that a
    // long pass can be cancelled within it
    if (batch.progress) threads_.progress = [&outer = batch.progress, this](double) { return outer(at_); };
    frame_ = {std::cos(o.angle), std::sin(o.angle), -std::sin(o.angle), std::cos(o.angle)};
    reach_ = static_cast<long>(std::ceil(h_.r_max / o.sample_step - 1e-9));
  }
  Placer(const Placer&) = delete;  // its batches' progress refers to it
  Placer& operator=(const Placer&) = delete;

  // The pass at `offset` in the turned frame: CL points (x, y, z) rows, or nothing outside the boundary.
  std::optional<std::vector<double>> line(double offset) const {
    std::array<double, 4> seg;
    if (!clip_line(offset * frame_.nx, offset * frame_.ny, frame_.dx, frame_.dy, o_, seg)) return std::nullopt;
    const double sx = seg[0] * frame_.dx + seg[1] * frame_.dy, sy = seg[0] * frame_.nx + seg[1] * frame_.ny;
    const double ex = seg[2] * frame_.dx + seg[3] * frame_.dy, ey = seg[2] * frame_.nx + seg[3] * frame_.ny;
    const double length = std::sqrt((ex - sx) * (ex - sx) + (ey - sy) * (ey - sy));
    const long k = std::max(1L, static_cast<long>(std::ceil(length / o_.sample_step - 1e-9)));
    const double step = 1.0 / static_cast<double>(k);
    std::vector<double> xy(2 * static_cast<std::size_t>(k + 1));
    for (long i = 0; i <= k; ++i) {  // numpy's linspace(0, 1, k + 1): i * (1 / k), the last exactly 1
      const double t = i == k ? 1.0 : static_cast<double>(i) * step;
      xy[2 * i] = sx * (1 - t) + ex * t;
      xy[2 * i + 1] = sy * (1 - t) + ey * t;
    }
    std::vector<double> z(static_cast<std::size_t>(k + 1));
    drop(xy, z);
    std::vector<double> pts(3 * z.size());
    for (std::size_t i = 0; i < z.size(); ++i) {
      pts[3 * i] = xy[2 * i];
      pts[3 * i + 1] = xy[2 * i + 1];
      pts[3 * i + 2] = z[i];
    }
    return pts;
  }

  // Tip heights of the tool at the points: dropped on the design (the stock to leave), never below the floor.
  void drop(const std::vector<double>& xy, std::vector<double>& z) const {
    const double s = o_.stock_to_leave;
    drop_batch(index_, tool_, xy.data(), z.size(), o_.floor_z - s, z.data(), threads_);
    for (double& v : z) v = std::max(v + s, o_.floor_z);
    out_.drops += z.size();
  }

  // Sections across the passes through pass a's CL points (see the header and the reference's Strip).
  void begin_strip(const std::vector<double>& a) {
    const std::size_t n = a.size() / 3;
    x_.resize(n);
    za_.resize(n);
    for (std::size_t i = 0; i < n; ++i) {
      x_[i] = a[3 * i];
      za_[i] = a[3 * i + 2];
    }
    y0_ = a[1];
    const double x0 = *std::min_element(x_.begin(), x_.end()), x1 = *std::max_element(x_.begin(), x_.end());
    const double r = h_.r_max;
    sections_.clear();
    for (std::size_t i = 0; i < n; ++i)  // pass ends: the tool's round end leaves what no next pass changes
      if (!(x1 - x0 > 4 * r) || (x_[i] >= x0 + r && x_[i] <= x1 - r)) sections_.push_back(i);
    const std::size_t S = sections_.size(), K = static_cast<std::size_t>(2 * reach_ + 1);
    near_.resize(S * K);
    dx2_.resize(S * K);
    hdx_.resize(S * K);
    std::vector<std::pair<double, std::size_t>> by_dx(K);
    for (std::size_t s = 0; s < S; ++s) {  // each section's neighbours along the pass, nearest first
      for (std::size_t k = 0; k < K; ++k) {
        const long j = std::clamp(static_cast<long>(sections_[s]) + static_cast<long>(k) - reach_, 0L,
                                  static_cast<long>(n) - 1);
        const double dx = x_[static_cast<std::size_t>(j)] - x_[sections_[s]];
        by_dx[k] = {dx * dx, static_cast<std::size_t>(j)};
      }
      std::stable_sort(by_dx.begin(), by_dx.end(),
                       [](const auto& p, const auto& q) { return p.first < q.first; });
      for (std::size_t k = 0; k < K; ++k) {
        near_[s * K + k] = by_dx[k].second;
        dx2_[s * K + k] = by_dx[k].first;
        hdx_[s * K + k] = h_(std::sqrt(by_dx[k].first));
      }
    }
    // ys as numpy's arange(y0 - r, y0 + s_max + r + spacing, spacing): start + i * delta
    const double start = y0_ - r, stop = y0_ + o_.step_max + r + kSpacing;
    const double delta = (start + kSpacing) - start;
    const auto ny = static_cast<std::size_t>(std::max(0.0, std::ceil((stop - start) / kSpacing)));
    ys_.resize(ny);
    for (std::size_t j = 0; j < ny; ++j) ys_[j] = start + static_cast<double>(j) * delta;
    // the design (the mesh offset by the stock to leave, by a needle's drop), -inf off the model
    // (exactly drop_point's value: the highest contact of the needle over the triangles that may hold it,
    // gathered once per section, sorted along it, instead of a tree walk per sample)
    design_.resize(S * ny);
    const double reach = needle_.max_radius(), floor_d = o_.floor_z - 1.0;
    parallel_chunks(S, kSectionChunk, threads_, [&](std::size_t begin, std::size_t end) {
      std::vector<const IndexedTriangle*> line, active;
      for (std::size_t s = begin; s < end; ++s) {
        const double xs = x_[sections_[s]];
        line.clear();
        index_.near_rect(xs, ys_.front(), xs, ys_.back(), reach, floor_d,
                         [&](const IndexedTriangle& t, int32_t) { line.push_back(&t); });
        std::sort(line.begin(), line.end(),
                  [](const IndexedTriangle* p, const IndexedTriangle* q) { return p->ymin < q->ymin; });
        active.clear();
        std::size_t next = 0;
        const IndexedTriangle* last = nullptr;
        for (std::size_t j = 0; j < ny; ++j) {  // the triangles whose y range holds the sample, sweeping along
          const double y = ys_[j];
          while (next < line.size() && line[next]->ymin - reach <= y) active.push_back(line[next++]);
          active.erase(std::remove_if(active.begin(), active.end(),
                                      [&](const IndexedTriangle* t) { return t->ymax + reach < y; }),
                       active.end());
          double d = floor_d;
          if (last) {  // the previous sample's triangle first: its contact prunes the rest
            const double z = drop_on_triangle(needle_, xs, y, *last, d);
            if (z > d) d = z;
          }
          const IndexedTriangle* won = last;
          for (const IndexedTriangle* t : active) {
            if (t == last || t->zmax <= d) continue;
            const double z = drop_on_triangle(needle_, xs, y, *t, d);
            if (z > d) {
              d = z;
              won = t;
            }
          }
          last = won;
          d += o_.stock_to_leave;
          design_[s * ny + j] = d > o_.floor_z - 0.5 ? d : -kInf;
        }
      }
    });
    out_.drops += S * ny;
    a_.assign(S, {});
    for (std::size_t s = 0; s < S; ++s) gather(za_.data(), near_, dx2_, hdx_, s * K, K, a_[s]);
    // a's surface on the sections: the same for every candidate
    std::vector<Across> at(ny);
    for (std::size_t j = 0; j < ny; ++j) at[j] = across(ys_[j] - y0_, h_);
    pa_.resize(S * ny);
    parallel_chunks(S, kSectionChunk, threads_, [&](std::size_t begin, std::size_t end) {
      for (std::size_t s = begin; s < end; ++s) {
        std::size_t hint = 0;
        for (std::size_t j = 0; j < ny; ++j) pa_[s * ny + j] = lowest(a_[s], at[j], h_, &hint);
      }
    });
    unreachable_ = false;
  }

  // The largest cusp between pass a and a candidate pass at y1 (the reference's Strip.cusp).
  double cusp(double y1) {
    const std::size_t S = sections_.size(), n = x_.size();
    if (!S) return 0.0;
    Candidate c;
    c.y1 = y1;
    while (c.N < ys_.size() && ys_[c.N] <= y1 + h_.r_max + kSpacing) ++c.N;
    const std::size_t N = c.N;
    for (int k = 1; k < kDense; ++k) c.yp[k - 1] = y0_ + (y1 - y0_) * (static_cast<double>(k) / kDense);
    c.yp[kDense - 1] = y1;
    std::vector<double> xy(2 * kDense * n);
    c.z.resize(kDense * n);
    for (int p = 0; p < kDense; ++p)
      for (std::size_t i = 0; i < n; ++i) {
        xy[2 * (p * n + i)] = x_[i];
        xy[2 * (p * n + i) + 1] = c.yp[p];
      }
    drop(xy, c.z);
    c.at.resize(kDense * N);  // b's and the dense passes' dy terms at the samples, for all sections
    for (int p = 0; p < kDense; ++p)
      for (std::size_t j = 0; j < N; ++j) c.at[p * N + j] = across(ys_[j] - c.yp[p], h_);
    std::vector<double> best(S, 0.0);
    std::vector<char> unreach(S, 0);
    parallel_chunks(S, kSectionChunk, threads_, [&](std::size_t begin, std::size_t end) {
      SectionScratch w(N);
      for (std::size_t s = begin; s < end; ++s) {
        envelope(c, s, w);
        bool un = false;
        const double b = sample_cusp(c, s, w, un);
        best[s] = ridge_cusp(c, s, w, b);
        unreach[s] = un;
      }
    });
    unreachable_ = std::any_of(unreach.begin(), unreach.end(), [](char u) { return u != 0; });
    return *std::max_element(best.begin(), best.end());
  }

  bool unreachable() const { return unreachable_; }
  // The fraction of the width placed, reported while the next pass is placed.
  void at(double fraction) { at_ = fraction; }

 private:
  // One candidate pass b at y1: the samples across that matter (N), the dense passes' y (then b's), their
  // CL heights (kDense passes of x_.size() points) and their dy terms at the samples.
  struct Candidate {
    double y1 = 0;
    std::size_t N = 0;
    std::array<double, kDense> yp{};
    std::vector<double> z;
    std::vector<Across> at;
  };
  // One thread's work space over a section: the dense passes (then b) and the profiles across.
  struct SectionScratch {
    explicit SectionScratch(std::size_t N) : pa(N), pb(N), env(N), cosv(N), ok(N) {}
    std::array<std::vector<Instance>, kDense> pass;
    std::vector<double> pa, pb, env, cosv;
    std::vector<char> ok;
  };

  // Section s: a's and b's surfaces across (pa, pb) and the envelope of every pass between (env).
  void envelope(const Candidate& c, std::size_t s, SectionScratch& w) const {
    const std::size_t n = x_.size(), K = static_cast<std::size_t>(2 * reach_ + 1), N = c.N, ny = ys_.size();
    const double y0 = y0_, y1 = c.y1;
    auto& pass = w.pass;
    for (int p = 0; p < kDense; ++p) gather(c.z.data() + p * n, near_, dx2_, hdx_, s * K, K, pass[p]);
    const std::vector<Instance>& B = pass[kDense - 1];
    std::array<std::size_t, kDense> hint{};  // each pass's least at the previous sample
    for (std::size_t j = 0; j < N; ++j) {
      w.pa[j] = pa_[s * ny + j];
      w.pb[j] = lowest(B, c.at[(kDense - 1) * N + j], h_, &hint[kDense - 1]);
      double e = std::min(w.pa[j], w.pb[j]);
      // the dense passes nearest first (the least is the same in any order); one that cannot come lower
      // is skipped
      const double f = (ys_[j] - y0) / (y1 - y0) * kDense - 1;
      const int near = f <= 0 ? 0 : f >= kDense - 2 ? kDense - 2 : static_cast<int>(std::lround(f));
      for (int d = 0; d < kDense - 1; ++d)
        for (int side = 0; side < (d ? 2 : 1); ++side) {
          const int p = side ? near + d : near - d;
          if (p < 0 || p > kDense - 2) continue;
          const Across& ap = c.at[p * N + j];
          if (floor_of(pass[p], ap) < e) e = std::min(e, lowest(pass[p], ap, h_, &hint[p]));
        }
      w.env[j] = e;
    }
  }

  // The cusp on section s's samples (the slope's cosine and which samples count kept in w); un: material
  // out of reach between the two passes' contacts.
  double sample_cusp(const Candidate& c, std::size_t s, SectionScratch& w, bool& un) const {
    const std::size_t N = c.N, ny = ys_.size();
    const double cos_limit = std::cos(o_.max_slope), floor_z = o_.floor_z, tol = o_.cusp;
    const std::vector<double>& pa = w.pa;
    const std::vector<double>& pb = w.pb;
    const std::vector<double>& env = w.env;
    // out of reach only between the two passes' contacts (each one's least height above the design, the
    // first such sample: numpy's argmin): before a's contact the material is the previous pass's
    double ya = ys_[0], yb = ys_[0];
    {
      double ga = kInf, gb = kInf;
      for (std::size_t j = 0; j < N; ++j) {
        const double d = design_[s * ny + j];
        if (!std::isfinite(d)) continue;
        if (std::isfinite(pa[j]) && pa[j] - d < ga) {
          ga = pa[j] - d;
          ya = ys_[j];
        }
        if (std::isfinite(pb[j]) && pb[j] - d < gb) {
          gb = pb[j] - d;
          yb = ys_[j];
        }
      }
    }
    // the slope across (numpy's gradient over the envelope, the floor where nothing reaches)
    auto g = [&](std::size_t j) { return std::isfinite(env[j]) ? env[j] : floor_z; };
    double b = 0.0;
    un = false;
    for (std::size_t j = 0; j < N; ++j) {
      double grad = 0.0;
      if (N >= 2)
        grad = j == 0 ? (g(1) - g(0)) / kSpacing
               : j == N - 1 ? (g(N - 1) - g(N - 2)) / kSpacing
                            : (g(j + 1) - g(j - 1)) / (2.0 * kSpacing);
      w.cosv[j] = 1.0 / std::sqrt(1.0 + grad * grad);
      bool good = std::isfinite(env[j]) && env[j] > floor_z + 1e-6 && w.cosv[j] >= cos_limit;
      const bool reached = (env[j] - design_[s * ny + j]) * w.cosv[j] <= tol;
      if (good && !reached && ys_[j] >= ya && ys_[j] <= yb) un = true;
      good = good && reached;
      w.ok[j] = good;
      if (good) b = std::max(b, (std::min(pa[j], pb[j]) - env[j]) * w.cosv[j]);
    }
    return b;
  }

  // The cusp b on the samples raised by the one at the ridge, where a's and b's surfaces cross: bracketed on
  // the samples (the last where a's is the lower), then halved.
  double ridge_cusp(const Candidate& c, std::size_t s, const SectionScratch& w, double b) const {
    const std::size_t N = c.N;
    const double y0 = y0_, y1 = c.y1;
    const std::vector<Instance>& A = a_[s];
    const std::vector<Instance>& B = w.pass[kDense - 1];
    std::size_t last = 0;
    for (std::size_t j = N; j-- > 0;)
      if (w.pa[j] <= w.pb[j] && std::isfinite(w.pa[j])) {
        last = j;
        break;
      }
    double lo_y = ys_[last], hi_y = ys_[std::min(last + 1, N - 1)];
    for (int it = 0; it < kRidgeHalvings; ++it) {
      const double mid = 0.5 * (lo_y + hi_y);
      if (lowest(A, mid - y0, h_) >= lowest(B, mid - y1, h_)) hi_y = mid;
      else lo_y = mid;
    }
    const double ridge = 0.5 * (lo_y + hi_y);
    const double h_ridge = std::min(lowest(A, ridge - y0, h_), lowest(B, ridge - y1, h_));
    double e_ridge = h_ridge;
    for (int p = 0; p + 1 < kDense; ++p) {
      const Across ap = across(ridge - c.yp[p], h_);
      if (floor_of(w.pass[p], ap) < e_ridge) e_ridge = std::min(e_ridge, lowest(w.pass[p], ap, h_));
    }
    const double cr = std::nearbyint((ridge - ys_[0]) / kSpacing);  // numpy's round: half to even
    const std::size_t col = cr <= 0 ? 0 : std::min(static_cast<std::size_t>(cr), N - 1);
    if (w.ok[col] && std::isfinite(h_ridge) && std::isfinite(e_ridge))
      b = std::max(b, (h_ridge - e_ridge) * w.cosv[col]);
    return b;
  }

  const MeshIndex& index_;
  const Cutter& tool_;
  const AdaptiveRasterOptions& o_;
  Profile h_;
  AdaptiveRasterResult& out_;
  Cutter needle_;
  BatchOptions threads_;
  Frame frame_{};
  long reach_ = 0;
  double at_ = 0.0;
  // the strip of pass a
  std::vector<double> x_, za_, ys_, design_, dx2_, hdx_, pa_;
  std::vector<std::size_t> sections_, near_;
  std::vector<std::vector<Instance>> a_;
  double y0_ = 0;
  bool unreachable_ = false;
};

void validate(const Cutter& cutter, const AdaptiveRasterOptions& o) {
  const bool bounds = std::isfinite(o.xmin) && std::isfinite(o.ymin) && std::isfinite(o.xmax) &&
                      std::isfinite(o.ymax) && o.xmin < o.xmax && o.ymin < o.ymax;
  require(bounds, "adaptive raster boundary must be finite and non-empty, got (" + num(o.xmin) + ", " +
                      num(o.ymin) + ", " + num(o.xmax) + ", " + num(o.ymax) + ")");
  require(std::isfinite(o.angle), "adaptive raster angle must be finite, got " + num(o.angle));
  require(std::isfinite(o.cusp) && o.cusp > 0, "cusp height must be > 0 mm, got " + num(o.cusp));
  require(std::isfinite(o.sample_step) && o.sample_step > 0,
          "sample step must be > 0 mm, got " + num(o.sample_step));
  require(std::isfinite(o.floor_z), "floor must be finite, got " + num(o.floor_z));
  const std::pair<const char*, double> lengths[] = {{"xmin", o.xmin}, {"ymin", o.ymin}, {"xmax", o.xmax},
                                                    {"ymax", o.ymax}, {"floor_z", o.floor_z},
                                                    {"stock_to_leave", o.stock_to_leave}};
  for (const auto& [name, v] : lengths) require_in_range(v, std::string("adaptive raster ") + name);
  require(std::isfinite(o.stock_to_leave) && o.stock_to_leave >= 0,
          "stock to leave must be >= 0 mm, got " + num(o.stock_to_leave));
  require(std::isfinite(o.max_slope) && o.max_slope > 0 && o.max_slope < kPi / 2,
          "adaptive slope limit must be in (0, pi/2) rad, got " + num(o.max_slope));
  require(std::isfinite(o.step_min) && o.step_min > 0 && o.step_min <= o.step_max &&
              o.step_max < 2 * cutter.max_radius(),
          "adaptive steps must satisfy 0 < step_min <= step_max < " + num(2 * cutter.max_radius()) +
              " mm (the tool's width), got " + num(o.step_min) + " and " + num(o.step_max));
}

}  // namespace

AdaptiveRasterWork adaptive_raster_work(const Cutter& cutter, const AdaptiveRasterOptions& o) {
  validate(cutter, o);
  const double c = std::cos(o.angle), s = std::sin(o.angle);
  const double xs[4] = {o.xmin, o.xmax, o.xmax, o.xmin}, ys[4] = {o.ymin, o.ymin, o.ymax, o.ymax};
  double a0 = kInf, a1 = -kInf, l0 = kInf, l1 = -kInf;
  for (int k = 0; k < 4; ++k) {
    const double along = xs[k] * c + ys[k] * s, across = -xs[k] * s + ys[k] * c;
    a0 = std::min(a0, across);
    a1 = std::max(a1, across);
    l0 = std::min(l0, along);
    l1 = std::max(l1, along);
  }
  AdaptiveRasterWork w;
  const double points = (l1 - l0) / o.sample_step + 2;
  w.cl_points = ((a1 - a0) / o.step_min + 2) * points * (kRounds + 1);
  w.section_samples = points * ((o.step_max + 2 * cutter.max_radius()) / kSpacing + 2);
  require(w.section_samples <= static_cast<double>(kMaxAdaptiveSectionSamples),
          "sample step " + num(o.sample_step) + " mm over a " + num(l1 - l0) + " mm long pass gives about " +
              num(w.section_samples) + " section samples per pass, more than the kernel's " +
              num(static_cast<double>(kMaxAdaptiveSectionSamples)) + "; use a coarser sample step or a smaller boundary");
  return w;
}

AdaptiveRasterResult adaptive_raster(const MeshIndex& index, const Cutter& tool, const Cutter& cutter,
                                     const AdaptiveRasterOptions& o, const BatchOptions& batch) {
  adaptive_raster_work(cutter, o);
  AdaptiveRasterResult out;
  Placer placer(index, tool, cutter, o, batch, out);
  const double nx = -std::sin(o.angle), ny = std::cos(o.angle);
  const double cx[4] = {o.xmin, o.xmax, o.xmax, o.xmin}, cy[4] = {o.ymin, o.ymin, o.ymax, o.ymax};
  double lo = kInf, hi = -kInf;
  for (int k = 0; k < 4; ++k) {
    lo = std::min(lo, cx[k] * nx + cy[k] * ny);
    hi = std::max(hi, cx[k] * nx + cy[k] * ny);
  }
  const double s_min = o.step_min, s_max = o.step_max, target = o.cusp * kSafety;
  out.offsets.push_back(lo);
  std::optional<std::vector<double>> prev = placer.line(lo);
  double step = s_max;
  while (out.offsets.back() < hi - 1e-9) {
    const double placed = (out.offsets.back() - lo) / (hi - lo);
    if (batch.progress && !batch.progress(placed)) throw Cancelled();
    placer.at(placed);
    const double base = out.offsets.back();
    if (!prev) {  // the boundary's corner: nothing to measure against
      const double next = std::min(hi, base + s_min);
      out.offsets.push_back(next);
      prev = placer.line(next);
      continue;
    }
    const double room = hi - base;
    placer.begin_strip(*prev);
    double good = 0.0, bad = kInf, good_c = 0.0;  // the largest step within the cusp, the smallest above it
    bool have_good = false;
    double s = std::min({step * 1.2, s_max, room});
    for (int round = 0; round < kRounds; ++round) {
      ++out.evaluations;
      const double c = placer.cusp(base + s);
      if (c <= target) {
        good = s;
        good_c = c;
        have_good = true;
      } else {
        bad = s;
      }
      if (good >= std::min(s_max, room) - 1e-12 || bad <= s_min * (1 + 1e-9) || bad - good < 0.02 * bad) break;
      // the cusp grows about as the step squared: aim at the target, inside the bracket
      double guess = c > 1e-12 ? s * std::sqrt(target / c) * (c > target ? 0.99 : 1.0) : 2 * s;
      if (!(good < guess && guess < bad)) guess = std::isfinite(bad) ? 0.5 * (good + bad) : 2 * s;
      s = std::max(s_min, std::min({guess, s_max, room}));
    }
    if (!have_good) {  // no step within the cusp yet: from the smallest allowed one, halve the bracket
      good = std::min(s_min, room);
      good_c = placer.cusp(base + good);
      ++out.evaluations;
      if (good_c > o.cusp) {
        ++out.limited;  // even the smallest step leaves more: keep it and say so
      } else {
        for (int round = 0; round < kRounds; ++round) {
          if (!std::isfinite(bad) || bad - good < 0.02 * bad) break;
          const double mid = 0.5 * (good + bad);
          const double c = placer.cusp(base + mid);
          ++out.evaluations;
          if (c <= target) {
            good = mid;
            good_c = c;
          } else {
            bad = mid;
          }
        }
      }
    }
    out.unreachable += placer.unreachable() ? 1 : 0;  // as the reference: the last evaluation's
    out.offsets.push_back(base + good);
    out.cusps.push_back(good_c);
    prev = placer.line(base + good);
    step = good;
  }
  return out;
}

}  // namespace tmm
