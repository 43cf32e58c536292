// The coordinator's durable state: every SQL statement the coordinator runs
// lives here. One SQLite file (coordinator.db) under the data folder holds
//   collections (name, parameters, current codebook),
//   models      (mesh, label, ingest ordinal, state, attempts, error,
//                the codebook it was indexed with),
//   jobs        (ingest and build jobs and their state),
//   thumbnails  (a PNG per model, under the collection clients name),
//   rankings    (what the build of a fused or re-ranked collection leaves for
//                its queries: coordinator/ranking.h),
//   settings    (facts fixed at first use: the number of index shards).
//
// A fused collection ("a+b") holds no models itself: its member collections
// ("<name>~a", "<name>~b") hold a row of each, extracted and indexed by
// their method (the mesh stored once, in the first member's row); the calls
// below take the member names where they count or list a fused collection's
// models.
//
// Bounded storage: a model's local features are kept from its extraction
// until it is indexed (and, in a rescaled collection, ranked), then freed
// (DropFeatures); a build extracts again what it trains on from the mesh.
// They are kept beside the database, a file a model (feature_files.h), not
// in it: freeing megabytes of blobs in SQLite rewrote the file.
// What stays per model beyond its mesh is its row, thumbnail and, in the
// index, its histograms (docs/design.md "Bounded storage").
//
// The schema and its versions: coordinator_schema.h.
//
// States are typed (ModelState, v1::JobState); statements that belong
// together (a model leaving PENDING and its ingest job finishing, a job and
// its id) run in one transaction. An ingest job's state is written when it
// changes: when its last pending model ends or its stream closes with none
// pending, never when someone reads it.
//
// Thread-safe: one connection behind one mutex (SQLite serialises writers
// anyway; statements here are short).
#ifndef MESHSEEK_SERVICES_COORDINATOR_COORDINATOR_STORE_H_
#define MESHSEEK_SERVICES_COORDINATOR_COORDINATOR_STORE_H_

#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <tuple>
#include <utility>
#include <vector>

#include "absl/status/status.h"
#include "absl/status/statusor.h"
#include "absl/synchronization/mutex.h"
#include "absl/time/time.h"
#include "common/store/sqlite_db.h"
#include "services/coordinator/coordinator_schema.h"
#include "services/coordinator/feature_files.h"
#include "meshseek/v1/coordinator.pb.h"
#include "meshseek/v1/types.pb.h"

namespace meshseek {

/// Stored as these integers (the first release's values).
enum class ModelState : int64_t { kPending = 0, kExtracted = 1, kFailed = 2 };

v1::ModelState ToProto(ModelState state);

/// A model by its key.
struct ModelKey {
  std::string collection;
  std::string model_id;
  bool operator<(const ModelKey& o) const {
    return std::tie(collection, model_id) < std::tie(o.collection, o.model_id);
  }
  bool operator==(const ModelKey& o) const {
    return collection == o.collection && model_id == o.model_id;
  }
};

struct StoredCollection {
  v1::PipelineParams params;
  std::string codebook_id;  // empty before the first build
};

struct StoredRanking {
  std::string build;  // the build job that computed it
  std::string state;  // RankingState::Serialize
};

struct ModelCounts {
  uint64_t models = 0;
  uint64_t pending = 0;
  uint64_t extracted = 0;
  uint64_t failed = 0;
  uint64_t indexed = 0;  // extracted and indexed with the given codebook
  uint64_t added = 0;    // of those, indexed live: after the build trained it
};

/// What a dispatcher needs to extract one pending model.
struct PendingModel {
  std::string mesh;  // serialized v1::Mesh
  uint64_t ordinal = 0;
  std::string label;
  int attempts = 0;  // made before this one
  std::string job_id;
};

/// An extracted model, as a build reads it.
struct ExtractedModel {
  std::string model_id;
  uint64_t ordinal = 0;
  std::string label;
  std::string indexed_codebook;
};

/// A model a ranking state holds, in node order.
struct RankedModel {
  std::string model_id;
  uint64_t ordinal = 0;
  std::string label;
};

class CoordinatorStore {
 public:
  /// Opens (creating and migrating) `data_dir`/coordinator.db and the
  /// features folder `data_dir`/features (moving features that a release
  /// before files kept in the database there). The number of
  /// index shards is recorded at first use: FailedPrecondition when it
  /// differs later, as models would be looked for on the wrong shards.
  /// Streams do not survive a restart: every job's stream is marked closed
  /// (and ingest jobs with nothing pending finish).
  static absl::StatusOr<std::unique_ptr<CoordinatorStore>> Open(const std::string& data_dir,
                                                                int index_shards);

