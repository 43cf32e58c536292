// Live ingest (docs/design.md, "Live ingest"): once a collection has been
// built, a model extracted into it is searchable without another build.
//
//   1. Each part (the collection, or a fused collection's member) encodes
//      the model's features with its current codebook and indexes it
//      (marked `live`: status counts the models added since the codebook).
//   2. A fused or re-ranked collection ranks by its build's RankingState
//      (ranking.h). When the last part has indexed the model, it joins the
//      state: its distances to every ranked model, fused with the build's
//      scales, make it the next node of the neighbour graph, exactly as the
//      graph of all pairs would hold it (NeighborGraph::PlanJoin). The join
//      is stored (CoordinatorStore::AddRankingJoin) before it is applied in
//      memory, so a restart replays it.
//
// Codebooks and scales stay those of the build: the new model's words are
// the old vocabulary's. A build (explicit, resumable) retrains them and
// starts a new state; the joins of the old one are dropped with it.
//
// Crash safety: every step is idempotent and recorded in the store, so
// CatchUp (at start, and after each build) redoes what a kill -9 cut off:
// extracted models not indexed with their part's codebook are indexed, and
// indexed models missing from the ranking join it.
//
// Thread-safety: thread-safe. Joins of one collection run one at a time
// (each must see the ones before it); queries read a ranking under a reader
// lock while a join is computed, and wait only while it is applied.
#ifndef MESHSEEK_SERVICES_COORDINATOR_LIVE_INDEX_H_
#define MESHSEEK_SERVICES_COORDINATOR_LIVE_INDEX_H_

#include <atomic>
#include <map>
#include <memory>
#include <string>
#include <utility>

#include "absl/status/status.h"
#include "absl/status/statusor.h"
#include "absl/synchronization/mutex.h"
#include "services/coordinator/coordinator_store.h"
#include "services/coordinator/ranking.h"
#include "services/coordinator/workers.h"

namespace meshseek {

/// The ranking of a rescaled collection's last build with the models that
/// joined it since.
struct LiveRanking {
  explicit LiveRanking(Ranking r) : build(r.build), ranking(std::move(r)) {}
  const std::string build;
  /// Held for the whole of one join (distances, plan, store, apply).
  absl::Mutex join_mutex;
  mutable absl::Mutex mutex;
  Ranking ranking ABSL_GUARDED_BY(mutex);
};

class LiveIndex {
 public:
  /// Not owned; both must outlive the LiveIndex.
  LiveIndex(CoordinatorStore* store, Workers* workers);

  /// The ranking of `plan`'s last build with its stored joins, parsed once
  /// per build. FailedPrecondition when the store has no state of it.
  absl::StatusOr<std::shared_ptr<LiveRanking>> RankingOf(const CollectionPlan& plan);

  /// Step 1 and 2 for a model whose copy in `key.collection` (one part) has
  /// just been extracted: nothing before the collection's first build.
  absl::Status ModelExtracted(const ModelKey& key,
                              const v1::LocalFeatures& features,
                              uint64_t ordinal,
                              const std::string& label);

  /// Redoes what a restart or a build left undone in `collection` (a
  /// collection clients name): see above.
  absl::Status CatchUp(const std::string& collection);

 private:
  // Encodes and indexes one part's copy with the part's codebook.
  absl::Status IndexInPart(const CollectionInfo& part,
                           const std::string& model_id,
                           const v1::LocalFeatures& features,
                           uint64_t ordinal,
                           const std::string& label);
  // Step 2 for one model: nothing when a part has not indexed it with the
  // build's codebook yet (that part's own call joins it) or it is ranked.
  absl::Status Join(const CollectionPlan& plan, const RankedModel& model);

  CoordinatorStore* const store_;
  Workers* const workers_;

  absl::Mutex mutex_;
  std::map<std::string, std::shared_ptr<LiveRanking>> rankings_ ABSL_GUARDED_BY(mutex_);
};

}  // namespace meshseek

#endif  // MESHSEEK_SERVICES_COORDINATOR_LIVE_INDEX_H_
