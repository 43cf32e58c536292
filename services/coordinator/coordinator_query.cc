// CoordinatorService: Query and Evaluate (coordinator_service.h). A
// collection of one method without re-ranking is ranked by the index alone
// (top-k merged over the shards, its own distances); a fused or re-ranked one
// by its build's Ranking (ranking.h), with the models that joined it live
// (live_index.h), over every part's distances, or with candidates over their
// union of proposals (fused_candidates.h).
#include <algorithm>
#include <map>
#include <optional>

#include "absl/strings/str_cat.h"
#include "common/base/parallel.h"
#include "common/base/status_macros.h"
#include "common/rpc/convert.h"
#include "common/rpc/status.h"
#include "services/coordinator/coordinator_service.h"
#include "services/coordinator/fused_candidates.h"

namespace meshseek {
namespace {

absl::Status Prefixed(const absl::Status& status, const std::string& prefix) {
  return absl::Status(status.code(), absl::StrCat(prefix, status.message()));
}

}  // namespace

grpc::Status CoordinatorService::Query(grpc::ServerContext*,
                                       const v1::QueryRequest* request,
                                       v1::QueryResponse* response) {
  if (request->top_k() == 0) {
    return grpc::Status(grpc::StatusCode::INVALID_ARGUMENT, "query: top_k must be at least 1");
  }
  absl::StatusOr<CollectionPlan> plan = PublicPlan(request->collection());
  if (!plan.ok()) return rpc::ToGrpcStatus(plan.status());
  if (plan->codebook_id.empty()) {
    return grpc::Status(grpc::StatusCode::FAILED_PRECONDITION,
                        absl::StrCat("collection '", request->collection(), "' is not built yet"));
  }
  if (request->candidates() > 0 && !plan->options.rescaled() &&
      FeatureMethodInfoOf(plan->parts.front().options.extractor.method).kind ==
          DescriptorKind::kGlobal) {
    // Never ignored: a flag that cannot act is the caller's mistake.
    return grpc::Status(grpc::StatusCode::INVALID_ARGUMENT,
                        absl::StrCat("query: candidates=", request->candidates(),
                                     " does not apply to collection '", request->collection(),
                                     "' (a global descriptor, ranked exactly); ask with "
                                     "candidates=0"));
  }
  if (plan->options.rescaled() && request->candidates() > kMaxFusedCandidates) {
    return grpc::Status(grpc::StatusCode::INVALID_ARGUMENT,
                        absl::StrCat("query: candidates=", request->candidates(),
                                     " on fused or re-ranked collection '", request->collection(),
                                     "'; at most ", kMaxFusedCandidates));
  }
  v1::Mesh arrays;
  if (!request->model_id().empty()) {
    // A model of the collection: the mesh it was stored with (already
    // checked at ingest).
    if (request->has_mesh()) {
      return grpc::Status(grpc::StatusCode::INVALID_ARGUMENT,
                          "query: give a mesh or a model_id, not both");
    }
    absl::StatusOr<std::optional<std::string>> stored =
        store_->ModelMesh({plan->parts.front().name, request->model_id()});
    if (!stored.ok()) return rpc::ToGrpcStatus(stored.status());
    if (!stored->has_value()) {
      return grpc::Status(grpc::StatusCode::NOT_FOUND,
                          absl::StrCat("query: collection '",
                                       request->collection(),
                                       "' has no model '",
                                       request->model_id(),
                                       "'"));
    }
    if (!arrays.ParseFromString(**stored)) {
      return grpc::Status(
          grpc::StatusCode::DATA_LOSS,
          absl::StrCat("query: model ", request->model_id(), ": stored mesh does not parse"));
    }
  } else {
    absl::StatusOr<TriangleMesh> mesh = rpc::MeshFromProto(request->mesh(), options_.mesh_limits);
    if (!mesh.ok()) return rpc::ToGrpcStatus(Prefixed(mesh.status(), "query: "));
    rpc::MeshToProto(*mesh, &arrays);
  }
  // Each part's signature of the query, the parts (methods) side by side.
  const std::size_t parts = plan->parts.size();
  std::vector<absl::StatusOr<IndexSignature>> signatures(parts, absl::UnknownError(""));
  std::vector<uint32_t> counts(parts, 0);
  ParallelFor(parts, static_cast<int>(parts), [&](std::size_t p) {
    const CollectionInfo& part = plan->parts[p];
    absl::StatusOr<v1::LocalFeatures> features = workers_.Extract(arrays, part, "query");
    if (!features.ok()) {
      signatures[p] = features.status();
      return;
    }
    counts[p] = features->count();
    signatures[p] = workers_.Encode(part, part.codebook_id, *features);
  });
  uint32_t total = 0;
  for (std::size_t p = 0; p < parts; ++p) {
    if (!signatures[p].ok()) {
      return rpc::ToGrpcStatus(
          parts > 1 ? Prefixed(signatures[p].status(), absl::StrCat(plan->parts[p].name, ": "))
                    : signatures[p].status());
    }
    total += counts[p];
  }
  response->set_query_features(total);

  if (!plan->options.rescaled()) {
    const CollectionInfo& part = plan->parts.front();
    v1::SearchRequest search;
    search.set_collection(part.name);
    if (signatures[0]->descriptor.has_value()) {
      *search.mutable_global_descriptor() = *signatures[0]->descriptor;
    } else {
      *search.mutable_histogram() = signatures[0]->histogram;
    }
    search.set_top_k(request->top_k());
    search.set_candidates(request->candidates());
    search.set_kl_epsilon(part.options.kl.epsilon);
    absl::StatusOr<std::vector<v1::ScoredModel>> found = workers_.index()->Search(search);
    if (!found.ok()) return rpc::ToGrpcStatus(found.status());
    for (v1::ScoredModel& m : *found) *response->add_results() = std::move(m);
    return grpc::Status::OK;
  }

  // Fused or re-ranked: every part's distances to every model, ranked by the
  // build's state with the models that joined it since (live_index.h).
  absl::StatusOr<std::shared_ptr<LiveRanking>> ranking = live_.RankingOf(*plan);
  if (!ranking.ok()) return rpc::ToGrpcStatus(ranking.status());
  std::vector<const IndexSignature*> query(parts);
  for (std::size_t p = 0; p < parts; ++p) query[p] = &*signatures[p];
  // With candidates, to the union of the parts' proposals only
  // (fused_candidates.h).
  absl::StatusOr<std::vector<std::vector<IndexShards::Scored>>> distances =
      request->candidates() > 0
          ? CandidatePartDistances(workers_.index(), *plan, query,
                                   std::max(request->candidates(), request->top_k()))
          : PartDistances(workers_.index(), *plan, query);
  if (!distances.ok()) return rpc::ToGrpcStatus(distances.status());
  absl::StatusOr<std::vector<v1::ScoredModel>> found;
  {
    absl::ReaderMutexLock lock(&(*ranking)->mutex);
    found = (*ranking)->ranking.Query(*distances, plan->options, request->top_k());
  }
  if (!found.ok()) return rpc::ToGrpcStatus(found.status());
  for (v1::ScoredModel& m : *found) *response->add_results() = std::move(m);
  return grpc::Status::OK;
}

grpc::Status CoordinatorService::Evaluate(grpc::ServerContext* context,
                                          const v1::EvaluateRequest* request,
                                          grpc::ServerWriter<v1::EvaluateRow>* writer) {
  absl::StatusOr<CollectionPlan> plan = PublicPlan(request->collection());
  if (!plan.ok()) return rpc::ToGrpcStatus(plan.status());
  absl::StatusOr<v1::Collection> collection = DescribeCollection(request->collection());
  if (!collection.ok()) return rpc::ToGrpcStatus(collection.status());
  if (collection->codebook_id().empty() || collection->indexed() != collection->extracted() ||
      collection->pending() > 0) {
    return grpc::Status(grpc::StatusCode::FAILED_PRECONDITION,
                        absl::StrCat("collection '",
                                     request->collection(),
                                     "' has ",
                                     collection->extracted(),
                                     " extracted models of which ",
                                     collection->indexed(),
                                     " are indexed with its current codebook, and ",
                                     collection->pending(),
                                     " pending; build it first"));
  }
  // A copy: the stream is paced by the client, and joins must not wait.
  std::optional<Ranking> ranking;
  if (plan->options.rescaled()) {
    absl::StatusOr<std::shared_ptr<LiveRanking>> loaded = live_.RankingOf(*plan);
    if (!loaded.ok()) return rpc::ToGrpcStatus(loaded.status());
    absl::ReaderMutexLock lock(&(*loaded)->mutex);
    ranking = (*loaded)->ranking;
  }
  // Feature counts per model and part.
  const std::size_t parts = plan->parts.size();
  std::map<std::string, std::vector<uint32_t>> feature_counts;
  for (std::size_t p = 0; p < parts; ++p) {
    v1::ListCollectionModelsRequest list;
    list.set_collection(plan->parts[p].name);
    list.set_state(v1::MODEL_STATE_EXTRACTED);
    list.set_page_size(1000);
    do {
      absl::StatusOr<v1::ListCollectionModelsResponse> page = store_->ListModels(list);
      if (!page.ok()) return rpc::ToGrpcStatus(page.status());
      for (const v1::ModelInfo& m : page->models()) {
        std::vector<uint32_t>& counts = feature_counts[m.model_id()];
        counts.resize(parts, 0);
        counts[p] = m.features();
      }
      list.set_page_token(page->next_page_token());
    } while (!list.page_token().empty());
  }
  v1::EvaluateRow out;
  uint64_t rows = 0;
  const absl::Status streamed = workers_.index()->ForEachDistanceRow(
      IndexParts(*plan), [&](const IndexShards::Row& row) -> absl::Status {
        if (context->IsCancelled()) return absl::CancelledError("evaluate: cancelled");
        out.set_model_id(row.model->model_id());
        out.set_label(row.model->label());
        if (!ranking.has_value()) {
          out.mutable_distances()->Assign(row.distances[0].begin(), row.distances[0].end());
        } else {
          // Rows come in node order: the build's order, unless the
          // collection changed since.
          if (rows >= ranking->state.model_ids.size() ||
              ranking->state.model_ids[rows] != row.model->model_id()) {
            return absl::FailedPreconditionError(absl::StrCat("collection '",
                                                              request->collection(),
                                                              "' changed since build ",
                                                              ranking->build,
                                                              "; build it again"));
          }
          MESHSEEK_ASSIGN_OR_RETURN(
              const std::vector<float> ranked,
              ranking->RankRow(row.distances, static_cast<uint32_t>(rows), plan->options));
          out.mutable_distances()->Assign(ranked.begin(), ranked.end());
        }
        const std::vector<uint32_t>& counts = feature_counts[row.model->model_id()];
        uint32_t total = 0;
        out.clear_method_features();
        for (uint32_t c : counts) {
          total += c;
          out.add_method_features(c);
        }
        out.set_features(total);
        if (!writer->Write(out)) return absl::CancelledError("evaluate: client went away");
        ++rows;
        return absl::OkStatus();
      });
  if (!streamed.ok()) return rpc::ToGrpcStatus(streamed);
  if (rows != collection->indexed()) {
    return grpc::Status(grpc::StatusCode::FAILED_PRECONDITION,
                        absl::StrCat("index returned ",
                                     rows,
                                     " rows for ",
                                     collection->indexed(),
                                     " indexed models; build again"));
  }
  return grpc::Status::OK;
}

}  // namespace meshseek
