// Progress and cancel of the mesh phases that take seconds on big meshes (weld, normals, adjacency, the
// drop-cutter index) and of the multipoint positioner's samples: each reports, stops at a cancel, and
// gives the same result with a callback that goes on as without one.
#include <gtest/gtest.h>

#include <cstring>
#include <memory>
#include <random>

#include "support/progress_checks.hpp"
#include "support/seed_patches.hpp"
#include "support/test_meshes.hpp"
#include "tmm/mesh/mesh.hpp"
#include "tmm/mesh/mesh_index.hpp"
#include "tmm/position/multipoint.hpp"

namespace {

using tmm_test::ProgressFn;
using tmm_test::run_reported;

struct Grid {
  tmm::Vertices V;
  tmm::Triangles F;
};

Grid grid(int n) {
  std::mt19937_64 rng(7);
  auto [V, F] = tmm_test::bumpy_grid(n, 5.0, 7.0, rng);
  return {V, F};
}

tmm::Soup soup_of(const Grid& g) {
  tmm::Soup soup(g.F.rows(), 9);
  for (Eigen::Index t = 0; t < g.F.rows(); ++t)
    for (int k = 0; k < 3; ++k) soup.block<1, 3>(t, 3 * k) = g.V.row(g.F(t, k));
  return soup;
}

template <class A, class B>
bool same_bytes(const std::vector<A>& a, const std::vector<B>& b) {
  return a.size() == b.size() && std::memcmp(a.data(), b.data(), a.size() * sizeof(A)) == 0;
}


TEST(MeshCancel, Weld) {
  const tmm::Soup soup = soup_of(grid(60));
  const tmm::Mesh m = run_reported([&](const ProgressFn& p) { return tmm::weld(soup, 1e-6, nullptr, p); });
  const tmm::Mesh plain = tmm::weld(soup, 1e-6);
  EXPECT_EQ(m.V, plain.V);
  EXPECT_EQ(m.F, plain.F);
}

TEST(MeshCancel, FaceAndVertexNormals) {
  const Grid g = grid(60);
  EXPECT_EQ(run_reported([&](const ProgressFn& p) { return tmm::face_normals(g.V, g.F, p); }),
            tmm::face_normals(g.V, g.F));
  for (const auto w : {tmm::NormalWeighting::Angle, tmm::NormalWeighting::Area, tmm::NormalWeighting::Meyer})
    EXPECT_EQ(run_reported([&](const ProgressFn& p) { return tmm::vertex_normals(g.V, g.F, w, p); }),
              tmm::vertex_normals(g.V, g.F, w))
        << tmm::weighting_name(w);
}

TEST(MeshCancel, Adjacency) {
  const Grid g = grid(60);
  EXPECT_EQ(run_reported([&](const ProgressFn& p) { return tmm::triangle_adjacency(g.F, p); }),
            tmm::triangle_adjacency(g.F));
  // Unused vertex numbers: the compacting pass first.
  const tmm::Triangles sparse = g.F * 10;
  EXPECT_EQ(run_reported([&](const ProgressFn& p) { return tmm::triangle_adjacency(sparse, p); }),
            tmm::triangle_adjacency(sparse));
}

TEST(MeshCancel, MeshIndex) {
  const Grid g = grid(60);
  for (const int threads : {1, 2}) {
    const auto index = run_reported([&](const ProgressFn& p) { return tmm::MeshIndex(g.V, g.F, threads, p); });
    const tmm::MeshIndex plain(g.V, g.F, threads);
    EXPECT_TRUE(tmm_test::same_triangles(index.triangles(), plain.triangles()));
    EXPECT_TRUE(same_bytes(index.nodes(), plain.nodes()));
  }
}

// A cancel while the tree is built on two threads (its part of the job, [0.87, 1], reports at once): the
// other thread leaves its half, the build unwinds.
TEST(MeshCancel, MeshIndexStopsWhileTheTreeIsBuiltOnTwoThreads) {
  const Grid g = grid(225);  // 101250 triangles: halves built on two threads (above kParallelBuild)
  ASSERT_GT(g.F.rows(), tmm::MeshIndex::kParallelBuild);
  double last = 0.0;
  EXPECT_THROW(tmm::MeshIndex(g.V, g.F, 2,
                              [&last](double f) {
                                last = f;
                                return f < 0.87;
                              }),
               tmm::Cancelled);
  EXPECT_GE(last, 0.87);  // the nodes are zeroed below 0.87: a report from 0.87 on is a leaf's
  EXPECT_LT(last, 1.0);
}

TEST(MeshCancel, MultipointPositionerSamples) {
  tmm::TorusTool tool;
  tool.Ro = 6.7;
  tool.Ri = 6.0;
  for (const double extend : {0.0, 2.0}) {
    tmm::MultipointOptions o;
    o.extend = extend;
    o.sample_spacing = 1.0;
    const auto mp = run_reported([&](const ProgressFn& p) {
      return std::make_unique<tmm::MultipointPositioner>(tmm_test::seed_patch("convex"), tool, o, p);
    });
    const tmm::MultipointPositioner plain(tmm_test::seed_patch("convex"), tool, o);
    EXPECT_TRUE(same_bytes(mp->samples().points(), plain.samples().points())) << extend;
    EXPECT_EQ(mp->position(75.0, 75.0).tip, plain.position(75.0, 75.0).tip) << extend;
  }
}

}  // namespace
