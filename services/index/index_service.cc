#include "services/index/index_service.h"

#include <algorithm>
#include <filesystem>
#include <tuple>

#include "absl/strings/str_cat.h"
#include "common/base/parallel.h"
#include "common/base/status_macros.h"
#include "common/rpc/convert.h"
#include "common/rpc/status.h"

namespace meshseek {
namespace {

grpc::Status InvalidArgument(const std::string& message) {
  return grpc::Status(grpc::StatusCode::INVALID_ARGUMENT, message);
}

absl::Span<const uint8_t> AsBytes(const std::string& data) {
  return absl::MakeConstSpan(reinterpret_cast<const uint8_t*>(data.data()), data.size());
}

double EpsilonOrDefault(double epsilon) {
  return epsilon > 0 ? epsilon : KlDivergenceOptions().epsilon;
}

}  // namespace

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
  // Global descriptors (serialised GlobalDescriptor; empty for a histogram),
  // added to databases of the first release in place.
  MESHSEEK_ASSIGN_OR_RETURN(
      Statement has_descriptor,
      db->Prepare("SELECT COUNT(*) FROM pragma_table_info('models') WHERE name = 'descriptor'"));
  MESHSEEK_RETURN_IF_ERROR(has_descriptor.Step().status());
  if (has_descriptor.ColumnInt(0) == 0) {
    MESHSEEK_RETURN_IF_ERROR(
        db->Execute("ALTER TABLE models ADD COLUMN descriptor BLOB NOT NULL DEFAULT x''"));
  }
  std::unique_ptr<IndexService> service(new IndexService(options, std::move(db)));
  MESHSEEK_RETURN_IF_ERROR(service->Load());
  IndexService* index = service.get();
  service->models_gauge_ = rpc::ScrapeGauge::Register(
      "meshseek_index_models",
      "Models indexed per collection (on this server; a shard holds part of each)",
      [index]() -> absl::StatusOr<std::vector<rpc::GaugeSample>> {
        absl::ReaderMutexLock lock(&index->mutex_);
        std::vector<rpc::GaugeSample> samples;
        for (const auto& [name, collection] : index->collections_) {
          samples.push_back({{{"collection", name}}, static_cast<double>(collection.docs.size())});
        }
        return samples;
      });
  return service;
}

absl::Status IndexService::Load() {
  absl::MutexLock write(&write_mutex_);
  absl::MutexLock lock(&mutex_);
  MESHSEEK_ASSIGN_OR_RETURN(
      Statement select,
      db_->Prepare(
          "SELECT collection, model_id, ordinal, label, histogram, descriptor FROM models"));
  while (true) {
    MESHSEEK_ASSIGN_OR_RETURN(const bool row, select.Step());
    if (!row) break;
    const std::string model_id = select.ColumnText(1);
    v1::SparseHistogram histogram;
    v1::GlobalDescriptor descriptor;
    const std::string descriptor_bytes = select.ColumnBlob(5);
    absl::StatusOr<Signature> signature =
        histogram.ParseFromString(select.ColumnBlob(4)) &&
                descriptor.ParseFromString(descriptor_bytes)
            ? ParseSignature(histogram,
                             descriptor_bytes.empty() ? nullptr : &descriptor,
                             absl::StrCat("model '", model_id, "'"))
            : absl::InvalidArgumentError("does not parse");
    absl::Status placed = signature.status();
    if (placed.ok()) {
      placed = Place(&collections_[select.ColumnText(0)],
                     model_id,
                     static_cast<uint64_t>(select.ColumnInt(2)),
                     select.ColumnText(3),
                     *signature);
    }
    if (!placed.ok()) {
      return absl::DataLossError(absl::StrCat("index: stored histogram of model '", model_id,
                                              "' in collection '", select.ColumnText(0),
                                              "': ", placed.message()));
    }
  }
  return absl::OkStatus();
}

