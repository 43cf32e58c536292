#include "common/search/neighbor_graph.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <limits>
#include <random>

namespace meshseek {
namespace {

// Points on a line: distance |x_i - x_j|.
std::vector<float> LineMatrix(const std::vector<float>& x) {
  const std::size_t n = x.size();
  std::vector<float> d(n * n);
  for (std::size_t i = 0; i < n; ++i) {
    for (std::size_t j = 0; j < n; ++j) d[i * n + j] = std::abs(x[i] - x[j]);
  }
  return d;
}

TEST(NeighborGraphTest, ListsStartWithTheModelThenNearestTiesByNode) {
  // Models 1 and 2 are both 1 from model 0; model 3 coincides with 0.
  const std::vector<float> x = {0, 1, -1, 0, 5};
  auto graph = NeighborGraph::FromMatrix(LineMatrix(x), x.size(), 3, 2);
  ASSERT_TRUE(graph.ok()) << graph.status();
  EXPECT_EQ(graph->k(), 3);
  const auto list0 = graph->Of(0);
  EXPECT_EQ(list0[0], (GraphNeighbor{0, 0.0f}));
  EXPECT_EQ(list0[1], (GraphNeighbor{3, 0.0f}));  // the twin at 0, after itself
  EXPECT_EQ(list0[2], (GraphNeighbor{1, 1.0f}));  // 1 before 2 at the same distance
  const auto list3 = graph->Of(3);
  EXPECT_EQ(list3[0].node, 3u);
  EXPECT_EQ(list3[1].node, 0u);
  EXPECT_EQ(graph->Of(4)[1], (GraphNeighbor{1, 4.0f}));
}

TEST(NeighborGraphTest, ShortCollectionsKeepEveryModelAndInfinityRanksLast) {
  const float inf = std::numeric_limits<float>::infinity();
  const std::vector<float> d = {0,
                                inf,
                                2,  //
                                inf,
                                0,
                                inf,
                                2,
                                inf,
                                0};
  auto graph = NeighborGraph::FromMatrix(d, 3, 10);
  ASSERT_TRUE(graph.ok());
  EXPECT_EQ(graph->k(), 3);
  EXPECT_EQ(graph->Of(0)[1].node, 2u);
  EXPECT_EQ(graph->Of(0)[2], (GraphNeighbor{1, inf}));
}

TEST(NeighborGraphTest, SparseRowsAreTheRowsWithInfinityElsewhere) {
  const float inf = std::numeric_limits<float>::infinity();
  std::mt19937 rng(7);
  for (const std::size_t n : {3, 12, 60}) {
    for (const int k : {1, 5, 21}) {
      auto sparse = NeighborGraph::Create(n, k);
      auto dense = NeighborGraph::Create(n, k);
      ASSERT_TRUE(sparse.ok() && dense.ok());
      for (uint32_t i = 0; i < n; ++i) {
        // A random subset, a tie, an infinite entry and the node itself.
        std::vector<GraphNeighbor> known;
        std::vector<float> row(n, inf);
        for (uint32_t j = 0; j < n; ++j) {
          if (rng() % 3 != 0) continue;
          const float d = j % 7 == 3 ? inf : static_cast<float>(rng() % 5);
          known.push_back({j, d});
          row[j] = d;
        }
        std::shuffle(known.begin(), known.end(), rng);
        sparse->SetSparseRow(i, known);
        dense->SetRow(i, row);
      }
      EXPECT_TRUE(*sparse == *dense) << "n " << n << " k " << k;
    }
  }
}

TEST(NeighborGraphTest, SerializedGraphReadsBackAndDamageIsNamed) {
  std::mt19937 rng(7);
  std::vector<float> x(40);
  for (float& v : x) v = static_cast<float>(rng() % 1000) / 10.0f;
  auto graph = NeighborGraph::FromMatrix(LineMatrix(x), x.size(), 6);
  ASSERT_TRUE(graph.ok());
  const std::string bytes = graph->Serialize();
  auto back = NeighborGraph::Parse(bytes);
  ASSERT_TRUE(back.ok()) << back.status();
  EXPECT_TRUE(*back == *graph);

  for (const std::size_t cut : {std::size_t{0}, std::size_t{10}, bytes.size() - 1}) {
    EXPECT_EQ(NeighborGraph::Parse(bytes.substr(0, cut)).status().code(),
              absl::StatusCode::kDataLoss);
  }
  std::string flipped = bytes;
  flipped[30] ^= 1;
  EXPECT_NE(NeighborGraph::Parse(flipped).status().message().find("checksum"), std::string::npos);
  std::string lying = bytes;
  lying[8] = 41;  // n = 41 for 40 lists
  EXPECT_NE(NeighborGraph::Parse(lying).status().message().find("bytes for 41 lists"),
            std::string::npos);
}

// Nodes joined one by one give the graph built over all of them at once,
// ties (a repeated point) and +inf included.
TEST(NeighborGraphTest, JoinedNodesGiveTheGraphOfTheWholeMatrix) {
  std::mt19937 rng(11);
  std::vector<float> x(60);
  for (float& v : x) v = static_cast<float>(rng() % 200) / 4.0f;
  x[50] = x[3];  // a tie, joined late
  std::vector<float> d = LineMatrix(x);
  const std::size_t n = x.size();
  const float inf = std::numeric_limits<float>::infinity();
  for (std::size_t j = 0; j < n; ++j) {  // model 55 has no features
    if (j != 55) d[55 * n + j] = d[j * n + 55] = inf;
  }
  const std::size_t built = 20;
  {
    // From fewer nodes than k: the lists grow until they reach it.
    auto small = NeighborGraph::FromMatrix({0}, 1, 7, 1);
    ASSERT_TRUE(small.ok());
    for (std::size_t i = 1; i < n; ++i) {
      std::vector<float> row(d.begin() + i * n, d.begin() + i * n + i);
      ASSERT_TRUE(small->ApplyJoin(small->PlanJoin(row, 7)).ok()) << i;
    }
    EXPECT_EQ(small->k(), 7);
    EXPECT_TRUE(*small == *NeighborGraph::FromMatrix(d, n, 7, 1));
  }
  std::vector<float> first;
  for (std::size_t i = 0; i < built; ++i) {
    first.insert(first.end(), d.begin() + i * n, d.begin() + i * n + built);
  }
  auto graph = NeighborGraph::FromMatrix(first, built, 7, 1);
  ASSERT_TRUE(graph.ok());
  for (std::size_t i = built; i < n; ++i) {
    const GraphJoin join = graph->PlanJoin(absl::MakeConstSpan(d.data() + i * n, i), 7);
    ASSERT_TRUE(graph->ApplyJoin(join).ok());
  }
  auto whole = NeighborGraph::FromMatrix(d, n, 7, 1);
  ASSERT_TRUE(whole.ok());
  EXPECT_TRUE(*graph == *whole);
  // Replayed from the serialised graph it round-trips too.
  auto back = NeighborGraph::Parse(graph->Serialize());
  ASSERT_TRUE(back.ok()) << back.status();
  EXPECT_TRUE(*back == *whole);
}

TEST(NeighborGraphTest, AJoinOfAnotherGraphIsRefusedAndChangesNothing) {
  const std::vector<float> x = {0, 1, 2, 3, 4};
  auto graph = NeighborGraph::FromMatrix(LineMatrix(x), x.size(), 3, 1);
  ASSERT_TRUE(graph.ok());
  const NeighborGraph before = *graph;
  GraphJoin join = graph->PlanJoin(std::vector<float>{5, 4, 3, 2, 1}, 3);
  GraphJoin short_list = join;
  short_list.list.pop_back();
  EXPECT_EQ(graph->ApplyJoin(short_list).code(), absl::StatusCode::kInvalidArgument);
  GraphJoin bad_node = join;
  bad_node.entered.push_back(GraphNeighbor{9, 1.0f});
  EXPECT_EQ(graph->ApplyJoin(bad_node).code(), absl::StatusCode::kInvalidArgument);
  EXPECT_TRUE(*graph == before);
  EXPECT_TRUE(graph->ApplyJoin(join).ok());
  EXPECT_EQ(graph->size(), 6u);
  EXPECT_EQ(graph->Of(4)[2], (GraphNeighbor{5, 1.0f}));  // after 3, at the same distance
  EXPECT_FALSE(NeighborGraph().ApplyJoin(join).ok());
}

TEST(NeighborGraphTest, BadInputIsRefused) {
  EXPECT_FALSE(NeighborGraph::Create(10, 0).ok());
  EXPECT_FALSE(NeighborGraph::Create(10, NeighborGraph::kMaxK + 1).ok());
  EXPECT_FALSE(NeighborGraph::FromMatrix(std::vector<float>(5), 2, 2).ok());
  EXPECT_FALSE(NeighborGraph::FromMatrix({0, std::nanf(""), 1, 0}, 2, 2).ok());
  auto empty = NeighborGraph::Create(0, 5);
  ASSERT_TRUE(empty.ok());
  EXPECT_TRUE(NeighborGraph::Parse(empty->Serialize()).ok());
}

}  // namespace
}  // namespace meshseek
