// The index build: its thread count option, and a tree independent of it.
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <stdexcept>

#include "support/test_meshes.hpp"
#include "tmm/mesh/mesh_index.hpp"

namespace {

// An n x n grid of squares, two triangles each, over a wavy height field.
void wavy_grid(int n, tmm::Vertices* V, tmm::Triangles* F) {
  V->resize((n + 1) * (n + 1), 3);
  F->resize(2 * n * n, 3);
  for (int i = 0; i <= n; ++i)
    for (int j = 0; j <= n; ++j) V->row(i * (n + 1) + j) << i, j, std::sin(0.1 * i) * std::cos(0.07 * j);
  int t = 0;
  for (int i = 0; i < n; ++i) {
    for (int j = 0; j < n; ++j) {
      const int a = i * (n + 1) + j, b = a + 1, c = a + n + 1, d = c + 1;
      F->row(t++) << a, b, d;
      F->row(t++) << a, d, c;
    }
  }
}

TEST(MeshIndexBuild, UsesTheThreadsAskedForAndBuildsTheSameTree) {
  tmm::Vertices V;
  tmm::Triangles F;
  wavy_grid(320, &V, &F);  // 204800 triangles: halves of 102400 above kParallelBuild, quarters below
  ASSERT_GT(F.rows(), 2 * tmm::MeshIndex::kParallelBuild);
  ASSERT_LT(F.rows(), 4 * tmm::MeshIndex::kParallelBuild);
  const tmm::MeshIndex one(V, F, 1), two(V, F, 2), many(V, F, 8);
  EXPECT_EQ(one.build_threads(), 1);
  EXPECT_EQ(two.build_threads(), 2);
  EXPECT_EQ(many.build_threads(), 4);  // the quarters are too small to split again
  for (const tmm::MeshIndex* other : {&two, &many}) {
    ASSERT_EQ(other->nodes().size(), one.nodes().size());
    EXPECT_EQ(std::memcmp(other->nodes().data(), one.nodes().data(), one.nodes().size() * sizeof(tmm::BvhNode)), 0);
    EXPECT_TRUE(tmm_test::same_triangles(other->triangles(), one.triangles()));
  }
}

TEST(MeshIndexBuild, SmallMeshesBuildOnOneThreadAndNegativeThreadsAreRefused) {
  tmm::Vertices V;
  tmm::Triangles F;
  wavy_grid(20, &V, &F);
  EXPECT_EQ(tmm::MeshIndex(V, F, 0).build_threads(), 1);
  EXPECT_EQ(tmm::MeshIndex(V, F, 4).build_threads(), 1);
  try {
    tmm::MeshIndex(V, F, -1);
    FAIL() << "threads -1 accepted";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("threads must be >= 0"), std::string::npos) << e.what();
  }
}

}  // namespace