absl::StatusOr<IndexService::Signature> IndexService::ParseSignature(
    const v1::SparseHistogram& histogram,
    const v1::GlobalDescriptor* descriptor,
    const std::string& what) {
  Signature signature;
  if (descriptor == nullptr) {
    MESHSEEK_ASSIGN_OR_RETURN(signature.histogram, rpc::SparseHistogramFromProto(histogram, what));
    return signature;
  }
  if (histogram.size() != 0 || histogram.bins_size() != 0) {
    return absl::InvalidArgumentError(absl::StrCat(what, ": both a histogram and a descriptor"));
  }
  absl::StatusOr<FeatureMethod> method = ParseFeatureMethod(descriptor->method());
  if (!method.ok() || FeatureMethodInfoOf(*method).kind != DescriptorKind::kGlobal) {
    return absl::InvalidArgumentError(absl::StrCat(
        what, ": descriptor of '", descriptor->method(), "', which is not a global method"));
  }
  if (descriptor->data().empty() || descriptor->data().size() > kMaxDescriptorDimension) {
    return absl::InvalidArgumentError(absl::StrCat(what,
                                                   ": descriptor of ",
                                                   descriptor->data().size(),
                                                   " bytes, expected 1 to ",
                                                   kMaxDescriptorDimension));
  }
  signature.descriptor = *descriptor;
  return signature;
}

absl::Status IndexService::CheckFits(const Collection& collection,
                                     const std::string& model_id,
                                     const Signature& signature) {
  if (collection.docs.empty() ||
      (collection.docs.size() == 1 && collection.docs.contains(model_id))) {
    return absl::OkStatus();  // the first model (or the only one, replacing itself) decides
  }
  if (signature.descriptor.has_value()) {
    if (!collection.global.has_value()) {
      return absl::InvalidArgumentError("a descriptor, but the collection holds histograms");
    }
    const std::string& method = signature.descriptor->method();
    if (method != FeatureMethodName(collection.global->method()) ||
        signature.descriptor->data().size() != collection.global->dimension()) {
      return absl::InvalidArgumentError(absl::StrCat("a ",
                                                     method,
                                                     " descriptor of ",
                                                     signature.descriptor->data().size(),
                                                     " bytes, but the collection holds ",
                                                     FeatureMethodName(collection.global->method()),
                                                     " descriptors of ",
                                                     collection.global->dimension()));
    }
    return absl::OkStatus();
  }
  if (collection.global.has_value()) {
    return absl::InvalidArgumentError("a histogram, but the collection holds global descriptors");
  }
  if (collection.engine->vocabulary() != signature.histogram.vocabulary) {
    return absl::InvalidArgumentError(absl::StrCat("histogram of size ",
                                                   signature.histogram.vocabulary,
                                                   " but the collection holds size ",
                                                   collection.engine->vocabulary()));
  }
  return absl::OkStatus();
}

absl::Status IndexService::Place(Collection* collection,
                                 const std::string& model_id,
                                 uint64_t ordinal,
                                 const std::string& label,
                                 const Signature& signature) {
  MESHSEEK_RETURN_IF_ERROR(CheckFits(*collection, model_id, signature));
  const bool fresh = collection->docs.empty() ||
                     (collection->docs.size() == 1 && collection->docs.contains(model_id));
  if (signature.descriptor.has_value()) {
    const std::string& data = signature.descriptor->data();
    if (fresh || !collection->global.has_value()) {
      MESHSEEK_ASSIGN_OR_RETURN(const FeatureMethod method,
                                ParseFeatureMethod(signature.descriptor->method()));
      MESHSEEK_ASSIGN_OR_RETURN(GlobalDescriptorIndex global,
                                GlobalDescriptorIndex::Create(method, data.size()));
      collection->global = std::move(global);
      collection->engine.reset();
      collection->docs.clear();
      collection->models.clear();
    }
    auto [it, inserted] = collection->docs.try_emplace(model_id, collection->next_doc);
    if (inserted) ++collection->next_doc;
    MESHSEEK_RETURN_IF_ERROR(collection->global->Upsert(
        it->second,
        absl::MakeConstSpan(reinterpret_cast<const uint8_t*>(data.data()), data.size())));
    collection->models[it->second] = Model{model_id, ordinal, label};
    return absl::OkStatus();
  }
  const SparseHistogram& histogram = signature.histogram;
  if (!collection->engine.has_value() ||
      (fresh && collection->engine->vocabulary() != histogram.vocabulary)) {
    // The first model fixes the vocabulary (or the only one replaces itself).
    KlDivergenceOptions kl;
    if (collection->engine.has_value()) kl = collection->engine->options();
    MESHSEEK_ASSIGN_OR_RETURN(KlInvertedIndex engine,
                              KlInvertedIndex::Create(histogram.vocabulary, kl));
    collection->engine = std::move(engine);
    collection->global.reset();
    collection->docs.clear();
    collection->models.clear();
  }
  auto [it, inserted] = collection->docs.try_emplace(model_id, collection->next_doc);
  if (inserted) ++collection->next_doc;
  MESHSEEK_RETURN_IF_ERROR(collection->engine->Upsert(it->second, histogram));
  collection->models[it->second] = Model{model_id, ordinal, label};
  return absl::OkStatus();
}

