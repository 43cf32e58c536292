// IndexStore: what is written is what is read back, across reopenings; a
// database of the first release (no version, no descriptor column) is
// migrated in place and keeps its models; one of a newer release is refused.
#include "services/index/index_store.h"

#include <filesystem>
#include <map>

#include "gmock/gmock.h"
#include "gtest/gtest.h"
#include "services/index/index_schema.h"

namespace meshseek {
namespace {

using ::testing::HasSubstr;

class IndexStoreTest : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = (std::filesystem::path(::testing::TempDir()) /
            ::testing::UnitTest::GetInstance()->current_test_info()->name())
               .string();
    std::filesystem::remove_all(dir_);
    std::filesystem::create_directories(dir_);
  }
  std::map<std::string, v1::IndexedModel> ReadAll(IndexStore* store) {
    std::map<std::string, v1::IndexedModel> models;
    const absl::Status status =
        store->ForEach([&](const std::string& collection, const v1::IndexedModel& model) {
          models[collection + "/" + model.model_id()] = model;
          return absl::OkStatus();
        });
    EXPECT_TRUE(status.ok()) << status;
    return models;
  }
  std::string dir_;
};

TEST_F(IndexStoreTest, RoundTripsAcrossReopening) {
  v1::IndexedModel histogram;
  histogram.set_model_id("m1");
  histogram.set_ordinal(3);
  histogram.set_label("chair");
  histogram.mutable_histogram()->set_size(8);
  histogram.mutable_histogram()->add_bins(2);
  histogram.mutable_histogram()->add_weights(1.0f);
  v1::IndexedModel descriptor;
  descriptor.set_model_id("m2");
  descriptor.mutable_global_descriptor()->set_method("lfd");
  descriptor.mutable_global_descriptor()->set_data("abc");
  {
    auto store = IndexStore::Open(dir_);
    ASSERT_TRUE(store.ok()) << store.status();
    ASSERT_TRUE((*store)->Upsert("c", histogram).ok());
    ASSERT_TRUE((*store)->Upsert("d", descriptor).ok());
    ASSERT_TRUE((*store)->Upsert("d", descriptor).ok());  // an upsert, not a second row
    ASSERT_TRUE((*store)->Upsert("c", descriptor).ok());
    ASSERT_TRUE((*store)->Remove("c", "m2").ok());
    ASSERT_TRUE((*store)->Remove("c", "never").ok());
  }
  auto store = IndexStore::Open(dir_);
  ASSERT_TRUE(store.ok()) << store.status();
  const auto models = ReadAll(store->get());
  ASSERT_EQ(models.size(), 2u);
  EXPECT_EQ(models.at("c/m1").SerializeAsString(), histogram.SerializeAsString());
  EXPECT_EQ(models.at("d/m2").SerializeAsString(), descriptor.SerializeAsString());
}

TEST_F(IndexStoreTest, MigratesTheFirstReleasesDatabase) {
  {
    auto db = Database::Open(dir_ + "/index.db");
    ASSERT_TRUE(db.ok());
    v1::SparseHistogram histogram;
    histogram.set_size(4);
    ASSERT_TRUE((*db)->Execute("CREATE TABLE models (collection TEXT NOT NULL, model_id TEXT NOT "
                               "NULL, ordinal INTEGER NOT NULL, label TEXT NOT NULL, histogram "
                               "BLOB NOT NULL, PRIMARY KEY (collection, model_id))")
                    .ok());
    auto insert = (*db)->Prepare("INSERT INTO models VALUES ('c', 'old', 0, '', ?)");
    ASSERT_TRUE(insert.ok());
    ASSERT_TRUE(insert->BindBlob(1, histogram.SerializeAsString()).Run().ok());
  }
  auto store = IndexStore::Open(dir_);
  ASSERT_TRUE(store.ok()) << store.status();
  const auto models = ReadAll(store->get());
  ASSERT_EQ(models.size(), 1u);
  EXPECT_EQ(models.at("c/old").histogram().size(), 4u);
  auto db = Database::Open(dir_ + "/index.db");
  ASSERT_TRUE(db.ok());
  EXPECT_EQ(*(*db)->UserVersion(), kIndexSchemaVersion);
}

TEST_F(IndexStoreTest, RefusesANewerSchema) {
  {
    auto db = Database::Open(dir_ + "/index.db");
    ASSERT_TRUE(db.ok());
    ASSERT_TRUE((*db)->SetUserVersion(kIndexSchemaVersion + 1).ok());
  }
  auto store = IndexStore::Open(dir_);
  EXPECT_EQ(store.status().code(), absl::StatusCode::kFailedPrecondition);
  EXPECT_THAT(store.status().message(), HasSubstr("a newer release wrote it"));
}

}  // namespace
}  // namespace meshseek
