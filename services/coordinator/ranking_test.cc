#include "services/coordinator/ranking.h"

#include <gtest/gtest.h>

#include <limits>

#include "common/search/fusion.h"

namespace meshseek {
namespace {

// Three models on a line at 0, 1 and 5, by two methods (the second's
// distances ten times the first's).
RankingState LineState(bool with_graph) {
  RankingState state;
  state.scales = {2.0, 20.0};
  state.model_ids = {"a", "b", "c"};
  state.ordinals = {0, 1, 2};
  state.labels = {"x", "x", "y"};
  if (with_graph) {
    const std::vector<float> d = {0, 0.5f, 2.5f, 0.5f, 0, 2, 2.5f, 2, 0};
    state.graph = *NeighborGraph::FromMatrix(d, 3, 3);
  }
  return state;
}

TEST(RankingStateTest, ReadsBackAndRefusesDamage) {
  for (bool graph : {false, true}) {
    const RankingState state = LineState(graph);
    const std::string bytes = state.Serialize();
    auto back = RankingState::Parse(bytes);
    ASSERT_TRUE(back.ok()) << back.status();
    EXPECT_EQ(back->scales, state.scales);
    EXPECT_EQ(back->model_ids, state.model_ids);
    EXPECT_EQ(back->ordinals, state.ordinals);
    EXPECT_EQ(back->labels, state.labels);
    EXPECT_EQ(back->graph.has_value(), graph);
    for (std::size_t cut : {std::size_t{0}, std::size_t{9}, bytes.size() / 2, bytes.size() - 1}) {
      EXPECT_EQ(RankingState::Parse(bytes.substr(0, cut)).status().code(),
                absl::StatusCode::kDataLoss)
          << cut;
    }
    std::string flipped = bytes;
    flipped[bytes.size() / 2] ^= 4;
    EXPECT_EQ(RankingState::Parse(flipped).status().code(), absl::StatusCode::kDataLoss);
  }
}

TEST(RankingTest, QueriesFuseTheScaledDistancesAndSkipModelsNotInTheBuild) {
  CollectionOptions options =
      CollectionOptions::ForMethods({FeatureMethod::kDldSift, FeatureMethod::kLfd});
  options.weights = {1, 1};
  options.rerank.method = RerankOptions::Method::kNone;
  auto ranking = Ranking::Make("build-1", LineState(false), options);
  ASSERT_TRUE(ranking.ok()) << ranking.status();
  // A query at 4: by each method (distances /2 and /20 of its scale).
  const std::vector<std::vector<IndexShards::Scored>> distances = {
      {{"c", 1.0f}, {"a", 4.0f}, {"b", 3.0f}, {"new", 0.0f}},
      {{"a", 40.0f}, {"b", 30.0f}, {"c", 10.0f}, {"new", 0.0f}}};
  auto top = ranking->Query(distances, options, 5);
  ASSERT_TRUE(top.ok()) << top.status();
  ASSERT_EQ(top->size(), 3u);  // "new" came after the build
  EXPECT_EQ((*top)[0].model_id(), "c");
  EXPECT_FLOAT_EQ((*top)[0].distance(), 0.5f);  // (1/2 + 10/20) / 2
  EXPECT_EQ((*top)[0].label(), "y");
  EXPECT_EQ((*top)[2].model_id(), "a");
  // A model one method no longer answers for (removed) ranks nowhere.
  auto without_b = ranking->Query({{{"a", 4.0f}, {"c", 1.0f}}, distances[1]}, options, 5);
  ASSERT_TRUE(without_b.ok());
  EXPECT_EQ(without_b->size(), 2u);
}

TEST(RankingTest, ReRankedCollectionsNeedTheirGraph) {
  const CollectionOptions options =
      CollectionOptions::ForMethods({FeatureMethod::kDldSift, FeatureMethod::kLfd});
  EXPECT_EQ(Ranking::Make("b", LineState(false), options).status().code(),
            absl::StatusCode::kDataLoss);
  auto ranking = Ranking::Make("b", LineState(true), options);
  ASSERT_TRUE(ranking.ok()) << ranking.status();
  const std::vector<float> a = {0, 1, 5}, b = {0, 10, 50};
  auto row = ranking->RankRow({a, b}, 0u, options);
  ASSERT_TRUE(row.ok()) << row.status();
  EXPECT_EQ((*row)[0], 0.0f);
  EXPECT_LT((*row)[1], (*row)[2]);
  EXPECT_EQ(ranking->RankRow({a, std::vector<float>{0, 1}}, 0u, options).status().code(),
            absl::StatusCode::kFailedPrecondition);
}

// Live ingest: a model joins as the next node, fused with the build's scales,
// its graph changes stored and replayed; then queries rank it.
TEST(RankingTest, AJoinedModelIsTheNextNodeAndReplaysFromItsBytes) {
  const CollectionOptions options =
      CollectionOptions::ForMethods({FeatureMethod::kDldSift, FeatureMethod::kLfd});
  auto ranking = Ranking::Make("b", LineState(true), options);
  ASSERT_TRUE(ranking.ok()) << ranking.status();
  // "d" at 4.5: scaled distances 4.5/2 .. and 45/20 .. to a, b, c.
  const std::vector<std::vector<IndexShards::Scored>> distances = {
      {{"a", 4.5f}, {"b", 3.5f}, {"c", 0.5f}, {"d", 0.0f}},
      {{"a", 45.0f}, {"b", 35.0f}, {"c", 5.0f}, {"d", 0.0f}}};
  auto join = ranking->PlanJoin("d", 7, "y", distances);
  ASSERT_TRUE(join.ok()) << join.status();
  EXPECT_EQ(join->graph.list.front().node, 3u);
  EXPECT_EQ(join->graph.list[1].node, 2u);  // c is nearest
  auto back = RankingJoin::Parse(join->Serialize());
  ASSERT_TRUE(back.ok()) << back.status();
  EXPECT_EQ(back->model_id, "d");
  EXPECT_EQ(back->ordinal, 7u);
  EXPECT_EQ(back->graph.list, join->graph.list);
  EXPECT_EQ(back->graph.entered, join->graph.entered);
  std::string damaged = join->Serialize();
  damaged[6] ^= 1;
  EXPECT_EQ(RankingJoin::Parse(damaged).status().code(), absl::StatusCode::kDataLoss);

  ASSERT_TRUE(ranking->Apply(*back).ok());
  EXPECT_EQ(ranking->PlanJoin("d", 7, "y", distances).status().code(),
            absl::StatusCode::kAlreadyExists);
  EXPECT_EQ(ranking->Apply(*back).code(), absl::StatusCode::kDataLoss);
  EXPECT_EQ(ranking->state.graph->size(), 4u);
  // c's list now holds d (nearer than a).
  EXPECT_EQ(ranking->state.graph->Of(2)[1].node, 3u);
  // Queried with d's own distances, d comes first.
  auto top = ranking->Query(distances, options, 2);
  ASSERT_TRUE(top.ok()) << top.status();
  EXPECT_EQ((*top)[0].model_id(), "d");
  EXPECT_EQ((*top)[0].ordinal(), 7u);
}

}  // namespace
}  // namespace meshseek
