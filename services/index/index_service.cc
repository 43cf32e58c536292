#include "services/index/index_service.h"

#include <algorithm>
#include <filesystem>

#include "absl/strings/str_cat.h"
#include "common/base/parallel.h"
#include "common/base/status_macros.h"

namespace meshseek {
namespace {

double EpsilonOrDefault(double epsilon) {
  return epsilon > 0 ? epsilon : KlDivergenceOptions().epsilon;
}

absl::StatusOr<ModelSignature> SignatureOf(const v1::SparseHistogram& histogram,
                                           bool has_descriptor,
                                           const v1::GlobalDescriptor& descriptor,
                                           const std::string& what) {
  return ModelSignature::Parse(histogram, has_descriptor ? &descriptor : nullptr, what);
}

}  // namespace

absl::Status IndexServiceOptions::Validate() const {
  if (data_dir.empty()) return absl::InvalidArgumentError("index: --data_dir is required");
  if (postings_max_models == 0) {
    return absl::InvalidArgumentError("index: --postings_max_models must be at least 1");
  }
  return absl::OkStatus();
}

IndexCollection& IndexService::CollectionNamed(const std::string& name) {
  return collections_.try_emplace(name, storage_).first->second;
}

absl::StatusOr<std::unique_ptr<IndexService>> IndexService::Create(
    const IndexServiceOptions& options) {
  MESHSEEK_RETURN_IF_ERROR(options.Validate());
  MESHSEEK_ASSIGN_OR_RETURN(std::unique_ptr<IndexStore> store, IndexStore::Open(options.data_dir));
  // Forward files are derived and unlinked; any left by name is stale.
  std::error_code ignored;
  std::filesystem::remove_all(options.data_dir + "/forward", ignored);
  std::unique_ptr<IndexService> service(new IndexService(options, std::move(store)));
  MESHSEEK_RETURN_IF_ERROR(service->Load());
  IndexService* index = service.get();
  service->models_gauge_ = rpc::ScrapeGauge::Register(
      "meshseek_index_models",
      "Models indexed per collection (on this server; a shard holds part of each)",
      [index]() -> absl::StatusOr<std::vector<rpc::GaugeSample>> {
        absl::ReaderMutexLock lock(&index->mutex_);
        std::vector<rpc::GaugeSample> samples;
        for (const auto& [name, collection] : index->collections_) {
          samples.push_back({{{"collection", name}}, static_cast<double>(collection.size())});
        }
        return samples;
      });
  return service;
}

absl::Status IndexService::Load() {
  absl::MutexLock write(&write_mutex_);
  absl::MutexLock lock(&mutex_);
  return store_->ForEach([this](const std::string& name, const v1::IndexedModel& model)
                             ABSL_EXCLUSIVE_LOCKS_REQUIRED(mutex_) {
    const std::string what = absl::StrCat("model '", model.model_id(), "'");
    absl::StatusOr<ModelSignature> signature = SignatureOf(
        model.histogram(), model.has_global_descriptor(), model.global_descriptor(), what);
    absl::Status placed = signature.status();
    if (placed.ok()) {
      placed = CollectionNamed(name).Place(model.model_id(), model.ordinal(), model.label(), *signature);
    }
    if (placed.ok()) return placed;
    return absl::DataLossError(absl::StrCat("index: stored histogram of model '", model.model_id(),
                                            "' in collection '", name, "': ", placed.message()));
  });
}

absl::StatusOr<v1::AddModelResponse> IndexService::AddModel(const v1::AddModelRequest& request,
                                                            const rpc::CallContext&) {
  if (request.collection().empty() || request.model_id().empty()) {
    return absl::InvalidArgumentError("add: collection and model_id must not be empty");
  }
  const std::string name = absl::StrCat("add model '", request.model_id(), "'");
  MESHSEEK_ASSIGN_OR_RETURN(
      const ModelSignature signature,
      SignatureOf(request.histogram(), request.has_global_descriptor(), request.global_descriptor(),
                  name));
  absl::MutexLock write(&write_mutex_);
  {
    // Refuse what Place would refuse before anything is written.
    absl::ReaderMutexLock lock(&mutex_);
    auto it = collections_.find(request.collection());
    if (it != collections_.end()) {
      if (absl::Status fits = it->second.CheckFits(request.model_id(), signature); !fits.ok()) {
        return Prefixed(fits, absl::StrCat(name, " to collection '", request.collection(), "': "));
      }
    }
  }
  v1::IndexedModel model;
  model.set_model_id(request.model_id());
  model.set_ordinal(request.ordinal());
  model.set_label(request.label());
  *model.mutable_histogram() = request.histogram();
  if (request.has_global_descriptor()) {
    *model.mutable_global_descriptor() = request.global_descriptor();
  }
  MESHSEEK_RETURN_IF_ERROR(store_->Upsert(request.collection(), model));
  absl::MutexLock lock(&mutex_);
  IndexCollection& collection = CollectionNamed(request.collection());
  MESHSEEK_RETURN_IF_ERROR(
      collection.Place(request.model_id(), request.ordinal(), request.label(), signature));
  v1::AddModelResponse response;
  response.set_collection_size(collection.size());
  return response;
}

absl::StatusOr<v1::RemoveModelResponse> IndexService::RemoveModel(
    const v1::RemoveModelRequest& request, const rpc::CallContext&) {
  absl::MutexLock write(&write_mutex_);
  MESHSEEK_RETURN_IF_ERROR(store_->Remove(request.collection(), request.model_id()));
  absl::MutexLock lock(&mutex_);
  auto it = collections_.find(request.collection());
  v1::RemoveModelResponse response;
  response.set_removed(it != collections_.end() && it->second.Remove(request.model_id()));
  return response;
}

absl::Status IndexService::UseEpsilon(const std::string& name, double epsilon) {
  epsilon = EpsilonOrDefault(epsilon);
  {
    absl::ReaderMutexLock lock(&mutex_);
    auto it = collections_.find(name);
    if (it == collections_.end() || it->second.epsilon().value_or(epsilon) == epsilon) {
      return absl::OkStatus();
    }
  }
  absl::MutexLock lock(&mutex_);
  auto it = collections_.find(name);
  if (it == collections_.end()) return absl::OkStatus();
  return it->second.SetEpsilon(epsilon);
}

absl::StatusOr<const IndexCollection*> IndexService::FindCollection(const std::string& name) {
  auto it = collections_.find(name);
  if (it == collections_.end() || it->second.empty()) {
    return absl::NotFoundError(absl::StrCat("index has no models in collection '", name, "'"));
  }
  return &it->second;
}

absl::StatusOr<const IndexCollection*> IndexService::FindCollection(const std::string& name,
                                                                    double epsilon) {
  MESHSEEK_ASSIGN_OR_RETURN(const IndexCollection* collection, FindCollection(name));
  const std::optional<double> ranked_with = collection->epsilon();  // none for descriptors
  if (ranked_with.has_value() && *ranked_with != EpsilonOrDefault(epsilon)) {
    return absl::AbortedError(absl::StrCat("collection '", name, "' is ranked with KL epsilon ",
                                           *ranked_with, " (changed meanwhile); retry"));
  }
  return collection;
}

namespace {

v1::SearchResponse SearchResponseOf(const std::vector<IndexCollection::Hit>& hits) {
  v1::SearchResponse response;
  for (const IndexCollection::Hit& hit : hits) {
    v1::ScoredModel* result = response.add_results();
    result->set_model_id(hit.model->model_id);
    result->set_label(hit.model->label);
    result->set_distance(hit.distance);
    result->set_ordinal(hit.model->ordinal);
  }
  return response;
}

}  // namespace

absl::StatusOr<v1::SearchResponse> IndexService::Search(const v1::SearchRequest& request,
                                                        const rpc::CallContext&) {
  if (request.top_k() == 0) return absl::InvalidArgumentError("search: top_k must be at least 1");
  if (!request.picture_view().empty()) {
    if (request.has_histogram() || request.has_global_descriptor()) {
      return absl::InvalidArgumentError(
          "search: a picture's view and a histogram or descriptor: one query at a time");
    }
    absl::ReaderMutexLock lock(&mutex_);
    MESHSEEK_ASSIGN_OR_RETURN(const IndexCollection* collection,
                              FindCollection(request.collection()));
    absl::StatusOr<std::vector<IndexCollection::Hit>> hits =
        collection->SearchView(request.picture_view(), request.top_k(), options_.num_threads);
    if (!hits.ok()) return Prefixed(hits.status(), absl::StrCat("search '", request.collection(), "': "));
    return SearchResponseOf(*hits);
  }
  MESHSEEK_ASSIGN_OR_RETURN(
      const ModelSignature query,
      SignatureOf(request.histogram(), request.has_global_descriptor(), request.global_descriptor(),
                  "search: query"));
  if (!query.descriptor.has_value()) {
    MESHSEEK_RETURN_IF_ERROR(UseEpsilon(request.collection(), request.kl_epsilon()));
  }
  absl::ReaderMutexLock lock(&mutex_);
  MESHSEEK_ASSIGN_OR_RETURN(const IndexCollection* collection,
                            FindCollection(request.collection(), request.kl_epsilon()));
  const std::size_t candidates =
      request.candidates() == 0 ? 0 : std::max(request.candidates(), request.top_k());
  absl::StatusOr<std::vector<IndexCollection::Hit>> hits =
      collection->Search(query, request.top_k(), candidates, options_.num_threads);
  if (!hits.ok()) return Prefixed(hits.status(), absl::StrCat("search '", request.collection(), "': "));
  return SearchResponseOf(*hits);
}

absl::Status IndexService::ExportModels(const v1::ExportModelsRequest& request,
                                        rpc::Writer<v1::IndexedModel> write,
                                        const rpc::CallContext& call) {
  // Copied under the lock, streamed after it: a slow reader never holds up
  // writers. Meant for evaluation-sized collections.
  std::vector<v1::IndexedModel> models;
  {
    absl::ReaderMutexLock lock(&mutex_);
    auto it = collections_.find(request.collection());
    if (it == collections_.end() || it->second.empty()) {
      return absl::NotFoundError(
          absl::StrCat("index has no models in collection '", request.collection(), "'"));
    }
    if (request.model_ids_size() > kMaxDistanceModels) {
      return absl::InvalidArgumentError(absl::StrCat("export: ", request.model_ids_size(),
                                                     " model ids, at most ", kMaxDistanceModels));
    }
    models = it->second.Export(request.model_ids(), !request.without_signatures());
  }
  for (const v1::IndexedModel& model : models) {
    if (call.cancelled() || !write(model)) return absl::CancelledError("");
  }
  return absl::OkStatus();
}

absl::StatusOr<v1::DistancesResponse> IndexService::Distances(const v1::DistancesRequest& request,
                                                              const rpc::CallContext&) {
  const int total = request.queries_size() + request.global_queries_size();
  if (total > kMaxDistanceQueries) {
    return absl::InvalidArgumentError(absl::StrCat(
        "distances: ", total, " queries, at most ", kMaxDistanceQueries, " per request"));
  }
  if (request.queries_size() > 0 && request.global_queries_size() > 0) {
    return absl::InvalidArgumentError("distances: both histogram and descriptor queries");
  }
  if (request.model_ids_size() > kMaxDistanceModels) {
    return absl::InvalidArgumentError(absl::StrCat("distances: ", request.model_ids_size(),
                                                   " model ids, at most ", kMaxDistanceModels,
                                                   " per request"));
  }
  std::vector<ModelSignature> queries;
  for (int q = 0; q < total; ++q) {
    const std::string what = absl::StrCat("distances: query ", q);
    MESHSEEK_ASSIGN_OR_RETURN(
        ModelSignature query,
        request.global_queries_size() > 0
            ? ModelSignature::Parse(
                  v1::SparseHistogram::default_instance(), &request.global_queries(q), what)
            : ModelSignature::Parse(request.queries(q), nullptr, what));
    queries.push_back(std::move(query));
  }
  if (request.queries_size() > 0) {
    MESHSEEK_RETURN_IF_ERROR(UseEpsilon(request.collection(), request.kl_epsilon()));
  }
  absl::ReaderMutexLock lock(&mutex_);
  MESHSEEK_ASSIGN_OR_RETURN(const IndexCollection* collection,
                            FindCollection(request.collection(), request.kl_epsilon()));
  v1::DistancesResponse response;
  const absl::Status status =
      collection->Distances(queries, request.model_ids(), options_.num_threads, &response);
  if (!status.ok()) return Prefixed(status, "distances: ");
  return response;
}

namespace {

// The queries of a Neighbors or PairDistances request, checked.
absl::StatusOr<std::vector<IndexCollection::Query>> QueriesOf(
    const std::vector<const v1::QueryModel*>& asked, const std::string& what) {
  std::vector<IndexCollection::Query> queries(asked.size());
  for (std::size_t q = 0; q < asked.size(); ++q) {
    const v1::QueryModel& m = *asked[q];
    queries[q].model_id = m.model_id();
    if (!m.has_model()) continue;
    MESHSEEK_ASSIGN_OR_RETURN(
        queries[q].signature,
        SignatureOf(m.model().histogram(), m.model().has_global_descriptor(),
                    m.model().global_descriptor(), absl::StrCat(what, " query ", q)));
  }
  return queries;
}

void AppendHits(const std::vector<IndexCollection::Hit>& hits, v1::NeighborList* list) {
  for (const IndexCollection::Hit& hit : hits) {
    list->add_neighbor_ids(hit.model->model_id);
    list->add_ordinals(hit.model->ordinal);
    list->add_distances(hit.distance);
  }
}

}  // namespace

absl::Status IndexService::Neighbors(const v1::NeighborsRequest& request,
                                     rpc::Writer<v1::NeighborLists> write,
                                     const rpc::CallContext& call) {
  if (request.count() < 1 || request.count() > kMaxNeighbors) {
    return absl::InvalidArgumentError(
        absl::StrCat("neighbors: count ", request.count(), " is not in [1, ", kMaxNeighbors, "]"));
  }
  if (request.candidates() != 0 &&
      (request.candidates() < request.count() || request.candidates() > kMaxDistanceModels)) {
    return absl::InvalidArgumentError(absl::StrCat("neighbors: candidates ", request.candidates(),
                                                   " is not 0 or in [count, ",
                                                   kMaxDistanceModels, "]"));
  }
  if (request.queries_size() > kMaxDistanceQueries) {
    return absl::InvalidArgumentError(absl::StrCat("neighbors: ", request.queries_size(),
                                                   " queries, at most ", kMaxDistanceQueries));
  }
  // The queries: those asked, or every model held (by id, in order).
  std::vector<v1::QueryModel> every;
  std::vector<const v1::QueryModel*> asked;
  for (const v1::QueryModel& q : request.queries()) asked.push_back(&q);
  MESHSEEK_RETURN_IF_ERROR(UseEpsilon(request.collection(), request.kl_epsilon()));
  if (asked.empty()) {
    absl::ReaderMutexLock lock(&mutex_);
    MESHSEEK_ASSIGN_OR_RETURN(const IndexCollection* collection,
                              FindCollection(request.collection(), request.kl_epsilon()));
    for (std::string& id : collection->ModelIds()) every.emplace_back().set_model_id(std::move(id));
    for (const v1::QueryModel& q : every) asked.push_back(&q);
  }
  MESHSEEK_ASSIGN_OR_RETURN(const std::vector<IndexCollection::Query> queries,
                            QueriesOf(asked, "neighbors:"));
  // A batch at a time under the reader lock, written after it: writers wait
  // for one batch at most, and a slow reader holds up nobody.
  for (std::size_t begin = 0; begin < queries.size(); begin += kNeighborBatch) {
    const std::size_t end = std::min(queries.size(), begin + kNeighborBatch);
    v1::NeighborLists lists;
    std::vector<absl::Status> errors(end - begin);
    {
      absl::ReaderMutexLock lock(&mutex_);
      MESHSEEK_ASSIGN_OR_RETURN(const IndexCollection* collection,
                                FindCollection(request.collection(), request.kl_epsilon()));
      for (std::size_t q = begin; q < end; ++q) lists.add_lists()->set_model_id(queries[q].model_id);
      ParallelFor(end - begin, options_.num_threads, [&](std::size_t i) {
        absl::StatusOr<std::vector<IndexCollection::Hit>> hits =
            collection->Neighbors(queries[begin + i], request.count(), request.candidates());
        if (hits.ok()) {
          AppendHits(*hits, lists.mutable_lists(static_cast<int>(i)));
        } else {
          errors[i] = hits.status();
        }
      });
    }
    for (const absl::Status& e : errors) MESHSEEK_RETURN_IF_ERROR(Prefixed(e, "neighbors: "));
    if (call.cancelled() || !write(lists)) return absl::CancelledError("");
  }
  return absl::OkStatus();
}

absl::StatusOr<v1::PairDistancesResponse> IndexService::PairDistances(
    const v1::PairDistancesRequest& request, const rpc::CallContext&) {
  if (request.rows_size() > kMaxDistanceQueries) {
    return absl::InvalidArgumentError(absl::StrCat("pair distances: ", request.rows_size(),
                                                   " rows, at most ", kMaxDistanceQueries));
  }
  std::size_t ids = 0;
  std::vector<const v1::QueryModel*> asked;
  for (const v1::PairRow& row : request.rows()) {
    ids += row.model_ids_size();
    asked.push_back(&row.query());
  }
  if (ids > kMaxPairIds) {
    return absl::InvalidArgumentError(
        absl::StrCat("pair distances: ", ids, " model ids, at most ", kMaxPairIds));
  }
  MESHSEEK_ASSIGN_OR_RETURN(const std::vector<IndexCollection::Query> queries,
                            QueriesOf(asked, "pair distances:"));
  MESHSEEK_RETURN_IF_ERROR(UseEpsilon(request.collection(), request.kl_epsilon()));
  absl::ReaderMutexLock lock(&mutex_);
  MESHSEEK_ASSIGN_OR_RETURN(const IndexCollection* collection,
                            FindCollection(request.collection(), request.kl_epsilon()));
  v1::PairDistancesResponse response;
  std::vector<absl::Status> errors(queries.size());
  for (const IndexCollection::Query& q : queries) response.add_rows()->set_model_id(q.model_id);
  ParallelFor(queries.size(), options_.num_threads, [&](std::size_t q) {
    absl::StatusOr<std::vector<IndexCollection::Hit>> hits =
        collection->PairDistances(queries[q], request.rows(static_cast<int>(q)).model_ids());
    if (hits.ok()) {
      AppendHits(*hits, response.mutable_rows(static_cast<int>(q)));
    } else {
      errors[q] = hits.status();
    }
  });
  for (const absl::Status& e : errors) MESHSEEK_RETURN_IF_ERROR(Prefixed(e, "pair distances: "));
  return response;
}

absl::StatusOr<v1::ListModelsResponse> IndexService::ListModels(
    const v1::ListModelsRequest& request, const rpc::CallContext&) {
  absl::ReaderMutexLock lock(&mutex_);
  v1::ListModelsResponse response;
  auto it = collections_.find(request.collection());
  if (it == collections_.end()) return response;
  for (std::string& id : it->second.ModelIds()) response.add_model_ids(std::move(id));
  return response;
}

std::size_t IndexService::MemoryBytes() {
  absl::ReaderMutexLock lock(&mutex_);
  std::size_t bytes = 0;
  for (const auto& [name, collection] : collections_) bytes += collection.MemoryBytes();
  return bytes;
}

}  // namespace meshseek