grpc::Status IndexService::AddModel(grpc::ServerContext*,
                                    const v1::AddModelRequest* request,
                                    v1::AddModelResponse* response) {
  if (request->collection().empty() || request->model_id().empty()) {
    return InvalidArgument("add: collection and model_id must not be empty");
  }
  const std::string name = absl::StrCat("add model '", request->model_id(), "'");
  absl::StatusOr<Signature> signature =
      ParseSignature(request->histogram(),
                     request->has_global_descriptor() ? &request->global_descriptor() : nullptr,
                     name);
  if (!signature.ok()) return rpc::ToGrpcStatus(signature.status());
  absl::MutexLock write(&write_mutex_);
  {
    // Refuse what Place would refuse before anything is written.
    absl::ReaderMutexLock lock(&mutex_);
    auto it = collections_.find(request->collection());
    if (it != collections_.end()) {
      if (absl::Status fits = CheckFits(it->second, request->model_id(), *signature); !fits.ok()) {
        return InvalidArgument(
            absl::StrCat(name, " to collection '", request->collection(), "': ", fits.message()));
      }
    }
  }
  absl::StatusOr<Statement> upsert = db_->Prepare(
      "INSERT OR REPLACE INTO models (collection, model_id, ordinal, label, histogram, "
      "descriptor) VALUES (?, ?, ?, ?, ?, ?)");
  absl::Status stored = upsert.ok()
                            ? upsert->Bind(1, request->collection())
                                  .Bind(2, request->model_id())
                                  .Bind(3, static_cast<int64_t>(request->ordinal()))
                                  .Bind(4, request->label())
                                  .BindBlob(5, request->histogram().SerializeAsString())
                                  .BindBlob(6,
                                            request->has_global_descriptor()
                                                ? request->global_descriptor().SerializeAsString()
                                                : std::string())
                                  .Run()
                            : upsert.status();
  if (!stored.ok()) return rpc::ToGrpcStatus(stored);
  absl::MutexLock lock(&mutex_);
  Collection& collection = collections_[request->collection()];
  const absl::Status placed =
      Place(&collection, request->model_id(), request->ordinal(), request->label(), *signature);
  if (!placed.ok()) return rpc::ToGrpcStatus(placed);  // checked above: not reached
  response->set_collection_size(collection.docs.size());
  return grpc::Status::OK;
}

grpc::Status IndexService::RemoveModel(grpc::ServerContext*,
                                       const v1::RemoveModelRequest* request,
                                       v1::RemoveModelResponse* response) {
  absl::MutexLock write(&write_mutex_);
  absl::StatusOr<Statement> remove =
      db_->Prepare("DELETE FROM models WHERE collection = ? AND model_id = ?");
  absl::Status done = remove.ok()
                          ? remove->Bind(1, request->collection()).Bind(2, request->model_id()).Run()
                          : remove.status();
  if (!done.ok()) return rpc::ToGrpcStatus(done);
  absl::MutexLock lock(&mutex_);
  auto it = collections_.find(request->collection());
  bool removed = false;
  if (it != collections_.end()) {
    Collection& collection = it->second;
    auto doc = collection.docs.find(request->model_id());
    if (doc != collection.docs.end()) {
      if (collection.global.has_value()) {
        collection.global->Remove(doc->second);
      } else {
        collection.engine->Remove(doc->second);
      }
      collection.models.erase(doc->second);
      collection.docs.erase(doc);
      removed = true;
    }
  }
  response->set_removed(removed);
  return grpc::Status::OK;
}

