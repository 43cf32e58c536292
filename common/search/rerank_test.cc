#include "common/search/rerank.h"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <random>

namespace meshseek {
namespace {

struct Points {
  std::vector<double> x, y;
  std::vector<int> label;
};

// `classes` elongated Gaussian clusters side by side: their tails come closer
// to the next cluster than to their own far end.
Points Clusters(int classes, int per_class, uint32_t seed) {
  std::mt19937 rng(seed);
  std::normal_distribution<double> along(0.0, 2.0), across(0.0, 0.4);
  Points p;
  for (int c = 0; c < classes; ++c) {
    for (int i = 0; i < per_class; ++i) {
      p.x.push_back(along(rng));
      p.y.push_back(2.0 * c + across(rng));
      p.label.push_back(c);
    }
  }
  return p;
}

std::vector<float> Matrix(const Points& p) {
  const std::size_t n = p.x.size();
  std::vector<float> d(n * n);
  for (std::size_t i = 0; i < n; ++i) {
    for (std::size_t j = 0; j < n; ++j) {
      d[i * n + j] = static_cast<float>(std::hypot(p.x[i] - p.x[j], p.y[i] - p.y[j]) / 4.0);
    }
  }
  return d;
}

// Mean fraction of a query's class among its nearest (class size - 1) others.
double FirstTier(const std::vector<float>& d, const std::vector<int>& label) {
  const std::size_t n = label.size();
  double sum = 0;
  for (std::size_t i = 0; i < n; ++i) {
    std::vector<std::pair<float, std::size_t>> row;
    for (std::size_t j = 0; j < n; ++j) {
      if (j != i) row.emplace_back(d[i * n + j], j);
    }
    std::sort(row.begin(), row.end());
    std::size_t size = 0;
    for (int l : label) size += l == label[i];
    std::size_t hits = 0;
    for (std::size_t r = 0; r + 1 < size; ++r) hits += label[row[r].second] == label[i];
    sum += static_cast<double>(hits) / static_cast<double>(size - 1);
  }
  return sum / static_cast<double>(n);
}

TEST(RerankTest, ReciprocalNeighbourhoodsSeparateClustersBetter) {
  const Points p = Clusters(3, 40, 1);
  const std::vector<float> d = Matrix(p);
  RerankOptions options;
  auto graph = NeighborGraph::FromMatrix(d, p.label.size(), options.graph_k());
  ASSERT_TRUE(graph.ok());
  auto reranked = RerankMatrix(*graph, d, options, 2);
  ASSERT_TRUE(reranked.ok()) << reranked.status();
  const double before = FirstTier(d, p.label), after = FirstTier(*reranked, p.label);
  EXPECT_GT(after, before + 0.03) << before << " -> " << after;
}

TEST(RerankTest, EachRowOfTheMatrixIsTheModelQueriedAlone) {
  const Points p = Clusters(3, 25, 2);
  const std::vector<float> d = Matrix(p);
  const std::size_t n = p.label.size();
  RerankOptions options;
  options.k1 = 8;
  options.k2 = 3;
  options.depth = 30;
  auto graph = NeighborGraph::FromMatrix(d, n, options.graph_k());
  ASSERT_TRUE(graph.ok());
  auto matrix = RerankMatrix(*graph, d, options, 2);
  ASSERT_TRUE(matrix.ok());
  for (uint32_t i = 0; i < n; ++i) {
    auto row = RerankRow(*graph, absl::MakeConstSpan(d).subspan(i * n, n), i, options);
    ASSERT_TRUE(row.ok());
    for (std::size_t j = 0; j < n; ++j) ASSERT_EQ((*row)[j], (*matrix)[i * n + j]) << i << " " << j;
    EXPECT_EQ((*row)[i], 0.0f);
  }
}

TEST(RerankTest, AQueryJoiningTheGraphRanksAsIfItHadBeenAModel) {
  // The last point is the query; the collection is the others.
  const Points p = Clusters(2, 30, 3);
  const std::vector<float> all = Matrix(p);
  const std::size_t n = p.label.size() - 1;
  std::vector<float> collection(n * n), query(all.end() - (n + 1), all.end() - 1);
  for (std::size_t i = 0; i < n; ++i) {
    std::copy(all.begin() + i * (n + 1), all.begin() + i * (n + 1) + n, collection.begin() + i * n);
  }
  RerankOptions options;
  options.k1 = 10;
  auto small = NeighborGraph::FromMatrix(collection, n, options.graph_k());
  auto large = NeighborGraph::FromMatrix(all, n + 1, options.graph_k());
  ASSERT_TRUE(small.ok() && large.ok());
  auto joined = RerankRow(*small, query, std::nullopt, options);
  auto member = RerankRow(*large,
                          absl::MakeConstSpan(all).subspan(n * (n + 1), n + 1),
                          static_cast<uint32_t>(n),
                          options);
  ASSERT_TRUE(joined.ok() && member.ok());
  for (std::size_t j = 0; j < n; ++j) EXPECT_EQ((*joined)[j], (*member)[j]) << j;
}

TEST(RerankTest, UnrankableModelsStayLastAndNoneLeavesRowsAlone) {
  const float inf = std::numeric_limits<float>::infinity();
  const std::vector<float> d = {0,
                                0.2f,
                                inf,
                                0.5f,  //
                                0.2f,
                                0,
                                inf,
                                0.4f,
                                inf,
                                inf,
                                0,
                                inf,
                                0.5f,
                                0.4f,
                                inf,
                                0};
  RerankOptions options;
  options.k1 = 2;
  options.k2 = 2;
  auto graph = NeighborGraph::FromMatrix(d, 4, options.graph_k());
  ASSERT_TRUE(graph.ok());
  auto r = RerankMatrix(*graph, d, options);
  ASSERT_TRUE(r.ok());
  EXPECT_EQ((*r)[0 * 4 + 2], inf);
  EXPECT_EQ((*r)[2 * 4 + 2], 0.0f);
  EXPECT_EQ((*r)[2 * 4 + 0], inf);
  EXPECT_LT((*r)[0 * 4 + 1], (*r)[0 * 4 + 3]);
  options.method = RerankOptions::Method::kNone;
  auto none = RerankMatrix(*graph, d, options);
  ASSERT_TRUE(none.ok());
  EXPECT_EQ(*none, d);
}

TEST(RerankTest, BadOptionsAndInputsAreNamed) {
  RerankOptions options;
  EXPECT_TRUE(options.Validate().ok());
  options.k2 = 30;
  EXPECT_NE(options.Validate().message().find("k2 must be in [1, k1 + 1 = 21], got 30"),
            std::string::npos);
  options = RerankOptions();
  options.lambda = 1.5;
  EXPECT_FALSE(options.Validate().ok());
  options = RerankOptions();
  const std::vector<float> d = {0, 1, 1, 0};
  auto graph = NeighborGraph::FromMatrix(d, 2, 2);
  ASSERT_TRUE(graph.ok());
  EXPECT_FALSE(RerankRow(*graph, std::vector<float>{0, 1, 2}, 0u, options).ok());
  EXPECT_FALSE(RerankRow(*graph, std::vector<float>{0, -1}, 0u, options).ok());
  EXPECT_FALSE(RerankRow(*graph, std::vector<float>{0, 1}, 5u, options).ok());
  auto thin = NeighborGraph::FromMatrix(std::vector<float>(25, 1.0f), 5, 2);
  ASSERT_TRUE(thin.ok());
  EXPECT_NE(RerankRow(*thin, std::vector<float>(5, 1.0f), std::nullopt, options)
                .status()
                .message()
                .find("keeps 2 neighbours"),
            std::string::npos);
}

}  // namespace
}  // namespace meshseek
