// The index service's handlers called as functions, with no gRPC server:
// what a client sends in, what it gets back, the errors by code and message,
// and what survives a restart (a new service on the same folder). The same
// service over real binaries, under kills, is tests/services_test.cc.
#include "services/index/index_service.h"

#include <filesystem>
#include <string>
#include <vector>

#include "gmock/gmock.h"
#include "gtest/gtest.h"

namespace meshseek {
namespace {

using ::testing::HasSubstr;

const rpc::CallContext kInProcess(nullptr);

v1::AddModelRequest Add(const std::string& id, uint64_t ordinal, std::vector<uint32_t> words) {
  v1::AddModelRequest request;
  request.set_collection("c");
  request.set_model_id(id);
  request.set_ordinal(ordinal);
  request.set_label(ordinal % 2 == 0 ? "even" : "odd");
  v1::SparseHistogram& h = *request.mutable_histogram();
  h.set_size(8);
  for (uint32_t w : words) {
    h.add_bins(w);
    h.add_weights(1.0f / static_cast<float>(words.size()));
  }
  return request;
}

v1::SearchRequest Search(std::vector<uint32_t> words, uint32_t top_k) {
  v1::SearchRequest request;
  request.set_collection("c");
  *request.mutable_histogram() = Add("query", 0, std::move(words)).histogram();
  request.set_top_k(top_k);
  request.set_kl_epsilon(1e-10);
  return request;
}

class IndexServiceTest : public ::testing::Test {
 protected:
  void SetUp() override {
    options_.data_dir = (std::filesystem::path(::testing::TempDir()) /
                         ::testing::UnitTest::GetInstance()->current_test_info()->name())
                            .string();
    std::filesystem::remove_all(options_.data_dir);
    options_.num_threads = 1;
  }
  std::unique_ptr<IndexService> Start() {
    absl::StatusOr<std::unique_ptr<IndexService>> service = IndexService::Create(options_);
    EXPECT_TRUE(service.ok()) << service.status();
    return service.ok() ? *std::move(service) : nullptr;
  }
  IndexServiceOptions options_;
};

TEST_F(IndexServiceTest, AddedModelsAreSearchedRemovedAndKeptAcrossARestart) {
  {
    auto index = Start();
    ASSERT_NE(index, nullptr);
    EXPECT_EQ(index->AddModel(Add("a", 0, {1, 2}), kInProcess)->collection_size(), 1u);
    EXPECT_EQ(index->AddModel(Add("b", 1, {1, 3}), kInProcess)->collection_size(), 2u);
    EXPECT_EQ(index->AddModel(Add("c", 2, {5, 6}), kInProcess)->collection_size(), 3u);
    const absl::StatusOr<v1::SearchResponse> found = index->Search(Search({1, 2}, 2), kInProcess);
    ASSERT_TRUE(found.ok()) << found.status();
    ASSERT_EQ(found->results_size(), 2);
    EXPECT_EQ(found->results(0).model_id(), "a");
    EXPECT_EQ(found->results(0).distance(), 0.0f);
    EXPECT_EQ(found->results(1).model_id(), "b");
    v1::RemoveModelRequest remove;
    remove.set_collection("c");
    remove.set_model_id("b");
    EXPECT_TRUE(index->RemoveModel(remove, kInProcess)->removed());
    EXPECT_FALSE(index->RemoveModel(remove, kInProcess)->removed());
  }
  auto index = Start();  // the same folder: what was acknowledged is there
  ASSERT_NE(index, nullptr);
  v1::ListModelsRequest list;
  list.set_collection("c");
  const absl::StatusOr<v1::ListModelsResponse> models = index->ListModels(list, kInProcess);
  ASSERT_TRUE(models.ok()) << models.status();
  EXPECT_THAT(std::vector<std::string>(models->model_ids().begin(), models->model_ids().end()),
              ::testing::ElementsAre("a", "c"));
}

TEST_F(IndexServiceTest, BadRequestsAreRefusedWithTheirCodeAndWhatIsWrong) {
  auto index = Start();
  ASSERT_NE(index, nullptr);
  ASSERT_TRUE(index->AddModel(Add("a", 0, {1, 2}), kInProcess).ok());
  // Another vocabulary size than the collection's.
  v1::AddModelRequest other = Add("b", 1, {1});
  other.mutable_histogram()->set_size(16);
  const absl::Status misfit = index->AddModel(other, kInProcess).status();
  EXPECT_EQ(misfit.code(), absl::StatusCode::kInvalidArgument);
  EXPECT_THAT(misfit.message(), HasSubstr("16"));
  // Weights that do not sum to 1.
  v1::AddModelRequest unnormalised = Add("b", 1, {1, 2});
  unnormalised.mutable_histogram()->set_weights(0, 0.9f);
  EXPECT_EQ(index->AddModel(unnormalised, kInProcess).status().code(),
            absl::StatusCode::kInvalidArgument);
  // top_k 0, and a collection that does not exist.
  EXPECT_EQ(index->Search(Search({1}, 0), kInProcess).status().code(),
            absl::StatusCode::kInvalidArgument);
  v1::SearchRequest elsewhere = Search({1}, 1);
  elsewhere.set_collection("nowhere");
  const absl::Status missing = index->Search(elsewhere, kInProcess).status();
  EXPECT_EQ(missing.code(), absl::StatusCode::kNotFound);
  EXPECT_THAT(missing.message(), HasSubstr("nowhere"));
}

}  // namespace
}  // namespace meshseek
