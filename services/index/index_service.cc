#include "services/index/index_service.h"

#include <algorithm>
#include <filesystem>

#include "absl/strings/str_cat.h"
#include "common/base/status_macros.h"
#include "common/pipeline/retrieval_pipeline.h"
#include "common/rpc/convert.h"
#include "common/rpc/status.h"

namespace meshseek {

absl::Status IndexServiceOptions::Validate() const {
  if (data_dir.empty()) return absl::InvalidArgumentError("index: --data_dir is required");
  return absl::OkStatus();
}

absl::StatusOr<std::unique_ptr<IndexService>> IndexService::Create(
    const IndexServiceOptions& options) {
  MESHSEEK_RETURN_IF_ERROR(options.Validate());
  std::error_code error;
  std::filesystem::create_directories(options.data_dir, error);
  MESHSEEK_ASSIGN_OR_RETURN(std::unique_ptr<Database> db,
                            Database::Open(options.data_dir + "/index.db"));
  MESHSEEK_RETURN_IF_ERROR(db->Execute(
      "CREATE TABLE IF NOT EXISTS models (collection TEXT NOT NULL, model_id TEXT NOT NULL, "
      "ordinal INTEGER NOT NULL, label TEXT NOT NULL, histogram BLOB NOT NULL, "
      "PRIMARY KEY (collection, model_id))"));
  std::unique_ptr<IndexService> service(new IndexService(options, std::move(db)));
  MESHSEEK_RETURN_IF_ERROR(service->Load());
  return service;
}

absl::Status IndexService::Load() {
  absl::MutexLock lock(&mutex_);
  MESHSEEK_ASSIGN_OR_RETURN(
      Statement select,
      db_->Prepare("SELECT collection, model_id, ordinal, label, histogram FROM models"));
  std::size_t loaded = 0;
  while (true) {
    MESHSEEK_ASSIGN_OR_RETURN(const bool row, select.Step());
    if (!row) break;
    v1::SparseHistogram proto;
    if (!proto.ParseFromString(select.ColumnBlob(4))) {
      return absl::DataLossError(absl::StrCat("index: stored histogram of model '",
                                              select.ColumnText(1), "' does not parse"));
    }
    MESHSEEK_ASSIGN_OR_RETURN(std::vector<float> histogram, rpc::HistogramFromProto(proto));
    Entry entry{select.ColumnText(1), static_cast<uint64_t>(select.ColumnInt(2)),
                select.ColumnText(3), std::move(histogram), proto.size()};
    collections_[select.ColumnText(0)][entry.model_id] = std::move(entry);
    ++loaded;
  }
  return absl::OkStatus();
}

grpc::Status IndexService::AddModel(grpc::ServerContext*,
                                    const v1::AddModelRequest* request,
                                    v1::AddModelResponse* response) {
  if (request->collection().empty() || request->model_id().empty()) {
    return grpc::Status(grpc::StatusCode::INVALID_ARGUMENT,
                        "add: collection and model_id must not be empty");
  }
  absl::StatusOr<std::vector<float>> histogram = rpc::HistogramFromProto(request->histogram());
  if (!histogram.ok()) {
    return grpc::Status(grpc::StatusCode::INVALID_ARGUMENT,
                        absl::StrCat("add model '", request->model_id(),
                                     "': ", histogram.status().message()));
  }
  absl::MutexLock lock(&mutex_);
  auto& models = collections_[request->collection()];
  // All histograms of a collection come from one codebook: refuse another size.
  if (!histogram->empty()) {
    for (const auto& [id, other] : models) {
      if (id == request->model_id() || other.histogram.empty()) continue;
      if (other.vocabulary != request->histogram().size()) {
        return grpc::Status(
            grpc::StatusCode::INVALID_ARGUMENT,
            absl::StrCat("add model '", request->model_id(), "': histogram of size ",
                         request->histogram().size(), " but collection '", request->collection(),
                         "' holds size ", other.vocabulary, " (model '", id, "')"));
      }
      break;
    }
  }
  absl::StatusOr<Statement> upsert = db_->Prepare(
      "INSERT OR REPLACE INTO models (collection, model_id, ordinal, label, histogram) "
      "VALUES (?, ?, ?, ?, ?)");
  absl::Status stored = upsert.ok() ? upsert->Bind(1, request->collection())
                                          .Bind(2, request->model_id())
                                          .Bind(3, static_cast<int64_t>(request->ordinal()))
                                          .Bind(4, request->label())
                                          .BindBlob(5, request->histogram().SerializeAsString())
                                          .Run()
                                    : upsert.status();
  if (!stored.ok()) return rpc::ToGrpcStatus(stored);
  models[request->model_id()] = Entry{request->model_id(), request->ordinal(), request->label(),
                                      *std::move(histogram), request->histogram().size()};
  response->set_collection_size(models.size());
  return grpc::Status::OK;
}

grpc::Status IndexService::RemoveModel(grpc::ServerContext*,
                                       const v1::RemoveModelRequest* request,
                                       v1::RemoveModelResponse* response) {
  absl::MutexLock lock(&mutex_);
  absl::StatusOr<Statement> remove =
      db_->Prepare("DELETE FROM models WHERE collection = ? AND model_id = ?");
  absl::Status done = remove.ok()
                          ? remove->Bind(1, request->collection()).Bind(2, request->model_id()).Run()
                          : remove.status();
  if (!done.ok()) return rpc::ToGrpcStatus(done);
  auto it = collections_.find(request->collection());
  response->set_removed(it != collections_.end() && it->second.erase(request->model_id()) > 0);
  return grpc::Status::OK;
}

absl::StatusOr<std::vector<IndexService::Entry>> IndexService::Snapshot(
    const std::string& collection) {
  absl::MutexLock lock(&mutex_);
  auto it = collections_.find(collection);
  if (it == collections_.end() || it->second.empty()) {
    return absl::NotFoundError(absl::StrCat("index has no models in collection '", collection, "'"));
  }
  std::vector<Entry> entries;
  entries.reserve(it->second.size());
  for (const auto& [id, entry] : it->second) entries.push_back(entry);
  std::stable_sort(entries.begin(), entries.end(),
                   [](const Entry& a, const Entry& b) { return a.ordinal < b.ordinal; });
  return entries;
}

grpc::Status IndexService::Search(grpc::ServerContext*,
                                  const v1::SearchRequest* request,
                                  v1::SearchResponse* response) {
  if (request->top_k() == 0) {
    return grpc::Status(grpc::StatusCode::INVALID_ARGUMENT, "search: top_k must be at least 1");
  }
  absl::StatusOr<std::vector<float>> query = rpc::HistogramFromProto(request->histogram());
  if (!query.ok()) return rpc::ToGrpcStatus(query.status());
  absl::StatusOr<std::vector<Entry>> entries = Snapshot(request->collection());
  if (!entries.ok()) return rpc::ToGrpcStatus(entries.status());
  std::vector<std::vector<float>> histograms;
  for (const Entry& e : *entries) {
    if (!query->empty() && !e.histogram.empty() && e.histogram.size() != query->size()) {
      return grpc::Status(grpc::StatusCode::INVALID_ARGUMENT,
                          absl::StrCat("search: query histogram has size ", query->size(),
                                       ", the collection's have ", e.histogram.size()));
    }
    histograms.push_back(e.histogram);
  }
  RetrievalPipelineOptions options;
  if (request->kl_epsilon() > 0) options.kl.epsilon = request->kl_epsilon();
  options.num_threads = options_.num_threads;
  absl::StatusOr<std::vector<float>> distances = QueryDistances(*query, histograms, options);
  if (!distances.ok()) return rpc::ToGrpcStatus(distances.status());
  std::vector<std::size_t> order(entries->size());
  for (std::size_t i = 0; i < order.size(); ++i) order[i] = i;
  std::stable_sort(order.begin(), order.end(),
                   [&](std::size_t a, std::size_t b) { return (*distances)[a] < (*distances)[b]; });
  order.resize(std::min<std::size_t>(order.size(), request->top_k()));
  for (std::size_t i : order) {
    v1::ScoredModel* result = response->add_results();
    result->set_model_id((*entries)[i].model_id);
    result->set_label((*entries)[i].label);
    result->set_distance((*distances)[i]);
  }
  return grpc::Status::OK;
}

grpc::Status IndexService::DistanceMatrix(grpc::ServerContext* context,
                                          const v1::DistanceMatrixRequest* request,
                                          grpc::ServerWriter<v1::DistanceRow>* writer) {
  absl::StatusOr<std::vector<Entry>> entries = Snapshot(request->collection());
  if (!entries.ok()) return rpc::ToGrpcStatus(entries.status());
  std::vector<std::vector<float>> histograms;
  for (const Entry& e : *entries) histograms.push_back(e.histogram);
  RetrievalPipelineOptions options;
  if (request->kl_epsilon() > 0) options.kl.epsilon = request->kl_epsilon();
  options.num_threads = options_.num_threads;
  absl::StatusOr<std::vector<float>> matrix = RankCollection(histograms, options);
  if (!matrix.ok()) return rpc::ToGrpcStatus(matrix.status());
  const std::size_t n = entries->size();
  v1::DistanceRow row;
  for (std::size_t i = 0; i < n; ++i) {
    if (context->IsCancelled()) return grpc::Status::CANCELLED;
    row.set_model_id((*entries)[i].model_id);
    row.set_label((*entries)[i].label);
    row.set_ordinal((*entries)[i].ordinal);
    row.mutable_distances()->Assign(matrix->begin() + i * n, matrix->begin() + (i + 1) * n);
    if (!writer->Write(row)) return grpc::Status::CANCELLED;
  }
  return grpc::Status::OK;
}

grpc::Status IndexService::ListModels(grpc::ServerContext*,
                                      const v1::ListModelsRequest* request,
                                      v1::ListModelsResponse* response) {
  absl::StatusOr<std::vector<Entry>> entries = Snapshot(request->collection());
  if (!entries.ok()) {
    return entries.status().code() == absl::StatusCode::kNotFound
               ? grpc::Status::OK
               : rpc::ToGrpcStatus(entries.status());
  }
  for (const Entry& e : *entries) response->add_model_ids(e.model_id);
  return grpc::Status::OK;
}

}  // namespace meshseek
