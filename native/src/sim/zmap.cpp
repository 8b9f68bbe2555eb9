#include "tmm/sim/zmap.hpp"

#include <algorithm>
#include <cmath>
#include <sstream>
#include <stdexcept>

#include "tmm/util/range.hpp"

namespace tmm {

namespace {

[[noreturn]] void refuse(const char* what, double value) {
  std::ostringstream msg;
  msg << "z-map " << what << ", got " << value;
  throw std::invalid_argument(msg.str());
}

}  // namespace

ZMap::ZMap(double x0, double y0, double cell, std::size_t nx, std::size_t ny, double top, std::size_t max_cells)
    : x0_(x0), y0_(y0), cell_(cell), nx_(nx), ny_(ny) {
  if (!std::isfinite(x0)) refuse("x0 must be finite", x0);
  if (!std::isfinite(y0)) refuse("y0 must be finite", y0);
  if (!(std::isfinite(cell) && cell > 0.0)) refuse("cell size must be > 0 mm", cell);
  if (!std::isfinite(top)) refuse("stock top must be finite", top);
  if (nx == 0) refuse("nx must be at least 1", 0.0);
  if (ny == 0) refuse("ny must be at least 1", 0.0);
  require_in_range(x0, "z-map x0");
  require_in_range(y0, "z-map y0");
  require_in_range(top, "z-map stock top");
  require_in_range(x0 + static_cast<double>(nx) * cell, "z-map x0 + nx * cell");
  require_in_range(y0 + static_cast<double>(ny) * cell, "z-map y0 + ny * cell");
  if (nx > max_cells / ny) {
    std::ostringstream msg;
    // In double: the byte count of a grid this large may not fit a size_t.
    const double mib = static_cast<double>(nx) * static_cast<double>(ny) * sizeof(double) / (1 << 20);
    msg << "z-map of " << nx << " x " << ny << " cells (" << mib
        << " MiB) is above the limit of " << max_cells << " cells: use larger cells";
    throw std::invalid_argument(msg.str());
  }
  z_.assign(nx * ny, top);
}

CellRange ZMap::cells_in(double xlo, double xhi, double ylo, double yhi) const {
  CellRange r;
  if (!(std::isfinite(xlo) && std::isfinite(xhi) && std::isfinite(ylo) && std::isfinite(yhi))) return r;
  // centre x0 + (i + 0.5) cell in [xlo, xhi]  <=>  i in [(xlo - x0) / cell - 0.5, (xhi - x0) / cell - 0.5]
  const double ilo = std::ceil((xlo - x0_) / cell_ - 0.5), ihi = std::floor((xhi - x0_) / cell_ - 0.5);
  const double jlo = std::ceil((ylo - y0_) / cell_ - 0.5), jhi = std::floor((yhi - y0_) / cell_ - 0.5);
  const double nx = static_cast<double>(nx_) - 1, ny = static_cast<double>(ny_) - 1;
  if (ihi < 0 || jhi < 0 || ilo > nx || jlo > ny || ilo > ihi || jlo > jhi) return r;
  r.i0 = static_cast<std::size_t>(std::max(0.0, ilo));
  r.i1 = static_cast<std::size_t>(std::min(nx, ihi));
  r.j0 = static_cast<std::size_t>(std::max(0.0, jlo));
  r.j1 = static_cast<std::size_t>(std::min(ny, jhi));
  return r;
}

}  // namespace tmm
