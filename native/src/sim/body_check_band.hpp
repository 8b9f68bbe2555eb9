// The body check's per-band state (internal to src/sim; the model is in tmm/sim/body_check.hpp): tile bounds of
// the band's heights, the 3-axis check of one move on a scratch copy of the stock, the 5-axis check of one pose.
#pragma once

#include <Eigen/Core>

#include <cstddef>
#include <cstdint>
#include <vector>

#include "tmm/cutter/cutter.hpp"
#include "tmm/query/drop_assembly.hpp"
#include "tmm/sim/body_check.hpp"
#include "tmm/sim/zmap.hpp"

namespace tmm {
namespace body_detail {

constexpr std::size_t kTile = 16;  // cells per side of a tile

// Upper bounds of a band's heights per square tile: heights only fall, so a bound stays one; a tile's bound is
// renewed whenever its cells are read.
class TileBounds {
 public:
  TileBounds(const ZMap& stock, std::size_t j0, std::size_t j1);
  std::size_t tiles_x() const { return tx_; }
  std::size_t tiles_y() const { return ty_; }
  double& bound(std::size_t tx, std::size_t ty) { return max_[ty * tx_ + tx]; }
  // Squared XY distance from (x, y) to the box of the tile's cell centres.
  double dist2(std::size_t tx, std::size_t ty, double x, double y) const;
  // The tile's cells: i in [i0, i1), j in [j0, j1) (rows of the stock).
  void cells(std::size_t tx, std::size_t ty, std::size_t& i0, std::size_t& i1, std::size_t& j0,
             std::size_t& j1) const;
  // The tiles whose box meets [xlo, xhi] x [ylo, yhi] (false if none).
  bool tiles_in(double xlo, double xhi, double ylo, double yhi, std::size_t& t0, std::size_t& t1, std::size_t& u0,
                std::size_t& u1) const;

 private:
  const ZMap& z_;
  std::size_t j0_, j1_, tx_, ty_;
  std::vector<double> max_;
};

// The deepest collision per piece of the current move.
class MoveWorst {
 public:
  explicit MoveWorst(std::size_t pieces) : worst_(pieces) {}
  void start(std::size_t move);
  void offer(std::size_t piece, double x, double y, double z, double depth) {
    BodyCollision& w = worst_[piece];
    if (depth > w.depth) w.x = x, w.y = y, w.z = z, w.depth = depth;
  }
  double depth(std::size_t piece) const { return worst_[piece].depth; }
  // Those deeper than the tolerance appended to out.
  void finish(double tolerance, std::vector<BodyCollision>& out) const;

 private:
  std::vector<BodyCollision> worst_;
};

// 3-axis: one band's check, move by move, before the move is cut into the stock.
class BodyBand3 {
 public:
  BodyBand3(ZMap& stock, const Cutter& cutter, const BodyCheck& check, std::size_t j0, std::size_t j1);
  // The move a -> b (tips) against the stock as it is now; collisions appended to out.
  void move(std::size_t k, const double* a, const double* b, std::vector<BodyCollision>& out);
  // The bodies' reach from the axis (clearance included): the bands a move must visit.
  static double reach(const Cutter& cutter, const BodyCheck& check);

 private:
  double lowest(double d2, std::size_t& owner) const;  // grown bodies' lowest height above the tip, +inf: none
  // Whether a tile at the squared distance near2 from the axis whose cells stand at most `top` above the tip
  // can deepen the move's worst of a piece reaching it (else its cells cannot change the report): each grown
  // piece's lowest point over the tile is at the tile's nearest point (it rises outwards).
  bool may_deepen(double near2, double top) const;
  // Cell c of the stock (j * nx + i, a row of the band) as the move's poses so far left it.
  double read(std::size_t c) const { return gen_[c - off_] == move_gen_ ? scratch_[c - off_] : z_.heights()[c]; }
  void write(std::size_t c, double v) { scratch_[c - off_] = v, gen_[c - off_] = move_gen_; }

  ZMap& z_;
  const Cutter& cutter_;
  const BodyCheck& check_;
  ToolAssembly assembly_;
  std::size_t off_;
  TileBounds tiles_;
  double reach_ = 0, lowest_ = 0, step_ = 0;
  std::vector<double> scratch_;      // the move's stock as its poses leave it (band cells, offset j0 * nx)
  std::vector<std::uint32_t> gen_;   // scratch_[c] holds this move's value when gen_[c] == move_gen_
  std::uint32_t move_gen_ = 0;
  MoveWorst worst_;
  std::vector<std::size_t> candidates_;
};

// 5-axis: one band's check, pose by pose, on the stock as it is.
class BodyBand5 {
 public:
  BodyBand5(ZMap& stock, const BodyCheck& check, std::size_t j0, std::size_t j1);
  void start_move(std::size_t k) { worst_.start(k); }
  void pose(const Eigen::Vector3d& tip, const Eigen::Vector3d& axis);
  void finish_move(std::vector<BodyCollision>& out) const { worst_.finish(check_.tolerance, out); }
  // The y range the bodies' enclosing frusta cover at a pose.
  static void y_range(const BodyCheck& check, const Eigen::Vector3d& tip, const Eigen::Vector3d& axis, double& ylo,
                      double& yhi);

 private:
  ZMap& z_;
  const BodyCheck& check_;
  TileBounds tiles_;
  MoveWorst worst_;
};

}  // namespace body_detail
}  // namespace tmm
