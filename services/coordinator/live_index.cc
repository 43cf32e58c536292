#include "services/coordinator/live_index.h"

#include <vector>

#include "absl/strings/str_cat.h"
#include "common/base/logging.h"
#include "common/base/status_macros.h"
#include "services/coordinator/fused_candidates.h"

namespace meshseek {
namespace {

// The collection clients name for a part: a member's fused collection, or
// the collection itself.
std::string PublicName(const std::string& collection) {
  return IsMemberCollection(collection) ? collection.substr(0, collection.find('~')) : collection;
}

}  // namespace

LiveIndex::LiveIndex(CoordinatorStore* store, Workers* workers)
    : store_(store), workers_(workers) {}

absl::StatusOr<std::shared_ptr<LiveRanking>> LiveIndex::RankingOf(const CollectionPlan& plan) {
  const std::string build = plan.build();
  {
    absl::MutexLock lock(&mutex_);
    auto it = rankings_.find(plan.name);
    if (it != rankings_.end() && it->second->build == build) return it->second;
  }
  MESHSEEK_ASSIGN_OR_RETURN(const std::optional<StoredRanking> stored,
                            store_->GetRanking(plan.name));
  if (!stored.has_value() || stored->build != build) {
    return absl::FailedPreconditionError(absl::StrCat(
        "collection '", plan.name, "' has no ranking state of build ", build, "; build it again"));
  }
  MESHSEEK_ASSIGN_OR_RETURN(RankingState state, RankingState::Parse(stored->state));
  MESHSEEK_ASSIGN_OR_RETURN(Ranking ranking,
                            Ranking::Make(stored->build, std::move(state), plan.options));
  MESHSEEK_ASSIGN_OR_RETURN(const std::vector<std::string> joins,
                            store_->RankingJoins(plan.name, build));
  for (const std::string& bytes : joins) {
    MESHSEEK_ASSIGN_OR_RETURN(const RankingJoin join, RankingJoin::Parse(bytes));
    MESHSEEK_RETURN_IF_ERROR(ranking.Apply(join));
  }
  auto live = std::make_shared<LiveRanking>(std::move(ranking));
  absl::MutexLock lock(&mutex_);
  auto [it, inserted] = rankings_.try_emplace(plan.name, live);
  // Two loads of one build at once: keep the first, which joins may use.
  if (!inserted && it->second->build == build) return it->second;
  it->second = live;
  return live;
}

absl::Status LiveIndex::IndexInPart(const CollectionInfo& part,
                                    const std::string& model_id,
                                    const v1::LocalFeatures& features,
                                    uint64_t ordinal,
                                    const std::string& label) {
  MESHSEEK_ASSIGN_OR_RETURN(const IndexSignature signature,
                            workers_->Encode(part, part.codebook_id, features));
  MESHSEEK_RETURN_IF_ERROR(workers_->AddToIndex(part.name, model_id, ordinal, label, signature));
  return store_->MarkIndexed({part.name, model_id}, part.codebook_id, /*live=*/true);
}

absl::Status LiveIndex::ModelExtracted(const ModelKey& key,
                                       const v1::LocalFeatures& features,
                                       uint64_t ordinal,
                                       const std::string& label) {
  MESHSEEK_ASSIGN_OR_RETURN(const CollectionPlan part_plan,
                            LoadCollectionPlan(store_, key.collection));
  MESHSEEK_ASSIGN_OR_RETURN(const CollectionInfo part, OnlyPart(part_plan));
  if (part.codebook_id.empty()) return absl::OkStatus();  // before the first build
  MESHSEEK_RETURN_IF_ERROR(IndexInPart(part, key.model_id, features, ordinal, label));
  const std::string name = PublicName(key.collection);
  absl::StatusOr<CollectionPlan> plan = part_plan;
  if (name != key.collection) plan = LoadCollectionPlan(store_, name);
  if (!plan.ok()) return plan.status();
  if (!plan->options.rescaled() || plan->codebook_id.empty()) {
    // Indexed: its features are not read again before the next build.
    return store_->DropFeatures({part.name}, part_plan.build(), key.model_id);
  }
  return Join(*plan, RankedModel{key.model_id, ordinal, label});
}

absl::Status LiveIndex::Join(const CollectionPlan& plan, const RankedModel& model) {
  MESHSEEK_ASSIGN_OR_RETURN(std::shared_ptr<LiveRanking> live, RankingOf(plan));
  absl::MutexLock join(&live->join_mutex);
  const std::string build = plan.build();
  {
    absl::ReaderMutexLock lock(&live->mutex);
    if (live->ranking.node_of.contains(model.model_id)) {
      return store_->DropFeatures(plan.PartNames(), build, model.model_id);
    }
  }
  // Every part's signature of the model, from its stored features, once
  // every part has indexed it with this build's codebook.
  std::vector<IndexSignature> signatures;
  for (const CollectionInfo& part : plan.parts) {
    const std::string codebook_id = absl::StrCat(part.name, "@", build);
    MESHSEEK_ASSIGN_OR_RETURN(const std::optional<ExtractedModel> stored,
                              store_->LoadExtracted({part.name, model.model_id}));
    if (!stored.has_value() || stored->indexed_codebook != codebook_id) return absl::OkStatus();
    MESHSEEK_ASSIGN_OR_RETURN(const v1::LocalFeatures features,
                              workers_->FeaturesOf(store_, part, *stored));
    MESHSEEK_ASSIGN_OR_RETURN(IndexSignature signature,
                              workers_->Encode(part, codebook_id, features));
    signatures.push_back(std::move(signature));
  }
  std::vector<const IndexSignature*> query;
  for (const IndexSignature& s : signatures) query.push_back(&s);
  // A collection past the exact graph's size joins from candidates, as its
  // graph was built (fused_candidates.h): O(candidates), not O(n).
  std::size_t nodes = 0;
  {
    absl::ReaderMutexLock lock(&live->mutex);
    nodes = live->ranking.state.model_ids.size();
  }
  const RankingGraphOptions& graph = workers_->options().ranking_graph;
  MESHSEEK_ASSIGN_OR_RETURN(
      const auto distances,
      nodes > graph.exact_graph_models
          ? CandidatePartDistances(workers_->index(), plan, query, graph.graph_candidates)
          : PartDistances(workers_->index(), plan, query));
  absl::StatusOr<RankingJoin> planned = absl::UnknownError("");
  {
    absl::ReaderMutexLock lock(&live->mutex);
    planned = live->ranking.PlanJoin(model.model_id, model.ordinal, model.label, distances);
  }
  if (!planned.ok()) return planned.status();
  MESHSEEK_ASSIGN_OR_RETURN(
      const bool stored,
      store_->AddRankingJoin(plan.name, build, model.model_id, planned->Serialize()));
  if (!stored) return absl::OkStatus();  // a newer build ranks it
  {
    absl::MutexLock lock(&live->mutex);
    MESHSEEK_RETURN_IF_ERROR(live->ranking.Apply(*planned));
  }
  // Indexed and ranked: its features are not read again before the next build.
  return store_->DropFeatures(plan.PartNames(), build, model.model_id);
}

absl::Status LiveIndex::CatchUp(const std::string& collection) {
  MESHSEEK_ASSIGN_OR_RETURN(const CollectionPlan plan, LoadCollectionPlan(store_, collection));
  if (plan.member || plan.codebook_id.empty()) return absl::OkStatus();
  uint64_t indexed = 0, joined = 0;
  for (const CollectionInfo& part : plan.parts) {
    if (part.codebook_id.empty()) continue;
    MESHSEEK_ASSIGN_OR_RETURN(const std::vector<ExtractedModel> behind,
                              store_->ExtractedModels(part.name, part.codebook_id));
    for (const ExtractedModel& m : behind) {
      MESHSEEK_ASSIGN_OR_RETURN(const v1::LocalFeatures features,
                                workers_->FeaturesOf(store_, part, m));
      MESHSEEK_RETURN_IF_ERROR(Prefixed(IndexInPart(part, m.model_id, features, m.ordinal, m.label),
                                        absl::StrCat("model ", m.model_id, ": ")));
      ++indexed;
    }
  }
  if (plan.options.rescaled()) {
    MESHSEEK_ASSIGN_OR_RETURN(std::shared_ptr<LiveRanking> live, RankingOf(plan));
    MESHSEEK_ASSIGN_OR_RETURN(const std::vector<RankedModel> models,
                              store_->IndexedModels(plan.PartNames(), plan.build()));
    for (const RankedModel& m : models) {
      bool ranked = false;
      {
        absl::ReaderMutexLock lock(&live->mutex);
        ranked = live->ranking.node_of.contains(m.model_id);
      }
      if (ranked) continue;
      MESHSEEK_RETURN_IF_ERROR(
          Prefixed(Join(plan, m), absl::StrCat("model ", m.model_id, ": ")));
      ++joined;
    }
  }
  MESHSEEK_RETURN_IF_ERROR(store_->DropFeatures(plan.PartNames(), plan.build()));
  if (indexed + joined > 0) {
    MESHSEEK_LOG(INFO) << "coordinator: " << collection << ": caught up with " << indexed
                       << " model copies to index and " << joined << " models to rank";
  }
  return absl::OkStatus();
}

}  // namespace meshseek
