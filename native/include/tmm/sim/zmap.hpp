// The stock as the simulator cuts it: a height field over a regular XY grid (a z-map). Cell (i, j) holds
// the height of the stock's top on the vertical line through its centre (x0 + (i + 0.5) cell,
// y0 + (j + 0.5) cell); cutting only ever lowers a cell. Row-major: index j * nx + i.
#pragma once

#include <cstddef>
#include <vector>

namespace tmm {

struct CellRange {  // cells i0..i1, j0..j1 inclusive; empty when i0 > i1 or j0 > j1
  std::size_t i0 = 1, i1 = 0, j0 = 1, j1 = 0;
  bool empty() const { return i0 > i1 || j0 > j1; }
};

class ZMap {
 public:
  // Throws std::invalid_argument naming the parameter: x0, y0, top not finite; cell not > 0 and finite;
  // nx or ny = 0; nx * ny above max_cells (the size is checked before anything is allocated).
  ZMap(double x0, double y0, double cell, std::size_t nx, std::size_t ny, double top,
       std::size_t max_cells = kDefaultMaxCells);

  static constexpr std::size_t kDefaultMaxCells = std::size_t{1} << 28;  // 268M cells, 2 GiB of heights
  // Bytes a grid of nx x ny cells takes (for estimates before allocating).
  static std::size_t bytes_for(std::size_t nx, std::size_t ny) { return nx * ny * sizeof(double); }

  double x0() const { return x0_; }
  double y0() const { return y0_; }
  double cell() const { return cell_; }
  std::size_t nx() const { return nx_; }
  std::size_t ny() const { return ny_; }
  double cx(std::size_t i) const { return x0_ + (static_cast<double>(i) + 0.5) * cell_; }
  double cy(std::size_t j) const { return y0_ + (static_cast<double>(j) + 0.5) * cell_; }
  double& at(std::size_t i, std::size_t j) { return z_[j * nx_ + i]; }
  double at(std::size_t i, std::size_t j) const { return z_[j * nx_ + i]; }
  std::vector<double>& heights() { return z_; }
  const std::vector<double>& heights() const { return z_; }
  // The cells whose centres lie in the closed box [xlo, xhi] x [ylo, yhi] (empty if none or not finite).
  CellRange cells_in(double xlo, double xhi, double ylo, double yhi) const;

 private:
  double x0_, y0_, cell_;
  std::size_t nx_, ny_;
  std::vector<double> z_;
};

}  // namespace tmm
