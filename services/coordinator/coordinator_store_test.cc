#include "services/coordinator/coordinator_store.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <filesystem>

#include "absl/time/clock.h"
#include "common/base/hash.h"
#include "common/pipeline/retrieval_pipeline.h"
#include "common/wire/convert.h"
#include "common/store/sqlite_db.h"
#include "services/coordinator/workers.h"

namespace meshseek {
namespace {

using ::testing::ElementsAre;
using ::testing::HasSubstr;

class CoordinatorStoreTest : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = std::filesystem::path(::testing::TempDir()) /
           ::testing::UnitTest::GetInstance()->current_test_info()->name();
    std::filesystem::remove_all(dir_);
    std::filesystem::create_directories(dir_);
  }
  std::unique_ptr<CoordinatorStore> OpenStore(int shards = 1) {
    auto store = CoordinatorStore::Open(dir_.string(), shards);
    EXPECT_TRUE(store.ok()) << store.status();
    return store.ok() ? *std::move(store) : nullptr;
  }
  std::filesystem::path dir_;
};

v1::PipelineParams Params() {
  v1::PipelineParams params;
  params.set_method(v1::FEATURE_METHOD_DLD);
  return params;
}

TEST_F(CoordinatorStoreTest, NewDatabaseHasTheCurrentSchemaVersion) {
  ASSERT_NE(OpenStore(), nullptr);
  auto db = Database::Open((dir_ / "coordinator.db").string());
  ASSERT_TRUE(db.ok());
  EXPECT_EQ((*db)->UserVersion().value(), kCoordinatorSchemaVersion);
}

TEST_F(CoordinatorStoreTest, RefusesANewerSchemaAndAnotherShardCount) {
  ASSERT_NE(OpenStore(2), nullptr);
  auto other = CoordinatorStore::Open(dir_.string(), 3);
  EXPECT_EQ(other.status().code(), absl::StatusCode::kFailedPrecondition);
  EXPECT_THAT(other.status().message(), HasSubstr("2 index shards, --index lists 3"));
  {
    auto db = Database::Open((dir_ / "coordinator.db").string());
    ASSERT_TRUE((*db)->SetUserVersion(kCoordinatorSchemaVersion + 1).ok());
  }
  auto newer = CoordinatorStore::Open(dir_.string(), 2);
  EXPECT_EQ(newer.status().code(), absl::StatusCode::kFailedPrecondition);
  EXPECT_THAT(newer.status().message(),
              HasSubstr(absl::StrCat("schema version ", kCoordinatorSchemaVersion + 1)));
}

TEST_F(CoordinatorStoreTest, SameModelAgainIsAcknowledgedAnotherIsRefused) {
  auto store = OpenStore();
  ASSERT_TRUE(store->CreateCollections({{"c", Params()}}).ok());
  EXPECT_TRUE(store->CreateCollections({{"c", Params()}}).ok());
  v1::PipelineParams other = Params();
  other.set_method(v1::FEATURE_METHOD_RLD);
  EXPECT_EQ(store->CreateCollections({{"c", other}}).code(), absl::StatusCode::kAlreadyExists);
  const std::string job = store->NewJob("ingest", "c", 0).value();
  EXPECT_EQ(job, "ingest-1");
  auto first = store->AddModel({"c"}, "m", "cat", "mesh bytes", job);
  ASSERT_TRUE(first.ok());
  EXPECT_TRUE(first->created);
  auto again = store->AddModel({"c"}, "m", "cat", "mesh bytes", "ingest-2");
  ASSERT_TRUE(again.ok());
  EXPECT_FALSE(again->created);
  EXPECT_EQ(again->job_id, job);
  EXPECT_EQ(store->AddModel({"c"}, "m", "dog", "mesh bytes", job).status().code(),
            absl::StatusCode::kAlreadyExists);
  EXPECT_EQ(store->AddModel({"c"}, "m", "cat", "other bytes", job).status().code(),
            absl::StatusCode::kAlreadyExists);
}