  // ------------------------------------------------------------ collections
  /// NotFound when absent; DataLoss when its stored parameters do not parse.
  absl::StatusOr<StoredCollection> GetCollection(const std::string& name);
  /// Creates each (name, parameters), or nothing for one that exists with
  /// the same parameters, in one transaction; AlreadyExists (and nothing
  /// created) when one exists with others.
  absl::Status CreateCollections(
      const std::vector<std::pair<std::string, v1::PipelineParams>>& collections);
  absl::Status SetCodebook(const std::string& collection, const std::string& codebook_id);
  /// The models of `collections` (one, or a fused collection's members),
  /// each model once: pending while pending in any, failed when failed in
  /// any, extracted when extracted in all, indexed when indexed by the build
  /// job `build` (codebook "<collection>@<build>") in all; no model is
  /// indexed for an empty `build`.
  absl::StatusOr<ModelCounts> CountModels(const std::vector<std::string>& collections,
                                          const std::string& build);
  /// The ranking state of a fused or re-ranked collection, replacing the
  /// previous build's (and the joins of that build).
  absl::Status SetRanking(const std::string& collection,
                          const std::string& build,
                          const std::string& state);
  absl::StatusOr<std::optional<StoredRanking>> GetRanking(const std::string& collection);
  /// Appends a model's join (RankingJoin bytes) to the state of `build`;
  /// false, and nothing stored, when the stored state is of another build
  /// (a build ended meanwhile: its state ranks the model already).
  absl::StatusOr<bool> AddRankingJoin(const std::string& collection,
                                      const std::string& build,
                                      const std::string& model_id,
                                      const std::string& join);
  /// The joins of `build`'s state, in join order.
  absl::StatusOr<std::vector<std::string>> RankingJoins(const std::string& collection,
                                                        const std::string& build);
  /// The models indexed by `build` in every one of `collections` (one, or a
  /// fused collection's members), in the first one's ingest order: those
  /// that the build's ranking state, with its joins, should rank.
  absl::StatusOr<std::vector<RankedModel>> IndexedModels(
      const std::vector<std::string>& collections, const std::string& build);

  // ------------------------------------------------------------------- jobs
  /// A RUNNING job with id "<kind>-<sequence>"; an ingest job starts with its
  /// stream open.
  absl::StatusOr<std::string> NewJob(const std::string& kind,
                                     const std::string& collection,
                                     uint64_t total);
  absl::Status FinishJob(const std::string& job_id, v1::JobState state, const std::string& message);
  /// The ingest stream of `job_id` ended; the job finishes if nothing of it
  /// is pending.
  absl::Status CloseIngestStream(const std::string& job_id);
  /// The job with its progress (models counted for ingest jobs, models
  /// indexed with the job's codebook for builds, in every member of a fused
  /// collection) and up to 20 errors.
  absl::StatusOr<v1::JobStatus> GetJob(const std::string& job_id);
  /// (job id, collection) of every RUNNING build, to resume after a restart.
  absl::StatusOr<std::vector<std::pair<std::string, std::string>>> RunningBuilds();

  // ----------------------------------------------------------------- models
  struct AddedModel {
    bool created = false;
    std::string job_id;  // the job that first stored it
    int rows = 0;        // PENDING rows stored now (created: at least one)
  };
  /// A model's picture, kept under `collection`: the one clients name (a
  /// fused collection's, not its members').
  struct ModelThumbnail {
    std::string collection;
    std::string png;  // empty: none
  };
  /// Stores a new PENDING model (ordinal: the collection's next) in each of
  /// `collections` (one, or a fused collection's members) and its thumbnail
  /// in one transaction, or acknowledges the same mesh and label again
  /// without change (storing the thumbnail if there was none);
  /// AlreadyExists when the id holds another mesh or label.
  absl::StatusOr<AddedModel> AddModel(const std::vector<std::string>& collections,
                                      const std::string& model_id,
                                      const std::string& label,
                                      const std::string& mesh,
                                      const std::string& job_id,
                                      const ModelThumbnail& thumbnail = {});
  /// Up to `limit` PENDING models whose retry time has come, oldest first,
  /// skipping `busy`.
  absl::StatusOr<std::vector<ModelKey>> ClaimablePending(absl::Time now,
                                                         const std::vector<ModelKey>& busy,
                                                         int limit);
  /// The earliest retry time after `now` of a PENDING model in backoff.
  absl::StatusOr<std::optional<absl::Time>> NextRetry(absl::Time now);
  /// The model if it is still PENDING (not removed or finished meanwhile).
  absl::StatusOr<std::optional<PendingModel>> LoadPending(const ModelKey& key);
  uint64_t PendingCount();
  /// Rows per (stored collection, state), for the metrics: one aggregate over
  /// an index. A fused collection's rows are its members'.
  struct StateCount {
    std::string collection;
    ModelState state = ModelState::kPending;
    uint64_t models = 0;
  };
  absl::StatusOr<std::vector<StateCount>> CountModelsByState();

