// The threads a batch takes when its caller names none: TMM_THREADS (a batch worker's one core), else all.
#include <gtest/gtest.h>

#include <cstdlib>
#include <thread>
#include <vector>
#include <algorithm>

#include "tmm/util/parallel.hpp"

namespace {

int hardware() { return static_cast<int>(std::max(1u, std::thread::hardware_concurrency())); }

TEST(DefaultThreads, NamedByTheEnvironmentWithinTheHardware) {
  ::unsetenv("TMM_THREADS");
  EXPECT_EQ(tmm::default_threads(), hardware());
  ::setenv("TMM_THREADS", "1", 1);
  EXPECT_EQ(tmm::default_threads(), 1);
  ::setenv("TMM_THREADS", "100000", 1);
  EXPECT_EQ(tmm::default_threads(), hardware());
  for (const char* bad : {"0", "-2", "two", "1x", ""}) {
    ::setenv("TMM_THREADS", bad, 1);
    EXPECT_EQ(tmm::default_threads(), hardware()) << bad;
  }
  ::unsetenv("TMM_THREADS");
}

TEST(DefaultThreads, OneThreadBatchRunsEveryChunkOnce) {
  ::setenv("TMM_THREADS", "1", 1);
  std::vector<int> hits(1000, 0);
  tmm::parallel_chunks(hits.size(), 7, tmm::BatchOptions{}, [&](std::size_t b, std::size_t e, tmm::ChunkContext&) {
    for (std::size_t i = b; i < e; ++i) ++hits[i];
  });
  ::unsetenv("TMM_THREADS");
  for (int h : hits) ASSERT_EQ(h, 1);
}

}  // namespace