// Features live from the extraction that ends a model until DropFeatures
// (or its removal); a late extraction of a model no longer pending writes
// none.
TEST_F(CoordinatorStoreTest, KeepsFeaturesFromExtractionUntilIndexed) {
  auto store = OpenStore();
  ASSERT_TRUE(store->CreateCollections({{"c", Params()}}).ok());
  const std::string job = store->NewJob("ingest", "c", 0).value();
  for (const char* id : {"a", "b", "r"}) ASSERT_TRUE(store->AddModel({"c"}, id, "", id, job).ok());
  EXPECT_EQ(store->LoadFeatures({"c", "a"}), std::nullopt);  // pending: none yet
  ASSERT_TRUE(store->MarkExtracted({"c", "a"}, "features of a", 1).value());
  ASSERT_TRUE(store->MarkExtracted({"c", "b"}, "features of b", 1).value());
  EXPECT_FALSE(store->MarkExtracted({"c", "a"}, "a late copy", 1).value());
  EXPECT_EQ(store->LoadFeatures({"c", "a"}), "features of a");
  ASSERT_TRUE(store->RemoveModel({"c", "r"}).ok());
  EXPECT_FALSE(store->MarkExtracted({"c", "r"}, "of a removed model", 1).value());
  EXPECT_EQ(store->LoadFeatures({"c", "r"}), std::nullopt);
  // Only models indexed by the build lose theirs.
  ASSERT_TRUE(store->MarkIndexed({"c", "a"}, "c@build-2").ok());
  ASSERT_TRUE(store->DropFeatures({"c"}, "build-2").ok());
  EXPECT_EQ(store->LoadFeatures({"c", "a"}), std::nullopt);
  EXPECT_EQ(store->LoadFeatures({"c", "b"}), "features of b");
  ASSERT_TRUE(store->RemoveModel({"c", "b"}).ok());
  EXPECT_EQ(store->LoadFeatures({"c", "b"}), std::nullopt);
  std::size_t files = 0;
  for (const auto& entry : std::filesystem::recursive_directory_iterator(dir_ / "features")) {
    files += entry.is_regular_file();
  }
  EXPECT_EQ(files, 0u);
}

TEST_F(CoordinatorStoreTest, IngestJobFinishesWhenItsLastModelEndsNotWhenRead) {
  auto store = OpenStore();
  ASSERT_TRUE(store->CreateCollections({{"c", Params()}}).ok());
  const std::string job = store->NewJob("ingest", "c", 0).value();
  ASSERT_TRUE(store->AddModel({"c"}, "a", "", "A", job).ok());
  ASSERT_TRUE(store->AddModel({"c"}, "b", "", "B", job).ok());
  EXPECT_EQ(store->PendingCount(), 2u);
  ASSERT_TRUE(store->CloseIngestStream(job).ok());
  EXPECT_EQ(store->GetJob(job)->state(), v1::JOB_STATE_RUNNING);
  EXPECT_TRUE(store->MarkExtracted({"c", "a"}, "", 7).value());
  EXPECT_FALSE(store->MarkExtracted({"c", "a"}, "", 7).value());  // no longer pending
  EXPECT_EQ(store->GetJob(job)->state(), v1::JOB_STATE_RUNNING);
  EXPECT_TRUE(store->MarkFailed({"c", "b"}, 1, "INVALID_ARGUMENT: no faces").value());
  const v1::JobStatus status = store->GetJob(job).value();
  EXPECT_EQ(status.state(), v1::JOB_STATE_FAILED);
  EXPECT_EQ(status.message(), "1 of 2 models failed");
  EXPECT_EQ(status.total(), 2u);
  EXPECT_EQ(status.done(), 2u);
  EXPECT_EQ(status.failed(), 1u);
  EXPECT_THAT(status.errors(), ElementsAre("model b: INVALID_ARGUMENT: no faces"));
  const ModelCounts counts = store->CountModels({"c"}, "").value();
  EXPECT_EQ(counts.models, 2u);
  EXPECT_EQ(counts.extracted, 1u);
  EXPECT_EQ(counts.failed, 1u);
  EXPECT_EQ(counts.pending, 0u);
}

TEST_F(CoordinatorStoreTest, RemovingTheLastPendingModelFinishesItsJob) {
  auto store = OpenStore();
  ASSERT_TRUE(store->CreateCollections({{"c", Params()}}).ok());
  const std::string job = store->NewJob("ingest", "c", 0).value();
  ASSERT_TRUE(store->AddModel({"c"}, "a", "", "A", job).ok());
  ASSERT_TRUE(store->CloseIngestStream(job).ok());
  EXPECT_EQ(store->RemoveModel({"c", "a"}).value(), ModelState::kPending);
  EXPECT_EQ(store->RemoveModel({"c", "a"}).value(), std::nullopt);
  EXPECT_EQ(store->GetJob(job)->state(), v1::JOB_STATE_SUCCEEDED);
}

