// The kernel's range (tmm/util/range.hpp): coordinates, heights and radii outside |value| < kMaxCoordinate are
// refused at the entry points, naming the argument, its value and the range, instead of coming back as huge
// heights, NaN normals or out-of-range casts; index values never size an allocation.
#include <gtest/gtest.h>

#include <chrono>
#include <cmath>
#include <functional>
#include <string>
#include <vector>

#include "tmm/cutter/torus_tool.hpp"
#include "tmm/mesh/mesh.hpp"
#include "tmm/mesh/mesh_index.hpp"
#include "tmm/position/surface_samples.hpp"
#include "tmm/query/drop_cutter.hpp"
#include "tmm/sim/sweep5.hpp"
#include "tmm/sim/zmap.hpp"
#include "tmm/surface/bezier.hpp"
#include "tmm/util/range.hpp"

namespace {

void expect_refused(const std::function<void()>& f, const std::string& needle) {
  try {
    f();
    ADD_FAILURE() << "not refused: " << needle;
  } catch (const std::invalid_argument& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find(needle), std::string::npos) << what;
    EXPECT_NE(what.find("outside the kernel's range"), std::string::npos) << what;
    EXPECT_NE(what.find("1e+09"), std::string::npos) << what;
  }
}

tmm::Vertices plate(double scale) {
  tmm::Vertices V(4, 3);
  V << 0, 0, 0, scale, 0, 0, 0, scale, 0, scale, scale, 1;
  return V;
}

tmm::Triangles two_triangles() {
  tmm::Triangles F(2, 3);
  F << 0, 1, 2, 1, 3, 2;
  return F;
}

TEST(KernelRange, TheBoundIsOneConstant) {
  EXPECT_EQ(tmm::kMaxCoordinate, 1e9);
  EXPECT_TRUE(tmm::in_range(-9.99e8));
  EXPECT_FALSE(tmm::in_range(1e9));
  EXPECT_FALSE(tmm::in_range(std::nan("")));
  EXPECT_FALSE(tmm::in_range(-tmm::kInf));
}

TEST(KernelRange, MeshesOutsideAreRefusedNamingTheVertex) {
  for (double scale : {1e150, 1e300, -2e9}) {
    const tmm::Vertices V = plate(scale);
    expect_refused([&] { tmm::MeshIndex(V, two_triangles()); }, "vertex 1 coordinate x = ");
    expect_refused([&] { tmm::face_normals(V, two_triangles()); }, "vertex 1 coordinate x");
    expect_refused([&] { tmm::vertex_normals(V, two_triangles(), tmm::NormalWeighting::Angle); }, "vertex 1");
    tmm::Soup soup(1, 9);
    soup << 0, 0, 0, scale, 0, 0, 0, 1, 0;
    expect_refused([&] { tmm::weld(soup, 1e-6); }, "triangle 0 corner 1 coordinate x");
  }
  tmm::MeshIndex(plate(9e8), two_triangles());  // inside: fine
}

TEST(KernelRange, AdjacencyIsSizedByTheTrianglesNotAnIndexValue) {
  tmm::Triangles F(3, 3);
  F << 0, 1, 2147483647, 1, 0, 7, 2147483647, 5, 6;  // the edge (0, 1) shared, sparse indices
  const auto start = std::chrono::steady_clock::now();
  const tmm::Adjacency A = tmm::triangle_adjacency(F);
  EXPECT_LT(std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count(), 1.0);
  EXPECT_EQ(A(0, 0), 1);
  EXPECT_EQ(A(1, 0), 0);
  EXPECT_EQ(A(0, 1), -1);
  EXPECT_EQ(A(2, 0), -1);
}

TEST(KernelRange, NetsAndBreakpointsOutsideAreRefused) {
  std::vector<Eigen::Vector3d> poles = {{0, 0, 0}, {0, 1, 0}, {1, 0, 0}, {1e300, 1e300, 0}};
  expect_refused([&] { tmm::BezierPatch(1, 1, poles); }, "Bezier pole 3 coordinate x = 1e+300");
  poles[3] = {1, 1, 0};
  expect_refused([&] { tmm::PatchSurface({tmm::BezierPatch(1, 1, poles)}, 1, 1, {0.0, 1e300}, {0.0, 1.0}); },
                 "surface breakpoint u[1]");
}

TEST(KernelRange, AWideFaceOverSmallBucketsKeepsItsBucketCountInRange) {
  // 1.9e9 mm wide over 1e-3 mm buckets: 1.9e12 buckets a side before the coarsening (an int overflow once).
  const std::vector<Eigen::Vector3d> poles = {{-9.5e8, -9.5e8, 0}, {-9.5e8, 9.5e8, 0}, {9.5e8, -9.5e8, 0},
                                              {9.5e8, 9.5e8, 0}};
  const tmm::PatchSurface face(tmm::BezierPatch(1, 1, poles));
  const tmm::SurfaceSamples samples(face, 1e8, 1e-3);
  EXPECT_GT(samples.points().size(), 4u);
}

TEST(KernelRange, ToolsFloorsStocksAndTipsOutsideAreRefused) {
  expect_refused([] { tmm::Cutter(1e10, 0.0); }, "cutter radius = 1e+10");
  expect_refused([] { tmm::Cutter::apt(1.0, 0.0, 1e300, 0.0, 0.0); }, "cutting-edge height = 1e+300");
  tmm::TorusTool tool;
  tool.Ro = 1.0;
  tool.Ri = 1e300;
  expect_refused([&] { tool.validate(); }, "minor radius Ri = 1e+300");
  expect_refused([] { tmm::ZMap(1e300, 0.0, 1.0, 10, 10, 0.0); }, "z-map x0 = 1e+300");
  expect_refused([] { tmm::ZMap(0.0, 0.0, 1e300, 10, 10, 0.0); }, "z-map x0 + nx * cell");
  const tmm::MeshIndex index(plate(10.0), two_triangles());
  const tmm::Cutter ball(1.0, 1.0);
  const double xy[2] = {5.0, 5.0};
  double z = 0.0;
  for (double floor : {std::nan(""), 1e300, -tmm::kInf})
    expect_refused([&] { tmm::drop_batch(index, ball, xy, 1, floor, &z, tmm::BatchOptions{}); }, "floor_z = ");
  tmm::ZMap stock(0.0, 0.0, 1.0, 10, 10, 5.0);
  tool.Ri = 1.0;
  const double tips[6] = {0, 0, 0, 1e150, 0, 0}, axes[6] = {0, 0, 1, 0, 0, 1};
  const tmm::MoveKind kinds[1] = {tmm::MoveKind::Cut};
  expect_refused([&] { tmm::cut_5axis(stock, tool, tips, axes, kinds, 2, {}, {}); }, "tips row 1 (1e+150, 0, 0)");
}

}  // namespace