  /// A PENDING model's outcome, each in one transaction with its ingest job
  /// finishing when this was the job's last pending model. false when the
  /// model was no longer PENDING (removed meanwhile): nothing changed.
  /// MarkExtracted keeps `features` (serialized v1::LocalFeatures) until
  /// DropFeatures; a failure to write them is logged, not returned (the
  /// build extracts the model again).
  absl::StatusOr<bool> MarkExtracted(const ModelKey& key,
                                     const std::string& features,
                                     uint32_t feature_count);
  absl::StatusOr<bool> MarkFailed(const ModelKey& key, int attempts, const std::string& reason);
  /// A transient failure: stays PENDING, not claimable before `retry_at`.
  absl::Status ScheduleRetry(const ModelKey& key,
                             int attempts,
                             absl::Time retry_at,
                             const std::string& error);
  /// `live`: by live ingest, after the build that trained the codebook.
  absl::Status MarkIndexed(const ModelKey& key, const std::string& codebook_id, bool live = false);
  /// Deletes the model and its features; its state before, or nullopt when
  /// there was none.
  absl::StatusOr<std::optional<ModelState>> RemoveModel(const ModelKey& key);

  /// The mesh (serialized v1::Mesh) a model was ingested with, in any
  /// state; nullopt when the collection has no such model. A fused
  /// collection stores it once, in its first member's row.
  absl::StatusOr<std::optional<std::string>> ModelMesh(const ModelKey& key);

  // ------------------------------------------------------------- thumbnails
  /// nullopt when none is stored (models ingested before thumbnails were,
  /// or whose mesh could not be drawn).
  absl::StatusOr<std::optional<std::string>> GetThumbnail(const ModelKey& key);
  absl::Status SetThumbnail(const ModelKey& key, const std::string& png);
  absl::Status RemoveThumbnail(const ModelKey& key);

  /// The names of the collections clients created (not fused collections'
  /// members), sorted.
  absl::StatusOr<std::vector<std::string>> ListCollectionNames();

  /// Every EXTRACTED model of the collection in ingest order; with
  /// `not_indexed_with`, those not indexed with that codebook only (what
  /// live indexing catches up with after a restart or a build).
  absl::StatusOr<std::vector<ExtractedModel>> ExtractedModels(
      const std::string& collection, const std::optional<std::string>& not_indexed_with = {});
  /// Frees the stored features of the models indexed by `build` in
  /// `collections` (one, or a fused collection's members; all of them, or
  /// only `model_id`): once a model is indexed (and ranked), nothing reads
  /// them before the next build, which extracts them again from the mesh.
  absl::Status DropFeatures(const std::vector<std::string>& collections,
                            const std::string& build,
                            const std::string& model_id = "");
  /// A model's stored features (serialized v1::LocalFeatures); nullopt when
  /// freed, never stored, or not intact (FeatureFiles::Get).
  std::optional<std::string> LoadFeatures(const ModelKey& key) const;
  /// One EXTRACTED model; nullopt when it is not (or no longer) extracted.
  absl::StatusOr<std::optional<ExtractedModel>> LoadExtracted(const ModelKey& key);
  /// A page of the collection's models (see ListCollectionModelsRequest):
  /// of request.collection, or with `members` (a fused collection's) each
  /// model once, in the state CountModels gives it, with its members' errors
  /// and feature counts summed.
  absl::StatusOr<v1::ListCollectionModelsResponse> ListModels(
      const v1::ListCollectionModelsRequest& request, const std::vector<std::string>& members = {});

 private:
  CoordinatorStore(std::unique_ptr<Database> db, FeatureFiles features)
      : features_(std::move(features)), db_(std::move(db)) {}
  absl::Status Migrate(int index_shards) ABSL_EXCLUSIVE_LOCKS_REQUIRED(mutex_);
  absl::Status MoveFeaturesOutOfRows() ABSL_EXCLUSIVE_LOCKS_REQUIRED(mutex_);
  absl::Status FinishIngestJobIfDone(const std::string& job_id)
      ABSL_EXCLUSIVE_LOCKS_REQUIRED(mutex_);
  absl::StatusOr<std::optional<std::string>> MeshInRows(const ModelKey& key)
      ABSL_EXCLUSIVE_LOCKS_REQUIRED(mutex_);
  absl::StatusOr<bool> EndPending(const ModelKey& key,
                                  ModelState state,
                                  int attempts,
                                  const std::string& error,
                                  const std::string* features,  // null: none to keep
                                  uint32_t feature_count);

  const FeatureFiles features_;  // thread-safe: needs no lock
  absl::Mutex mutex_;
  std::unique_ptr<Database> db_ ABSL_GUARDED_BY(mutex_);
};

}  // namespace meshseek

#endif  // MESHSEEK_SERVICES_COORDINATOR_COORDINATOR_STORE_H_