void IndexService::UseEpsilon(const std::string& name, double epsilon) {
  epsilon = EpsilonOrDefault(epsilon);
  {
    absl::ReaderMutexLock lock(&mutex_);
    auto it = collections_.find(name);
    if (it == collections_.end() || !it->second.engine.has_value() ||
        it->second.engine->options().epsilon == epsilon) {
      return;
    }
  }
  absl::MutexLock lock(&mutex_);
  auto it = collections_.find(name);
  if (it == collections_.end() || !it->second.engine.has_value()) return;
  const KlInvertedIndex& old = *it->second.engine;
  if (old.options().epsilon == epsilon) return;
  KlDivergenceOptions kl = old.options();
  kl.epsilon = epsilon;
  absl::StatusOr<KlInvertedIndex> rebuilt = KlInvertedIndex::Create(old.vocabulary(), kl);
  if (!rebuilt.ok()) return;  // FindCollection reports the mismatch
  absl::Status status;
  old.ForEach([&](uint32_t doc, const SparseHistogram& histogram) {
    if (status.ok()) status = rebuilt->Upsert(doc, histogram);
  });
  if (status.ok()) it->second.engine = *std::move(rebuilt);
}

absl::StatusOr<const IndexService::Collection*> IndexService::FindCollection(
    const std::string& name, double epsilon) {
  auto it = collections_.find(name);
  if (it == collections_.end() || it->second.docs.empty()) {
    return absl::NotFoundError(absl::StrCat("index has no models in collection '", name, "'"));
  }
  if (it->second.global.has_value()) return &it->second;  // no epsilon
  if (it->second.engine->options().epsilon != EpsilonOrDefault(epsilon)) {
    return absl::AbortedError(absl::StrCat("collection '", name, "' is ranked with KL epsilon ",
                                           it->second.engine->options().epsilon,
                                           " (changed meanwhile); retry"));
  }
  return &it->second;
}

std::vector<uint32_t> IndexService::DocsInOrder(const Collection& collection) {
  std::vector<uint32_t> docs;
  docs.reserve(collection.models.size());
  for (const auto& [doc, model] : collection.models) docs.push_back(doc);
  SortDocs(collection, &docs);
  return docs;
}

std::vector<uint32_t> IndexService::DocsInOrder(
    const Collection& collection, const google::protobuf::RepeatedPtrField<std::string>& model_ids) {
  std::vector<uint32_t> docs;
  for (const std::string& id : model_ids) {
    const auto it = collection.docs.find(id);
    if (it != collection.docs.end()) docs.push_back(it->second);
  }
  std::sort(docs.begin(), docs.end());
  docs.erase(std::unique(docs.begin(), docs.end()), docs.end());
  SortDocs(collection, &docs);
  return docs;
}

void IndexService::SortDocs(const Collection& collection, std::vector<uint32_t>* docs) {
  std::sort(docs->begin(), docs->end(), [&](uint32_t a, uint32_t b) {
    const Model& x = collection.models.at(a);
    const Model& y = collection.models.at(b);
    return std::tie(x.ordinal, x.model_id) < std::tie(y.ordinal, y.model_id);
  });
}

