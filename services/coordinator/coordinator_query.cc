// CoordinatorService: Query, QueryByImage and Evaluate (coordinator_service.h). A
// collection of one method without re-ranking is ranked by the index alone
// (top-k merged over the shards, its own distances); a fused or re-ranked one
// by its build's Ranking (ranking.h), with the models that joined it live
// (live_index.h), over every part's distances, or with candidates over their
// union of proposals (fused_candidates.h).
#include <algorithm>
#include <map>
#include <optional>

#include "absl/strings/str_cat.h"
#include "absl/strings/str_join.h"
#include "absl/time/clock.h"
#include "common/base/parallel.h"
#include "common/base/status_macros.h"
#include "common/global/picture_silhouette.h"
#include "common/wire/convert.h"
#include "services/coordinator/coordinator_service.h"
#include "services/coordinator/fused_candidates.h"

namespace meshseek {
namespace {

// Flags a query gives that cannot act on its collection are refused, never
// ignored.
absl::Status CheckQueryFlags(const v1::QueryRequest& request, const CollectionPlan& plan) {
  if (plan.codebook_id.empty()) {
    return absl::FailedPreconditionError(
        absl::StrCat("collection '", request.collection(), "' is not built yet"));
  }
  if (request.candidates() > 0 && !plan.options.rescaled() &&
      FeatureMethodInfoOf(plan.parts.front().options.extractor.method).kind ==
          DescriptorKind::kGlobal) {
    return absl::InvalidArgumentError(absl::StrCat(
        "query: candidates=", request.candidates(), " does not apply to collection '",
        request.collection(), "' (a global descriptor, ranked exactly); ask with candidates=0"));
  }
  if (plan.options.rescaled() && request.candidates() > kMaxFusedCandidates) {
    return absl::InvalidArgumentError(absl::StrCat(
        "query: candidates=", request.candidates(), " on fused or re-ranked collection '",
        request.collection(), "'; at most ", kMaxFusedCandidates));
  }
  if (!request.model_id().empty() && request.has_mesh()) {
    return absl::InvalidArgumentError("query: give a mesh or a model_id, not both");
  }
  return absl::OkStatus();
}

// Features per model and part (the counts an eval prints), from the store.
absl::StatusOr<std::map<std::string, std::vector<uint32_t>>> FeatureCounts(
    CoordinatorStore& store, const CollectionPlan& plan) {
  const std::size_t parts = plan.parts.size();
  std::map<std::string, std::vector<uint32_t>> feature_counts;
  for (std::size_t p = 0; p < parts; ++p) {
    v1::ListCollectionModelsRequest list;
    list.set_collection(plan.parts[p].name);
    list.set_state(v1::MODEL_STATE_EXTRACTED);
    list.set_page_size(1000);
    do {
      MESHSEEK_ASSIGN_OR_RETURN(const v1::ListCollectionModelsResponse page,
                                store.ListModels(list));
      for (const v1::ModelInfo& m : page.models()) {
        std::vector<uint32_t>& counts = feature_counts[m.model_id()];
        counts.resize(parts, 0);
        counts[p] = m.features();
      }
      list.set_page_token(page.next_page_token());
    } while (!list.page_token().empty());
  }
  return feature_counts;
}

}  // namespace

absl::StatusOr<v1::Mesh> CoordinatorService::QueryMesh(const v1::QueryRequest& request,
                                                      const CollectionPlan& plan) {
  v1::Mesh arrays;
  if (request.model_id().empty()) {
    absl::StatusOr<TriangleMesh> mesh = wire::MeshFromProto(request.mesh(), options_.mesh_limits);
    if (!mesh.ok()) return Prefixed(mesh.status(), "query: ");
    wire::MeshToProto(*mesh, &arrays);
    return arrays;
  }
  // A model of the collection: the mesh it was stored with (already checked
  // at ingest).
  MESHSEEK_ASSIGN_OR_RETURN(const std::optional<std::string> stored,
                            store_->ModelMesh({plan.parts.front().name, request.model_id()}));
  if (!stored.has_value()) {
    return absl::NotFoundError(absl::StrCat("query: collection '", request.collection(),
                                            "' has no model '", request.model_id(), "'"));
  }
  if (!arrays.ParseFromString(*stored)) {
    return absl::DataLossError(
        absl::StrCat("query: model ", request.model_id(), ": stored mesh does not parse"));
  }
  return arrays;
}

absl::StatusOr<std::vector<IndexSignature>> CoordinatorService::QuerySignatures(
    const v1::Mesh& mesh, const CollectionPlan& plan, uint32_t* features,
    v1::QueryTimings* timings) {
  const std::size_t parts = plan.parts.size();
  std::vector<absl::StatusOr<IndexSignature>> encoded(parts, absl::UnknownError(""));
  std::vector<uint32_t> counts(parts, 0);
  std::vector<v1::MethodTiming> times(parts);
  // The parts run side by side, each asking for every core (the services
  // cap it at theirs): the first to finish leaves its cores to the last,
  // which otherwise would run alone on one (docs/design.md 1.1).
  const auto threads = static_cast<uint32_t>(ResolveThreadCount(0));
  const absl::Time start = absl::Now();
  ParallelFor(parts, static_cast<int>(parts), [&](std::size_t p) {
    const CollectionInfo& part = plan.parts[p];
    times[p].set_method(FeatureMethodName(part.options.extractor.method));
    const absl::Time extract_start = absl::Now();
    absl::StatusOr<v1::LocalFeatures> extracted = workers_.Extract(mesh, part, "query", threads);
    const absl::Time encode_start = absl::Now();
    times[p].set_extract_seconds(absl::ToDoubleSeconds(encode_start - extract_start));
    if (!extracted.ok()) {
      encoded[p] = extracted.status();
      return;
    }
    counts[p] = extracted->count();
    encoded[p] = workers_.Encode(part, part.codebook_id, *extracted, threads);
    times[p].set_encode_seconds(absl::ToDoubleSeconds(absl::Now() - encode_start));
  });
  timings->set_signatures_seconds(absl::ToDoubleSeconds(absl::Now() - start));
  for (v1::MethodTiming& t : times) *timings->add_methods() = std::move(t);
  std::vector<IndexSignature> signatures;
  *features = 0;
  for (std::size_t p = 0; p < parts; ++p) {
    if (!encoded[p].ok()) {
      return parts > 1 ? Prefixed(encoded[p].status(), absl::StrCat(plan.parts[p].name, ": "))
                       : encoded[p].status();
    }
    signatures.push_back(*std::move(encoded[p]));
    *features += counts[p];
  }
  return signatures;
}

absl::StatusOr<v1::QueryResponse> CoordinatorService::Query(const v1::QueryRequest& request,
                                                            const rpc::CallContext&) {
  if (request.top_k() == 0) return absl::InvalidArgumentError("query: top_k must be at least 1");
  MESHSEEK_ASSIGN_OR_RETURN(const CollectionPlan plan, PublicPlan(request.collection()));
  MESHSEEK_RETURN_IF_ERROR(CheckQueryFlags(request, plan));
  v1::QueryResponse response;
  v1::QueryTimings& timings = *response.mutable_timings();
  const absl::Time start = absl::Now();
  MESHSEEK_ASSIGN_OR_RETURN(const v1::Mesh mesh, QueryMesh(request, plan));
  timings.set_mesh_seconds(absl::ToDoubleSeconds(absl::Now() - start));
  uint32_t features = 0;
  MESHSEEK_ASSIGN_OR_RETURN(const std::vector<IndexSignature> signatures,
                            QuerySignatures(mesh, plan, &features, &timings));
  response.set_query_features(features);
  const absl::Time search_start = absl::Now();

  std::vector<v1::ScoredModel> found;
  if (!plan.options.rescaled()) {
    // One method: the index's own ranking, merged over the shards.
    const CollectionInfo& part = plan.parts.front();
    v1::SearchRequest search;
    search.set_collection(part.name);
    if (signatures[0].descriptor.has_value()) {
      *search.mutable_global_descriptor() = *signatures[0].descriptor;
    } else {
      *search.mutable_histogram() = signatures[0].histogram;
    }
    search.set_top_k(request.top_k());
    search.set_candidates(request.candidates());
    search.set_kl_epsilon(part.options.kl.epsilon);
    MESHSEEK_ASSIGN_OR_RETURN(found, workers_.index()->Search(search));
  } else {
    // Fused or re-ranked: every part's distances to every model (or, with
    // candidates, to the union of the parts' proposals, fused_candidates.h),
    // ranked by the build's state with the models that joined it since
    // (live_index.h).
    MESHSEEK_ASSIGN_OR_RETURN(const std::shared_ptr<LiveRanking> ranking, live_.RankingOf(plan));
    std::vector<const IndexSignature*> query;
    for (const IndexSignature& signature : signatures) query.push_back(&signature);
    // A large collection is never scanned whole unless asked for candidates.
    const RankingGraphOptions& graph = workers_.options().ranking_graph;
    uint32_t candidates = request.candidates();
    if (candidates == 0) {
      absl::ReaderMutexLock lock(&ranking->mutex);
      if (ranking->ranking.state.model_ids.size() > graph.exact_graph_models) {
        candidates = graph.query_candidates;
      }
    }
    MESHSEEK_ASSIGN_OR_RETURN(
        const std::vector<std::vector<IndexShards::Scored>> distances,
        candidates > 0 ? CandidatePartDistances(workers_.index(), plan, query,
                                                std::max(candidates, request.top_k()))
                       : PartDistances(workers_.index(), plan, query));
    absl::ReaderMutexLock lock(&ranking->mutex);
    MESHSEEK_ASSIGN_OR_RETURN(found, ranking->ranking.Query(distances, plan.options, request.top_k()));
  }
  for (v1::ScoredModel& m : found) *response.add_results() = std::move(m);
  timings.set_search_seconds(absl::ToDoubleSeconds(absl::Now() - search_start));
  return response;
}

absl::StatusOr<v1::QueryResponse> CoordinatorService::QueryByImage(
    const v1::QueryByImageRequest& request, const rpc::CallContext&) {
  if (request.top_k() == 0) return absl::InvalidArgumentError("query: top_k must be at least 1");
  if (request.image().size() > kMaxPictureFileBytes) {
    return absl::InvalidArgumentError(absl::StrCat("query by picture: a file of ",
                                                   request.image().size(), " bytes; at most ",
                                                   kMaxPictureFileBytes));
  }
  MESHSEEK_ASSIGN_OR_RETURN(const CollectionPlan plan, PublicPlan(request.collection()));
  // The member whose descriptors are views (docs/design.md 2.7d).
  const CollectionInfo* views = nullptr;
  for (const CollectionInfo& part : plan.parts) {
    if (FeatureMethodInfoOf(part.options.extractor.method).view_distance != nullptr) views = &part;
  }
  if (views == nullptr) {
    std::vector<std::string> methods;
    for (const CollectionInfo& part : plan.parts) {
      methods.push_back(FeatureMethodName(part.options.extractor.method));
    }
    return absl::FailedPreconditionError(absl::StrCat(
        "query by picture: collection '", request.collection(), "' (", absl::StrJoin(methods, "+"),
        ") holds no views of its models to match a picture against; it needs lfd "
        "(--method lfd, or a fusion with lfd such as the default bfdsift+rld+lsf+lfd)"));
  }
  if (plan.codebook_id.empty()) {
    return absl::FailedPreconditionError(
        absl::StrCat("collection '", request.collection(), "' is not built yet"));
  }
  v1::QueryResponse response;
  v1::QueryTimings& timings = *response.mutable_timings();
  absl::Time start = absl::Now();
  absl::StatusOr<cv::Mat> picture = DecodePicture(request.image());
  if (!picture.ok()) return Prefixed(picture.status(), "query by picture: ");
  timings.set_mesh_seconds(absl::ToDoubleSeconds(absl::Now() - start));
  start = absl::Now();
  const LfdOptions& lfd = views->options.extractor.lfd;
  PictureSilhouetteOptions silhouette_options;
  silhouette_options.image_size = lfd.image_size;
  absl::StatusOr<std::vector<uint8_t>> silhouette = PictureSilhouette(*picture, silhouette_options);
  if (!silhouette.ok()) return Prefixed(silhouette.status(), "query by picture: ");
  MESHSEEK_ASSIGN_OR_RETURN(
      const auto view,
      DescribeLfdSilhouette({silhouette->data(), lfd.image_size, lfd.image_size}, lfd));
  timings.set_signatures_seconds(absl::ToDoubleSeconds(absl::Now() - start));
  start = absl::Now();
  v1::SearchRequest search;
  search.set_collection(views->name);
  search.set_picture_view(view.data(), view.size());
  search.set_top_k(request.top_k());
  MESHSEEK_ASSIGN_OR_RETURN(std::vector<v1::ScoredModel> found, workers_.index()->Search(search));
  for (v1::ScoredModel& m : found) *response.add_results() = std::move(m);
  timings.set_search_seconds(absl::ToDoubleSeconds(absl::Now() - start));
  return response;
}

absl::Status CoordinatorService::Evaluate(const v1::EvaluateRequest& request,
                                          rpc::Writer<v1::EvaluateRow> write,
                                          const rpc::CallContext& call) {
  MESHSEEK_ASSIGN_OR_RETURN(const CollectionPlan plan, PublicPlan(request.collection()));
  MESHSEEK_ASSIGN_OR_RETURN(const v1::Collection collection, DescribeCollection(request.collection()));
  if (collection.codebook_id().empty() || collection.indexed() != collection.extracted() ||
      collection.pending() > 0) {
    return absl::FailedPreconditionError(absl::StrCat(
        "collection '", request.collection(), "' has ", collection.extracted(),
        " extracted models of which ", collection.indexed(),
        " are indexed with its current codebook, and ", collection.pending(),
        " pending; build it first"));
  }
  // A copy: the stream is paced by the client, and joins must not wait.
  std::optional<Ranking> ranking;
  if (plan.options.rescaled()) {
    MESHSEEK_ASSIGN_OR_RETURN(const std::shared_ptr<LiveRanking> loaded, live_.RankingOf(plan));
    absl::ReaderMutexLock lock(&loaded->mutex);
    ranking = loaded->ranking;
  }
  MESHSEEK_ASSIGN_OR_RETURN(auto feature_counts, FeatureCounts(*store_, plan));
  v1::EvaluateRow out;
  uint64_t rows = 0;
  const absl::Status streamed = workers_.index()->ForEachDistanceRow(
      IndexParts(plan), [&](const IndexShards::Row& row) -> absl::Status {
        if (call.cancelled()) return absl::CancelledError("evaluate: cancelled");
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
                                                              request.collection(),
                                                              "' changed since build ",
                                                              ranking->build,
                                                              "; build it again"));
          }
          MESHSEEK_ASSIGN_OR_RETURN(
              const std::vector<float> ranked,
              ranking->RankRow(row.distances, static_cast<uint32_t>(rows), plan.options));
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
        if (!write(out)) return absl::CancelledError("evaluate: client went away");
        ++rows;
        return absl::OkStatus();
      });
  MESHSEEK_RETURN_IF_ERROR(streamed);
  if (rows != collection.indexed()) {
    return absl::FailedPreconditionError(absl::StrCat(
        "index returned ", rows, " rows for ", collection.indexed(), " indexed models; build again"));
  }
  return absl::OkStatus();
}

}  // namespace meshseek
