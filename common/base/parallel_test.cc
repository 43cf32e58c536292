#include "common/base/parallel.h"

#include <gtest/gtest.h>

#include <atomic>
#include <vector>

namespace meshseek {
namespace {

TEST(ParallelForTest, VisitsEveryIndexExactlyOnce) {
  for (int threads : {1, 2, 7}) {
    std::vector<std::atomic<int>> hits(1000);
    ParallelFor(hits.size(), threads, [&](std::size_t i) { hits[i]++; });
    for (const auto& h : hits) EXPECT_EQ(h.load(), 1);
  }
}

TEST(ParallelForTest, HandlesEmptyRange) {
  ParallelFor(0, 4, [](std::size_t) { FAIL(); });
}

TEST(ParallelForTest, ResolvesThreadCount) {
  EXPECT_EQ(ResolveThreadCount(3), 3);
  EXPECT_GE(ResolveThreadCount(0), 1);
}

TEST(ParallelForTest, CapsWhatACallAsksForAtTheServers) {
  EXPECT_EQ(CappedThreads(0, 4), 1);
  EXPECT_EQ(CappedThreads(1, 4), 1);
  EXPECT_EQ(CappedThreads(3, 4), 3);
  EXPECT_EQ(CappedThreads(4000000000u, 4), 4);
  EXPECT_EQ(CappedThreads(4000000000u, 0), ResolveThreadCount(0));
}

}  // namespace
}  // namespace meshseek
