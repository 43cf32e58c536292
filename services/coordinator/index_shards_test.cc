// IndexShards over real index servers in this process: two shards answer
// what one does. Neighbour lists, pair distances and distance rows of a
// collection split over two shards (models sent whole to the shard that does
// not hold them, signatures fetched a block at a time) equal those of the
// same collection on one shard, bit for bit.
#include "services/coordinator/index_shards.h"

#include <atomic>
#include <memory>
#include <random>
#include <string>
#include <vector>

#include "absl/strings/str_cat.h"
#include "gtest/gtest.h"
#include "common/rpc/server.h"
#include "services/index/index_grpc.h"

namespace meshseek {
namespace {

constexpr uint32_t kVocabulary = 64;
constexpr std::size_t kModels = 120;

struct IndexServer {
  std::unique_ptr<IndexService> service;
  std::unique_ptr<IndexGrpc> grpc;
  std::unique_ptr<rpc::RpcServer> server;
};

IndexServer StartIndex(const std::string& dir) {
  IndexServer index;
  index.service = *IndexService::Create({dir, 1});
  rpc::ServerOptions options;
  options.address = "127.0.0.1:0";
  index.grpc = std::make_unique<IndexGrpc>(index.service.get());
  index.server = *rpc::RpcServer::Start("index", {index.grpc.get()}, options);
  return index;
}

// Count histograms: each model near its own region of the vocabulary.
v1::AddModelRequest Model(std::size_t i, std::mt19937* rng) {
  v1::AddModelRequest add;
  add.set_collection("c");
  add.set_model_id(absl::StrCat("m", i));
  add.set_ordinal(i);
  std::vector<int> counts(kVocabulary, 0);
  const std::size_t centre = (*rng)() % kVocabulary;
  for (int d = 0; d < 40; ++d) ++counts[(centre + (*rng)() % 12) % kVocabulary];
  v1::SparseHistogram* h = add.mutable_histogram();
  h->set_size(kVocabulary);
  for (uint32_t k = 0; k < kVocabulary; ++k) {
    if (counts[k] == 0) continue;
    h->add_bins(k);
    h->add_weights(counts[k] / 40.0f);
  }
  return add;
}

class IndexShardsTest : public ::testing::Test {
 protected:
  void SetUp() override {
    const std::string dir = ::testing::TempDir();
    one_ = StartIndex(dir + "/one");
    two_[0] = StartIndex(dir + "/two0");
    two_[1] = StartIndex(dir + "/two1");
    const auto address = [](const IndexServer& s) { return absl::StrCat("127.0.0.1:", s.server->port()); };
    single_ = std::make_unique<IndexShards>(std::vector<std::string>{address(one_)},
                                            rpc::ChannelOptions(), absl::Seconds(30),
                                            rpc::RetryOptions(), &stop_);
    split_ = std::make_unique<IndexShards>(
        std::vector<std::string>{address(two_[0]), address(two_[1])}, rpc::ChannelOptions(),
        absl::Seconds(30), rpc::RetryOptions(), &stop_);
    std::mt19937 rng(7);
    for (std::size_t i = 0; i < kModels; ++i) {
      const v1::AddModelRequest add = Model(i, &rng);
      ids_.push_back(add.model_id());
      ASSERT_TRUE(single_->Add(add).ok());
      ASSERT_TRUE(split_->Add(add).ok());
    }
  }

  std::atomic<bool> stop_{false};
  IndexServer one_;
  IndexServer two_[2];
  std::unique_ptr<IndexShards> single_;
  std::unique_ptr<IndexShards> split_;
  std::vector<std::string> ids_;
  const IndexShards::Part part_{"c", 0.0};
};

TEST_F(IndexShardsTest, NeighboursOfTwoShardsAreThoseOfOne) {
  const std::vector<std::string> queries = {ids_[0], ids_[17], ids_[kModels - 1], ids_[64]};
  const auto one = single_->Neighbors(part_, queries, 9, 0);
  const auto two = split_->Neighbors(part_, queries, 9, 0);
  ASSERT_TRUE(one.ok()) << one.status();
  ASSERT_TRUE(two.ok()) << two.status();
  ASSERT_EQ(one->size(), queries.size());
  ASSERT_EQ(two->size(), queries.size());
  for (std::size_t q = 0; q < queries.size(); ++q) {
    ASSERT_EQ((*one)[q].size(), 9u);
    ASSERT_EQ((*two)[q].size(), 9u);
    EXPECT_EQ((*one)[q][0].model_id, queries[q]);  // itself first, at 0
    EXPECT_EQ((*two)[q][0].model_id, queries[q]);
    for (std::size_t j = 0; j < 9; ++j) EXPECT_EQ((*one)[q][j].distance, (*two)[q][j].distance);
  }
  // Every model, the pair distances of a few targets each.
  std::vector<std::vector<std::string>> targets(queries.size(), {ids_[3], ids_[90], "unknown"});
  const auto pairs_one = single_->PairDistances(part_, queries, targets);
  const auto pairs_two = split_->PairDistances(part_, queries, targets);
  ASSERT_TRUE(pairs_one.ok() && pairs_two.ok()) << pairs_two.status();
  for (std::size_t q = 0; q < queries.size(); ++q) {
    ASSERT_EQ((*pairs_one)[q].size(), 2u);
    ASSERT_EQ((*pairs_two)[q].size(), 2u);
    for (const IndexShards::Scored& a : (*pairs_one)[q]) {
      for (const IndexShards::Scored& b : (*pairs_two)[q]) {
        if (a.model_id == b.model_id) EXPECT_EQ(a.distance, b.distance) << a.model_id;
      }
    }
  }
}

TEST_F(IndexShardsTest, DistanceRowsOfTwoShardsAreThoseOfOne) {
  const std::vector<std::size_t> rows = {0, 5, kModels - 1};
  const auto rows_of = [&](IndexShards* index) {
    std::vector<std::vector<float>> out;
    const absl::Status status = index->ForEachDistanceRow(
        {part_},
        [&](const IndexShards::Row& row) {
          out.emplace_back(row.distances[0].begin(), row.distances[0].end());
          return absl::OkStatus();
        },
        &rows);
    EXPECT_TRUE(status.ok()) << status;
    return out;
  };
  const std::vector<std::vector<float>> one = rows_of(single_.get());
  ASSERT_EQ(one.size(), rows.size());
  EXPECT_EQ(one, rows_of(split_.get()));
  // The rows without signatures: ids, ordinals and labels alone.
  const auto bare = split_->ExportParts({part_}, /*signatures=*/false);
  ASSERT_TRUE(bare.ok()) << bare.status();
  ASSERT_EQ(bare->size(), kModels);
  EXPECT_EQ(bare->models[0][0].model_id(), ids_[0]);
  EXPECT_FALSE(bare->models[0][0].has_histogram());
}

TEST_F(IndexShardsTest, AnUnknownCollectionIsNotFound) {
  const IndexShards::Part unknown{"nothing", 0.0};
  EXPECT_EQ(split_->Neighbors(unknown, {ids_[0]}, 3, 0).status().code(),
            absl::StatusCode::kNotFound);
  EXPECT_EQ(single_->Neighbors(unknown, {ids_[0]}, 3, 0).status().code(),
            absl::StatusCode::kNotFound);
}

}  // namespace
}  // namespace meshseek