grpc::Status IndexService::Search(grpc::ServerContext*,
                                  const v1::SearchRequest* request,
                                  v1::SearchResponse* response) {
  if (request->top_k() == 0) return InvalidArgument("search: top_k must be at least 1");
  absl::StatusOr<Signature> query =
      ParseSignature(request->histogram(),
                     request->has_global_descriptor() ? &request->global_descriptor() : nullptr,
                     "search: query");
  if (!query.ok()) return rpc::ToGrpcStatus(query.status());
  if (!query->descriptor.has_value()) UseEpsilon(request->collection(), request->kl_epsilon());
  absl::ReaderMutexLock lock(&mutex_);
  absl::StatusOr<const Collection*> collection =
      FindCollection(request->collection(), request->kl_epsilon());
  if (!collection.ok()) return rpc::ToGrpcStatus(collection.status());
  if (absl::Status fits = CheckFits(**collection, "", *query); !fits.ok()) {
    return InvalidArgument(absl::StrCat("search '", request->collection(), "': ", fits.message()));
  }
  const std::size_t candidates =
      request->candidates() == 0 ? 0 : std::max(request->candidates(), request->top_k());
  absl::StatusOr<std::vector<KlNeighbor>> found =
      query->descriptor.has_value()
          ? (*collection)
                ->global->Search(
                    AsBytes(query->descriptor->data()), request->top_k(), options_.num_threads)
          : (*collection)
                ->engine->Search(
                    query->histogram, request->top_k(), options_.num_threads, candidates);
  if (!found.ok()) return rpc::ToGrpcStatus(found.status());
  // The engine breaks ties by doc and returns every model tied with the k-th:
  // rank ties by ordinal (then id) as the whole collection would be.
  struct Hit {
    float distance;
    const Model* model;
  };
  std::vector<Hit> hits;
  hits.reserve(found->size());
  for (const KlNeighbor& nb : *found) hits.push_back({nb.distance, &(*collection)->models.at(nb.doc)});
  std::sort(hits.begin(), hits.end(), [](const Hit& a, const Hit& b) {
    return std::tie(a.distance, a.model->ordinal, a.model->model_id) <
           std::tie(b.distance, b.model->ordinal, b.model->model_id);
  });
  hits.resize(std::min<std::size_t>(hits.size(), request->top_k()));
  for (const Hit& hit : hits) {
    v1::ScoredModel* result = response->add_results();
    result->set_model_id(hit.model->model_id);
    result->set_label(hit.model->label);
    result->set_distance(hit.distance);
    result->set_ordinal(hit.model->ordinal);
  }
  return grpc::Status::OK;
}

grpc::Status IndexService::ExportModels(grpc::ServerContext* context,
                                        const v1::ExportModelsRequest* request,
                                        grpc::ServerWriter<v1::IndexedModel>* writer) {
  // Copied under the lock, streamed after it: a slow reader never holds up
  // writers. Meant for evaluation-sized collections.
  std::vector<v1::IndexedModel> models;
  {
    absl::ReaderMutexLock lock(&mutex_);
    auto it = collections_.find(request->collection());
    if (it == collections_.end() || it->second.docs.empty()) {
      return grpc::Status(
          grpc::StatusCode::NOT_FOUND,
          absl::StrCat("index has no models in collection '", request->collection(), "'"));
    }
    const Collection& collection = it->second;
    const std::vector<uint32_t> docs = DocsInOrder(collection);
    absl::flat_hash_map<uint32_t, std::size_t> position;
    for (std::size_t i = 0; i < docs.size(); ++i) position[docs[i]] = i;
    models.resize(docs.size());
    auto describe = [&](uint32_t doc) -> v1::IndexedModel& {
      v1::IndexedModel& out = models[position.at(doc)];
      const Model& model = collection.models.at(doc);
      out.set_model_id(model.model_id);
      out.set_ordinal(model.ordinal);
      out.set_label(model.label);
      return out;
    };
    if (collection.global.has_value()) {
      const char* method = FeatureMethodName(collection.global->method());
      collection.global->ForEach([&](uint32_t doc, absl::Span<const uint8_t> bytes) {
        v1::GlobalDescriptor* d = describe(doc).mutable_global_descriptor();
        d->set_method(method);
        d->set_data(bytes.data(), bytes.size());
      });
    } else {
      collection.engine->ForEach([&](uint32_t doc, const SparseHistogram& histogram) {
        rpc::SparseHistogramToProto(histogram, describe(doc).mutable_histogram());
      });
    }
  }
  for (const v1::IndexedModel& model : models) {
    if (context->IsCancelled() || !writer->Write(model)) return grpc::Status::CANCELLED;
  }
  return grpc::Status::OK;
}