TEST_F(CoordinatorStoreTest, ModelsInBackoffAreClaimedOnlyWhenDue) {
  auto store = OpenStore();
  ASSERT_TRUE(store->CreateCollections({{"c", Params()}}).ok());
  const std::string job = store->NewJob("ingest", "c", 0).value();
  for (const char* id : {"a", "b", "c"}) ASSERT_TRUE(store->AddModel({"c"}, id, "", id, job).ok());
  const absl::Time now = absl::Now();
  ASSERT_TRUE(store->ScheduleRetry({"c", "a"}, 1, now + absl::Seconds(30), "UNAVAILABLE").ok());
  auto claimable = store->ClaimablePending(now, {{"c", "b"}}, 5).value();
  EXPECT_THAT(claimable, ElementsAre(ModelKey{"c", "c"}));
  EXPECT_EQ(store->NextRetry(now).value(), absl::FromUnixMicros(absl::ToUnixMicros(now + absl::Seconds(30))));
  claimable = store->ClaimablePending(now + absl::Seconds(31), {}, 5).value();
  EXPECT_THAT(claimable, ElementsAre(ModelKey{"c", "b"}, ModelKey{"c", "c"}, ModelKey{"c", "a"}));
  EXPECT_EQ(store->LoadPending({"c", "a"}).value()->attempts, 1);
}

TEST_F(CoordinatorStoreTest, ListModelsPagesInIngestOrderAndFiltersByState) {
  auto store = OpenStore();
  ASSERT_TRUE(store->CreateCollections({{"c", Params()}}).ok());
  const std::string job = store->NewJob("ingest", "c", 0).value();
  for (int i = 0; i < 5; ++i) {
    ASSERT_TRUE(store->AddModel({"c"}, absl::StrCat("m", i), "", absl::StrCat(i), job).ok());
  }
  ASSERT_TRUE(store->MarkFailed({"c", "m1"}, 3, "gave up after 3 attempts: UNAVAILABLE").ok());
  ASSERT_TRUE(store->MarkFailed({"c", "m3"}, 1, "DATA_LOSS: damaged").ok());
  v1::ListCollectionModelsRequest request;
  request.set_collection("c");
  request.set_page_size(2);
  std::vector<std::string> ids;
  do {
    const v1::ListCollectionModelsResponse page = store->ListModels(request).value();
    for (const v1::ModelInfo& m : page.models()) ids.push_back(m.model_id());
    request.set_page_token(page.next_page_token());
  } while (!request.page_token().empty());
  EXPECT_THAT(ids, ElementsAre("m0", "m1", "m2", "m3", "m4"));
  request.set_state(v1::MODEL_STATE_FAILED);
  request.set_page_size(0);
  const v1::ListCollectionModelsResponse failed = store->ListModels(request).value();
  ASSERT_EQ(failed.models_size(), 2);
  EXPECT_EQ(failed.models(0).model_id(), "m1");
  EXPECT_EQ(failed.models(0).attempts(), 3u);
  EXPECT_EQ(failed.models(0).state(), v1::MODEL_STATE_FAILED);
  EXPECT_EQ(failed.models(1).error(), "DATA_LOSS: damaged");
  request.set_page_token("not a token");
  EXPECT_EQ(store->ListModels(request).status().code(), absl::StatusCode::kInvalidArgument);
  request.set_page_token("");
  request.set_page_size(100000);
  EXPECT_EQ(store->ListModels(request).status().code(), absl::StatusCode::kInvalidArgument);
}

