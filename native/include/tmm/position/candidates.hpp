// Choosing a few candidate points, spread out, from many scored samples: the points that Newton then polishes
// (the drop's highest samples, the gouge check's deepest, VCRF's earliest circular rays). Only one point per
// neighbourhood is kept, so one shallow dip cannot crowd out a second, separate one.
#pragma once

#include <Eigen/Core>

#include <cstddef>
#include <utility>
#include <vector>

namespace tmm {

// The K lowest-scoring items of a stream, kept apart: an item closer than sqrt(separation2) to a kept one
// replaces it if lower and is dropped otherwise; a new, apart item takes a free slot or replaces the
// highest kept one if lower. (Order-dependent on purpose: one pass, no sort, K small.)
template <class Item, int K>
class SpreadLowest {
 public:
  struct Entry {
    double score;
    Item item;
    Eigen::Vector3d point;
  };
  explicit SpreadLowest(double separation2) : sep2_(separation2) {}

  void offer(double score, const Item& item, const Eigen::Vector3d& point) {
    for (int i = 0; i < n_; ++i) {
      if ((kept_[i].point - point).squaredNorm() < sep2_) {
        if (score < kept_[i].score) kept_[i] = {score, item, point};
        return;
      }
    }
    if (n_ < K) {
      kept_[n_++] = {score, item, point};
      return;
    }
    int worst = 0;
    for (int i = 1; i < K; ++i)
      if (kept_[i].score > kept_[worst].score) worst = i;
    if (score < kept_[worst].score) kept_[worst] = {score, item, point};
  }
  int size() const { return n_; }
  Entry* begin() { return kept_; }
  Entry* end() { return kept_ + n_; }
  const Entry& operator[](int i) const { return kept_[i]; }

 private:
  double sep2_;
  Entry kept_[K];
  int n_ = 0;
};

// The first (at most) k entries of `ranked` (best first; .second indexes `points`) that lie at least
// sqrt(separation2) from every entry taken before them.
inline std::vector<std::size_t> pick_apart(const std::vector<std::pair<double, std::size_t>>& ranked,
                                           const std::vector<Eigen::Vector3d>& points, double separation2,
                                           std::size_t k) {
  std::vector<std::size_t> chosen;
  for (const auto& r : ranked) {
    bool apart = true;
    for (std::size_t i = 0; i < chosen.size() && apart; ++i)
      apart = (points[chosen[i]] - points[r.second]).squaredNorm() >= separation2;
    if (apart) chosen.push_back(r.second);
    if (chosen.size() == k) break;
  }
  return chosen;
}

}  // namespace tmm