grpc::Status IndexService::Distances(grpc::ServerContext*,
                                     const v1::DistancesRequest* request,
                                     v1::DistancesResponse* response) {
  const int total = request->queries_size() + request->global_queries_size();
  if (total > kMaxDistanceQueries) {
    return InvalidArgument(absl::StrCat(
        "distances: ", total, " queries, at most ", kMaxDistanceQueries, " per request"));
  }
  if (request->queries_size() > 0 && request->global_queries_size() > 0) {
    return InvalidArgument("distances: both histogram and descriptor queries");
  }
  if (request->model_ids_size() > kMaxDistanceModels) {
    return InvalidArgument(absl::StrCat("distances: ", request->model_ids_size(),
                                        " model ids, at most ", kMaxDistanceModels,
                                        " per request"));
  }
  std::vector<Signature> queries;
  for (int q = 0; q < request->queries_size(); ++q) {
    absl::StatusOr<Signature> query =
        ParseSignature(request->queries(q), nullptr, absl::StrCat("distances: query ", q));
    if (!query.ok()) return rpc::ToGrpcStatus(query.status());
    queries.push_back(*std::move(query));
  }
  for (int q = 0; q < request->global_queries_size(); ++q) {
    absl::StatusOr<Signature> query = ParseSignature(
        v1::SparseHistogram(), &request->global_queries(q), absl::StrCat("distances: query ", q));
    if (!query.ok()) return rpc::ToGrpcStatus(query.status());
    queries.push_back(*std::move(query));
  }
  if (request->queries_size() > 0) UseEpsilon(request->collection(), request->kl_epsilon());
  absl::ReaderMutexLock lock(&mutex_);
  absl::StatusOr<const Collection*> found =
      FindCollection(request->collection(), request->kl_epsilon());
  if (!found.ok()) return rpc::ToGrpcStatus(found.status());
  const Collection& collection = **found;
  for (std::size_t q = 0; q < queries.size(); ++q) {
    // An empty histogram (a model without features) is every model's
    // stranger, whatever the vocabulary.
    if (!queries[q].descriptor.has_value() && queries[q].histogram.words.empty()) continue;
    if (absl::Status fits = CheckFits(collection, "", queries[q]); !fits.ok()) {
      return InvalidArgument(absl::StrCat("distances: query ", q, ": ", fits.message()));
    }
  }
  // Every model, or those asked for (exact distances from the forward
  // index, not a scan: what a fused query's candidates need).
  const bool subset = request->model_ids_size() > 0;
  const std::vector<uint32_t> docs =
      subset ? DocsInOrder(collection, request->model_ids()) : DocsInOrder(collection);
  absl::flat_hash_map<uint32_t, std::size_t> column;
  for (std::size_t i = 0; i < docs.size(); ++i) {
    column[docs[i]] = i;
    const Model& model = collection.models.at(docs[i]);
    response->add_model_ids(model.model_id);
    response->add_ordinals(model.ordinal);
  }
  const std::size_t n = docs.size();
  response->mutable_distances()->Resize(static_cast<int>(queries.size() * n), 0.0f);
  float* out = response->mutable_distances()->mutable_data();
  std::vector<absl::Status> errors(queries.size());
  ParallelFor(queries.size(), options_.num_threads, [&](std::size_t q) {
    absl::StatusOr<std::vector<KlNeighbor>> row;
    if (queries[q].descriptor.has_value()) {
      const auto bytes = AsBytes(queries[q].descriptor->data());
      row = subset ? collection.global->DistancesTo(bytes, docs)
                   : collection.global->Distances(bytes, 1);
    } else {
      row = subset ? collection.engine->DistancesTo(queries[q].histogram, docs, 1)
                   : collection.engine->Distances(queries[q].histogram, 1);
    }
    if (!row.ok()) {
      errors[q] = row.status();
      return;
    }
    for (const KlNeighbor& nb : *row) out[q * n + column.at(nb.doc)] = nb.distance;
  });
  for (const absl::Status& error : errors) {
    if (!error.ok()) return rpc::ToGrpcStatus(error);
  }
  return grpc::Status::OK;
}

grpc::Status IndexService::ListModels(grpc::ServerContext*,
                                      const v1::ListModelsRequest* request,
                                      v1::ListModelsResponse* response) {
  absl::ReaderMutexLock lock(&mutex_);
  auto it = collections_.find(request->collection());
  if (it == collections_.end()) return grpc::Status::OK;
  for (uint32_t doc : DocsInOrder(it->second)) {
    response->add_model_ids(it->second.models.at(doc).model_id);
  }
  return grpc::Status::OK;
}

std::size_t IndexService::MemoryBytes() {
  absl::ReaderMutexLock lock(&mutex_);
  std::size_t bytes = 0;
  for (const auto& [name, collection] : collections_) {
    if (collection.engine.has_value()) bytes += collection.engine->MemoryBytes();
    if (collection.global.has_value()) bytes += collection.global->MemoryBytes();
  }
  return bytes;
}

}  // namespace meshseek