// A database written by the first release (no schema version, fingerprints
// with the mistaken FNV basis, an ingest job whose state was only ever
// computed when read) opens migrated: the same mesh is still "the same".
TEST_F(CoordinatorStoreTest, FirstReleaseDatabaseIsMigrated) {
  const std::string mesh = "serialized mesh";
  {
    auto db = Database::Open((dir_ / "coordinator.db").string());
    ASSERT_TRUE(db.ok());
    ASSERT_TRUE((*db)->Execute(R"sql(
      CREATE TABLE collections (
        name TEXT PRIMARY KEY, params BLOB NOT NULL, codebook_id TEXT NOT NULL DEFAULT '');
      CREATE TABLE models (
        collection TEXT NOT NULL, model_id TEXT NOT NULL, ordinal INTEGER NOT NULL,
        label TEXT NOT NULL, mesh BLOB NOT NULL, fingerprint TEXT NOT NULL,
        state INTEGER NOT NULL, error TEXT NOT NULL DEFAULT '', features BLOB,
        feature_count INTEGER NOT NULL DEFAULT 0, job_id TEXT NOT NULL,
        indexed_codebook TEXT NOT NULL DEFAULT '',
        PRIMARY KEY (collection, model_id));
      CREATE INDEX models_by_state ON models (state);
      CREATE TABLE jobs (
        seq INTEGER PRIMARY KEY AUTOINCREMENT, id TEXT UNIQUE, kind TEXT NOT NULL,
        collection TEXT NOT NULL, state INTEGER NOT NULL, message TEXT NOT NULL DEFAULT '',
        total INTEGER NOT NULL DEFAULT 0, stream_open INTEGER NOT NULL DEFAULT 0);
      CREATE TABLE settings (key TEXT PRIMARY KEY, value INTEGER NOT NULL);
      INSERT INTO settings VALUES ('index_shards', 1);
      INSERT INTO jobs (id, kind, collection, state, stream_open) VALUES ('ingest-1', 'ingest', 'c', 1, 1);
    )sql").ok());
    const std::string params = Params().SerializeAsString();
    auto collection = (*db)->Prepare("INSERT INTO collections (name, params) VALUES ('c', ?)");
    ASSERT_TRUE(collection->BindBlob(1, params).Run().ok());
    auto model = (*db)->Prepare(
        "INSERT INTO models (collection, model_id, ordinal, label, mesh, fingerprint, state, "
        "feature_count, job_id, features) VALUES ('c', 'm', 0, 'cat', ?, ?, 1, 12, 'ingest-1', "
        "'stored features')");
    const std::string legacy =
        absl::StrCat(absl::Hex(Fnv1a64(mesh, kLegacyFnv1a64OffsetBasis), absl::kZeroPad16));
    ASSERT_TRUE(model->BindBlob(1, mesh).Bind(2, legacy).Run().ok());
  }
  auto store = OpenStore();
  ASSERT_NE(store, nullptr);
  // Features kept in the row by releases before feature files: in a file now.
  EXPECT_EQ(store->LoadFeatures({"c", "m"}), "stored features");
  {
    auto db = Database::Open((dir_ / "coordinator.db").string());
    auto in_rows = (*db)->Prepare("SELECT COUNT(*) FROM models WHERE features IS NOT NULL");
    ASSERT_TRUE(in_rows.ok() && in_rows->Run().ok());
    EXPECT_EQ(in_rows->ColumnInt(0), 0);
  }
  auto again = store->AddModel({"c"}, "m", "cat", mesh, "ingest-2");
  ASSERT_TRUE(again.ok()) << again.status();
  EXPECT_FALSE(again->created);
  const v1::JobStatus job = store->GetJob("ingest-1").value();
  EXPECT_EQ(job.state(), v1::JOB_STATE_SUCCEEDED);
  EXPECT_EQ(job.message(), "1 models extracted");
  EXPECT_EQ(store->CountModels({"c"}, "").value().extracted, 1u);
  EXPECT_EQ(store->NewJob("build", "c", 1).value(), "build-2");
}

// A fused collection's members hold a copy of every model, stored together;
// counts and lists see each model once, failed when any copy failed.
TEST_F(CoordinatorStoreTest, FusedMembersHoldEveryModelCountedOnce) {
  auto store = OpenStore();
  ASSERT_NE(store, nullptr);
  v1::PipelineParams other = Params();
  other.set_method(v1::FEATURE_METHOD_RLD);
  ASSERT_TRUE(
      store->CreateCollections({{"f", Params()}, {"f~dld", Params()}, {"f~rld", other}}).ok());
  // All or nothing: a conflict creates none.
  EXPECT_EQ(store->CreateCollections({{"g", Params()}, {"f~rld", Params()}}).code(),
            absl::StatusCode::kAlreadyExists);
  EXPECT_EQ(store->GetCollection("g").status().code(), absl::StatusCode::kNotFound);

  const std::vector<std::string> members = {"f~dld", "f~rld"};
  const std::string job = store->NewJob("ingest", "f", 0).value();
  for (const char* id : {"a", "b", "c"}) {
    auto added = store->AddModel(members, id, "cat", id, job);
    ASSERT_TRUE(added.ok() && added->created);
    EXPECT_EQ(added->rows, 2);  // one PENDING row per member: the dispatcher counts both
  }
  EXPECT_FALSE(store->AddModel(members, "a", "cat", "a", job)->created);
  EXPECT_EQ(store->AddModel(members, "a", "cat", "a", job)->rows, 0);
  EXPECT_EQ(store->AddModel(members, "a", "dog", "a", job).status().code(),
            absl::StatusCode::kAlreadyExists);
  // a: extracted by both; b: by one, failed by the other; c: extracted by one.
  ASSERT_TRUE(store->MarkExtracted({"f~dld", "a"}, "F", 10).ok());
  ASSERT_TRUE(store->MarkExtracted({"f~rld", "a"}, "F", 20).ok());
  ASSERT_TRUE(store->MarkExtracted({"f~dld", "b"}, "F", 10).ok());
  ASSERT_TRUE(store->MarkFailed({"f~rld", "b"}, 1, "bad mesh").ok());
  ASSERT_TRUE(store->MarkExtracted({"f~dld", "c"}, "F", 10).ok());
  ASSERT_TRUE(store->MarkIndexed({"f~dld", "a"}, "f~dld@build-9").ok());
  ASSERT_TRUE(store->MarkIndexed({"f~rld", "a"}, "f~rld@build-9").ok());
  const ModelCounts counts = store->CountModels(members, "build-9").value();
  EXPECT_EQ(counts.models, 3u);
  EXPECT_EQ(counts.extracted, 1u);
  EXPECT_EQ(counts.failed, 1u);
  EXPECT_EQ(counts.pending, 1u);
  EXPECT_EQ(counts.indexed, 1u);

  v1::ListCollectionModelsRequest request;
  request.set_collection("f");
  const v1::ListCollectionModelsResponse all = store->ListModels(request, members).value();
  ASSERT_EQ(all.models_size(), 3);
  EXPECT_EQ(all.models(0).model_id(), "a");
  EXPECT_EQ(all.models(0).state(), v1::MODEL_STATE_EXTRACTED);
  EXPECT_EQ(all.models(0).features(), 30u);
  EXPECT_EQ(all.models(1).state(), v1::MODEL_STATE_FAILED);
  EXPECT_EQ(all.models(1).error(), "rld: bad mesh");
  EXPECT_EQ(all.models(2).state(), v1::MODEL_STATE_PENDING);
  request.set_state(v1::MODEL_STATE_EXTRACTED);
  EXPECT_EQ(store->ListModels(request, members).value().models_size(), 1);

  // A build's progress counts the members' models it indexed.
  const std::string build = store->NewJob("build", "f", 2).value();
  ASSERT_TRUE(store->MarkIndexed({"f~dld", "a"}, "f~dld@" + build).ok());
  EXPECT_EQ(store->GetJob(build).value().done(), 1u);
}

TEST_F(CoordinatorStoreTest, RankingStateIsReplacedByTheNextBuild) {
  auto store = OpenStore();
  ASSERT_NE(store, nullptr);
  EXPECT_FALSE(store->GetRanking("f").value().has_value());
  ASSERT_TRUE(store->SetRanking("f", "build-1", "one").ok());
  ASSERT_TRUE(store->SetRanking("f", "build-2", "two").ok());
  const std::optional<StoredRanking> got = store->GetRanking("f").value();
  ASSERT_TRUE(got.has_value());
  EXPECT_EQ(got->build, "build-2");
  EXPECT_EQ(got->state, "two");
}

// A collection stored before histograms could be weighted has no
// histogram_power among its (otherwise complete) parameters: it keeps ranking
// unweighted, as its index was built, though LSF's default is now 0.5.
TEST_F(CoordinatorStoreTest, ACollectionStoredBeforeWeightingKeepsUnweightedHistograms) {
  auto store = OpenStore();
  v1::PipelineParams params;
  wire::PipelineParamsToProto(RetrievalPipelineOptions::ForMethod(FeatureMethod::kLsf), &params);
  ASSERT_TRUE(store->CreateCollections({{"now", params}}).ok());
  v1::PipelineParams legacy;
  for (const v1::ParamValue& v : params.values()) {
    if (v.name() != "histogram_power") *legacy.add_values() = v;
  }
  ASSERT_EQ(legacy.values_size() + 1, params.values_size());
  ASSERT_TRUE(store->CreateCollections({{"before", legacy}}).ok());
  auto now = LoadCollectionPlan(store.get(), "now");
  auto before = LoadCollectionPlan(store.get(), "before");
  ASSERT_TRUE(now.ok() && before.ok());
  EXPECT_EQ(now->options.methods[0].weighting.power, 0.5);
  EXPECT_EQ(before->options.methods[0].weighting.power, 1.0);
  EXPECT_FALSE(before->parts[0].options.weighting.enabled());
}

}  // namespace
}  // namespace meshseek
