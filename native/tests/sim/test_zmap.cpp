// The z-map stock: refusals (before allocating), cell centres, and cells_in at the edges.
#include <gtest/gtest.h>

#include <chrono>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>

#include "tmm/sim/zmap.hpp"

namespace {

using tmm::ZMap;

std::string refusal(double x0, double y0, double cell, std::size_t nx, std::size_t ny, double top,
                    std::size_t max_cells = ZMap::kDefaultMaxCells) {
  try {
    ZMap z(x0, y0, cell, nx, ny, top, max_cells);
  } catch (const std::invalid_argument& e) {
    return e.what();
  }
  return "";
}

TEST(ZMap, RefusesBadParametersNamingThem) {
  const double nan = std::numeric_limits<double>::quiet_NaN(), inf = std::numeric_limits<double>::infinity();
  EXPECT_NE(refusal(nan, 0, 1, 2, 2, 0).find("x0"), std::string::npos);
  EXPECT_NE(refusal(0, inf, 1, 2, 2, 0).find("y0"), std::string::npos);
  EXPECT_NE(refusal(0, 0, 0.0, 2, 2, 0).find("cell"), std::string::npos);
  EXPECT_NE(refusal(0, 0, -1.0, 2, 2, 0).find("cell"), std::string::npos);
  EXPECT_NE(refusal(0, 0, nan, 2, 2, 0).find("cell"), std::string::npos);
  EXPECT_NE(refusal(0, 0, inf, 2, 2, 0).find("cell"), std::string::npos);
  EXPECT_NE(refusal(0, 0, 1, 2, 2, nan).find("top"), std::string::npos);
  EXPECT_NE(refusal(0, 0, 1, 0, 2, 0).find("nx"), std::string::npos);
  EXPECT_NE(refusal(0, 0, 1, 2, 0, 0).find("ny"), std::string::npos);
  EXPECT_NE(refusal(0, 0, 1, 11, 10, 0, 100).find("limit of 100 cells"), std::string::npos);
  EXPECT_EQ(refusal(0, 0, 1, 10, 10, 0, 100), "");  // exactly at the limit is fine
}

TEST(ZMap, LimitIsCheckedBeforeAllocating) {
  // 2^40 cells (8 TiB) and 2^66 cells (overflowing a size_t product): refused at once, with a sane size.
  const auto t0 = std::chrono::steady_clock::now();
  const std::string big = refusal(0, 0, 0.01, std::size_t{1} << 20, std::size_t{1} << 20, 0);
  const std::string huge = refusal(0, 0, 0.01, std::size_t{1} << 33, std::size_t{1} << 33, 0);
  EXPECT_LT(std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count(), 0.5);
  EXPECT_NE(big.find("above the limit"), std::string::npos) << big;
  EXPECT_NE(big.find("8.38861e+06 MiB"), std::string::npos) << big;
  EXPECT_NE(huge.find("above the limit"), std::string::npos) << huge;
  EXPECT_NE(huge.find("5.6295e+14 MiB"), std::string::npos) << huge;  // not a wrapped product
  EXPECT_EQ(ZMap::bytes_for(1000, 1000), 8000000u);
}

TEST(ZMap, CellCentresAndRowMajorStorage) {
  ZMap z(-1.0, 2.0, 0.5, 4, 3, 7.0);
  EXPECT_EQ(z.heights().size(), 12u);
  for (const double h : z.heights()) EXPECT_EQ(h, 7.0);
  EXPECT_DOUBLE_EQ(z.cx(0), -0.75);
  EXPECT_DOUBLE_EQ(z.cx(3), 0.75);
  EXPECT_DOUBLE_EQ(z.cy(2), 3.25);
  z.at(3, 1) = 1.0;
  EXPECT_EQ(z.heights()[1 * 4 + 3], 1.0);
}

TEST(ZMap, CellsInAtTheEdgesAndOutside) {
  const ZMap z(0.0, 0.0, 1.0, 10, 5, 0.0);  // centres 0.5 .. 9.5 by 0.5 .. 4.5
  // Closed box: centres on the boundary count.
  tmm::CellRange r = z.cells_in(0.5, 2.5, 1.5, 1.5);
  EXPECT_EQ(r.i0, 0u);
  EXPECT_EQ(r.i1, 2u);
  EXPECT_EQ(r.j0, 1u);
  EXPECT_EQ(r.j1, 1u);
  // Beyond the grid on every side: clamped to it.
  r = z.cells_in(-100, 100, -3, 30);
  EXPECT_EQ(r.i0, 0u);
  EXPECT_EQ(r.i1, 9u);
  EXPECT_EQ(r.j0, 0u);
  EXPECT_EQ(r.j1, 4u);
  // The last centre exactly, and a box just past it.
  r = z.cells_in(9.5, 12, 4.5, 9);
  EXPECT_EQ(r.i0, 9u);
  EXPECT_EQ(r.j0, 4u);
  EXPECT_FALSE(r.empty());
  EXPECT_TRUE(z.cells_in(9.51, 12, 0, 5).empty());
  EXPECT_TRUE(z.cells_in(-5, 0.49, 0, 5).empty());
  // Between two centres, entirely outside, reversed, not finite.
  EXPECT_TRUE(z.cells_in(3.6, 4.4, 0, 5).empty());
  EXPECT_TRUE(z.cells_in(20, 30, 0, 5).empty());
  EXPECT_TRUE(z.cells_in(0, 10, -9, -1).empty());
  EXPECT_TRUE(z.cells_in(5, 2, 0, 5).empty());
  EXPECT_TRUE(z.cells_in(std::nan(""), 5, 0, 5).empty());
  EXPECT_TRUE(z.cells_in(0, INFINITY, 0, 5).empty());
}

}  // namespace
