#include "services/index/index_collection.h"

#include <algorithm>
#include <tuple>

#include "absl/strings/str_cat.h"
#include "common/base/parallel.h"
#include "common/base/status_macros.h"
#include "common/wire/convert.h"

namespace meshseek {

// A query as an engine takes it: a doc it holds (read from the engine, not
// prepared again), or a signature given whole.
struct EngineQuery {
  std::optional<uint32_t> doc;
  const ModelSignature* signature = nullptr;
};

namespace {

absl::Span<const uint8_t> DescriptorBytes(const ModelSignature& signature) {
  const std::string& data = signature.descriptor->data();
  return absl::MakeConstSpan(reinterpret_cast<const uint8_t*>(data.data()), data.size());
}

// What each operation is on either engine: one overload per engine, so a
// caller visits the collection's engine once and never chooses between them.
absl::Status Upsert(KlInvertedIndex& engine, uint32_t doc, const ModelSignature& signature) {
  return engine.Upsert(doc, signature.histogram);
}
absl::Status Upsert(GlobalDescriptorIndex& engine, uint32_t doc, const ModelSignature& signature) {
  return engine.Upsert(doc, DescriptorBytes(signature));
}

absl::StatusOr<std::vector<KlNeighbor>> Search(const KlInvertedIndex& engine,
                                               const EngineQuery& query,
                                               std::size_t top_k,
                                               std::size_t candidates,
                                               int num_threads) {
  return query.doc.has_value()
             ? engine.SearchStored(*query.doc, top_k, num_threads, candidates)
             : engine.Search(query.signature->histogram, top_k, num_threads, candidates);
}
absl::StatusOr<absl::Span<const uint8_t>> QueryBytes(const GlobalDescriptorIndex& engine,
                                                     const EngineQuery& query) {
  if (query.doc.has_value()) return engine.Descriptor(*query.doc);
  return DescriptorBytes(*query.signature);
}
absl::StatusOr<std::vector<KlNeighbor>> Search(const GlobalDescriptorIndex& engine,
                                               const EngineQuery& query,
                                               std::size_t top_k,
                                               std::size_t /*candidates: always exact*/,
                                               int num_threads) {
  MESHSEEK_ASSIGN_OR_RETURN(const absl::Span<const uint8_t> bytes, QueryBytes(engine, query));
  return engine.Search(bytes, top_k, num_threads);
}

// To every doc (`docs` nullptr) or to `docs`; single-threaded: the caller
// runs queries in parallel.
absl::StatusOr<std::vector<KlNeighbor>> Distances(const KlInvertedIndex& engine,
                                                  const EngineQuery& query,
                                                  const std::vector<uint32_t>* docs) {
  if (docs == nullptr) {
    if (!query.doc.has_value()) return engine.Distances(query.signature->histogram, 1);
    MESHSEEK_ASSIGN_OR_RETURN(const SparseHistogram histogram, engine.Histogram(*query.doc));
    return engine.Distances(histogram, 1);
  }
  return query.doc.has_value() ? engine.DistancesFromStored(*query.doc, *docs, 1)
                               : engine.DistancesTo(query.signature->histogram, *docs, 1);
}
absl::StatusOr<std::vector<KlNeighbor>> Distances(const GlobalDescriptorIndex& engine,
                                                  const EngineQuery& query,
                                                  const std::vector<uint32_t>* docs) {
  MESHSEEK_ASSIGN_OR_RETURN(const absl::Span<const uint8_t> bytes, QueryBytes(engine, query));
  return docs != nullptr ? engine.DistancesTo(bytes, *docs) : engine.Distances(bytes, 1);
}

template <typename Describe>
void Export(const KlInvertedIndex& engine, Describe&& describe) {
  engine.ForEach([&](uint32_t doc, const SparseHistogram& histogram) {
    wire::SparseHistogramToProto(histogram, describe(doc).mutable_histogram());
  });
}
void ExportOne(const KlInvertedIndex& engine, uint32_t doc, v1::IndexedModel& out) {
  wire::SparseHistogramToProto(*engine.Histogram(doc), out.mutable_histogram());  // doc is held
}
void ExportOne(const GlobalDescriptorIndex& engine, uint32_t doc, v1::IndexedModel& out) {
  const absl::Span<const uint8_t> bytes = *engine.Descriptor(doc);  // doc is held
  v1::GlobalDescriptor* descriptor = out.mutable_global_descriptor();
  descriptor->set_method(FeatureMethodName(engine.method()));
  descriptor->set_data(bytes.data(), bytes.size());
}
template <typename Describe>
void Export(const GlobalDescriptorIndex& engine, Describe&& describe) {
  const char* method = FeatureMethodName(engine.method());
  engine.ForEach([&](uint32_t doc, absl::Span<const uint8_t> bytes) {
    v1::GlobalDescriptor* descriptor = describe(doc).mutable_global_descriptor();
    descriptor->set_method(method);
    descriptor->set_data(bytes.data(), bytes.size());
  });
}

}  // namespace

absl::StatusOr<ModelSignature> ModelSignature::Parse(const v1::SparseHistogram& histogram,
                                                     const v1::GlobalDescriptor* descriptor,
                                                     const std::string& what) {
  ModelSignature signature;
  if (descriptor == nullptr) {
    MESHSEEK_ASSIGN_OR_RETURN(signature.histogram, wire::SparseHistogramFromProto(histogram, what));
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
    return absl::InvalidArgumentError(absl::StrCat(what, ": descriptor of ",
                                                   descriptor->data().size(),
                                                   " bytes, expected 1 to ",
                                                   kMaxDescriptorDimension));
  }
  signature.descriptor = *descriptor;
  return signature;
}

absl::Status IndexCollection::CheckFits(const std::string& model_id,
                                        const ModelSignature& signature) const {
  if (docs_.empty() || (docs_.size() == 1 && docs_.contains(model_id))) {
    return absl::OkStatus();  // the first model (or the only one, replacing itself) decides
  }
  if (const auto* global = std::get_if<GlobalDescriptorIndex>(&*engine_)) {
    if (!signature.descriptor.has_value()) {
      return absl::InvalidArgumentError("a histogram, but the collection holds global descriptors");
    }
    const std::string& method = signature.descriptor->method();
    if (method != FeatureMethodName(global->method()) ||
        signature.descriptor->data().size() != global->dimension()) {
      return absl::InvalidArgumentError(absl::StrCat(
          "a ", method, " descriptor of ", signature.descriptor->data().size(),
          " bytes, but the collection holds ", FeatureMethodName(global->method()),
          " descriptors of ", global->dimension()));
    }
    return absl::OkStatus();
  }
  if (signature.descriptor.has_value()) {
    return absl::InvalidArgumentError("a descriptor, but the collection holds histograms");
  }
  const uint32_t vocabulary = std::get<KlInvertedIndex>(*engine_).vocabulary();
  if (vocabulary != signature.histogram.vocabulary) {
    return absl::InvalidArgumentError(absl::StrCat("histogram of size ",
                                                   signature.histogram.vocabulary,
                                                   " but the collection holds size ", vocabulary));
  }
  return absl::OkStatus();
}

absl::Status IndexCollection::PrepareEngine(const std::string& model_id,
                                            const ModelSignature& signature) {
  const bool fresh = docs_.empty() || (docs_.size() == 1 && docs_.contains(model_id));
  const auto* kl = engine_.has_value() ? std::get_if<KlInvertedIndex>(&*engine_) : nullptr;
  if (signature.descriptor.has_value()) {
    if (!fresh && engine_.has_value() && kl == nullptr) return absl::OkStatus();
    MESHSEEK_ASSIGN_OR_RETURN(const FeatureMethod method,
                              ParseFeatureMethod(signature.descriptor->method()));
    MESHSEEK_ASSIGN_OR_RETURN(
        GlobalDescriptorIndex global,
        GlobalDescriptorIndex::Create(method, signature.descriptor->data().size()));
    engine_.emplace(std::move(global));
  } else {
    const uint32_t vocabulary = signature.histogram.vocabulary;
    if (kl != nullptr && !(fresh && kl->vocabulary() != vocabulary)) return absl::OkStatus();
    // The first model fixes the vocabulary (or the only one replaces itself);
    // the epsilon stays.
    const KlDivergenceOptions options = kl != nullptr ? kl->options() : KlDivergenceOptions();
    MESHSEEK_ASSIGN_OR_RETURN(KlInvertedIndex engine, KlInvertedIndex::Create(vocabulary, options, storage_));
    engine_.emplace(std::move(engine));
  }
  docs_.clear();
  models_.clear();
  return absl::OkStatus();
}

absl::Status IndexCollection::Place(const std::string& model_id,
                                    uint64_t ordinal,
                                    const std::string& label,
                                    const ModelSignature& signature) {
  MESHSEEK_RETURN_IF_ERROR(CheckFits(model_id, signature));
  MESHSEEK_RETURN_IF_ERROR(PrepareEngine(model_id, signature));
  auto [it, inserted] = docs_.try_emplace(model_id, next_doc_);
  if (inserted) ++next_doc_;
  const uint32_t doc = it->second;
  MESHSEEK_RETURN_IF_ERROR(
      std::visit([&](auto& engine) { return Upsert(engine, doc, signature); }, *engine_));
  models_[doc] = Model{model_id, ordinal, label};
  return absl::OkStatus();
}

bool IndexCollection::Remove(const std::string& model_id) {
  auto it = docs_.find(model_id);
  if (it == docs_.end()) return false;
  std::visit([doc = it->second](auto& engine) { engine.Remove(doc); }, *engine_);
  models_.erase(it->second);
  docs_.erase(it);
  return true;
}

std::optional<double> IndexCollection::epsilon() const {
  const auto* kl = engine_.has_value() ? std::get_if<KlInvertedIndex>(&*engine_) : nullptr;
  if (kl == nullptr) return std::nullopt;
  return kl->options().epsilon;
}

absl::Status IndexCollection::SetEpsilon(double epsilon) {
  auto* kl = engine_.has_value() ? std::get_if<KlInvertedIndex>(&*engine_) : nullptr;
  if (kl == nullptr || kl->options().epsilon == epsilon) return absl::OkStatus();
  KlDivergenceOptions options = kl->options();
  options.epsilon = epsilon;
  MESHSEEK_ASSIGN_OR_RETURN(KlInvertedIndex rebuilt,
                            KlInvertedIndex::Create(kl->vocabulary(), options, storage_));
  absl::Status status;
  kl->ForEach([&](uint32_t doc, const SparseHistogram& histogram) {
    if (status.ok()) status = rebuilt.Upsert(doc, histogram);
  });
  MESHSEEK_RETURN_IF_ERROR(status);
  engine_.emplace(std::move(rebuilt));
  return absl::OkStatus();
}

absl::StatusOr<std::vector<IndexCollection::Hit>> IndexCollection::Search(
    const ModelSignature& query, std::size_t top_k, std::size_t candidates, int num_threads) const {
  MESHSEEK_RETURN_IF_ERROR(CheckFits("", query));
  if (empty()) return std::vector<Hit>();
  const EngineQuery q{std::nullopt, &query};
  MESHSEEK_ASSIGN_OR_RETURN(
      const std::vector<KlNeighbor> found,
      std::visit(
          [&](const auto& engine) { return meshseek::Search(engine, q, top_k, candidates, num_threads); },
          *engine_));
  return Ranked(found, top_k);
}

absl::StatusOr<std::vector<IndexCollection::Hit>> IndexCollection::SearchView(
    absl::string_view view, std::size_t top_k, int num_threads) const {
  if (empty()) return std::vector<Hit>();
  const auto* global = std::get_if<GlobalDescriptorIndex>(&*engine_);
  if (global == nullptr) {
    return absl::InvalidArgumentError(
        "a collection of histograms cannot be searched by a picture (it needs lfd's views)");
  }
  MESHSEEK_ASSIGN_OR_RETURN(
      const std::vector<KlNeighbor> found,
      global->SearchView(
          absl::MakeConstSpan(reinterpret_cast<const uint8_t*>(view.data()), view.size()), top_k,
          num_threads));
  return Ranked(found, top_k);
}

std::vector<IndexCollection::Hit> IndexCollection::Ranked(const std::vector<KlNeighbor>& found,
                                                          std::size_t top_k) const {
  // The engine breaks ties by doc and returns every model tied with the k-th:
  // rank ties by ordinal (then id) as the whole collection would be.
  std::vector<Hit> hits;
  hits.reserve(found.size());
  for (const KlNeighbor& nb : found) hits.push_back({nb.distance, &models_.at(nb.doc)});
  std::sort(hits.begin(), hits.end(), [](const Hit& a, const Hit& b) {
    return std::tie(a.distance, a.model->ordinal, a.model->model_id) <
           std::tie(b.distance, b.model->ordinal, b.model->model_id);
  });
  hits.resize(std::min(hits.size(), top_k));
  return hits;
}

absl::StatusOr<std::vector<IndexCollection::Hit>> IndexCollection::Neighbors(
    const Query& query, std::size_t count, std::size_t candidates) const {
  if (empty()) return std::vector<Hit>();
  MESHSEEK_ASSIGN_OR_RETURN(const auto resolved, Resolve(query));
  MESHSEEK_ASSIGN_OR_RETURN(
      const std::vector<KlNeighbor> found,
      std::visit(
          [&](const auto& engine) { return meshseek::Search(engine, resolved, count, candidates, 1); },
          *engine_));
  return Ranked(found, count);
}

absl::StatusOr<std::vector<IndexCollection::Hit>> IndexCollection::PairDistances(
    const Query& query, const google::protobuf::RepeatedPtrField<std::string>& model_ids) const {
  if (empty()) return std::vector<Hit>();
  MESHSEEK_ASSIGN_OR_RETURN(const auto resolved, Resolve(query));
  const std::vector<uint32_t> docs = DocsInOrder(model_ids);
  MESHSEEK_ASSIGN_OR_RETURN(
      const std::vector<KlNeighbor> found,
      std::visit([&](const auto& engine) { return meshseek::Distances(engine, resolved, &docs); },
                 *engine_));
  std::vector<Hit> hits;
  hits.reserve(found.size());
  for (const KlNeighbor& nb : found) hits.push_back({nb.distance, &models_.at(nb.doc)});
  return hits;
}

absl::StatusOr<EngineQuery> IndexCollection::Resolve(const Query& query) const {
  if (query.signature.has_value()) {
    const bool stranger = !query.signature->descriptor.has_value() &&
                          query.signature->histogram.words.empty() &&
                          std::holds_alternative<KlInvertedIndex>(*engine_);
    if (!stranger) {
      if (absl::Status fits = CheckFits("", *query.signature); !fits.ok()) {
        return absl::InvalidArgumentError(
            absl::StrCat("query '", query.model_id, "': ", fits.message()));
      }
    }
    return EngineQuery{std::nullopt, &*query.signature};
  }
  const auto it = docs_.find(query.model_id);
  if (it == docs_.end()) {
    return absl::NotFoundError(
        absl::StrCat("query '", query.model_id, "' is not held by this index; send it whole"));
  }
  return EngineQuery{it->second, nullptr};
}

absl::Status IndexCollection::Distances(
    const std::vector<ModelSignature>& queries,
    const google::protobuf::RepeatedPtrField<std::string>& model_ids,
    int num_threads,
    v1::DistancesResponse* response) const {
  if (empty()) return absl::OkStatus();
  const bool to_histograms = std::holds_alternative<KlInvertedIndex>(*engine_);
  for (std::size_t q = 0; q < queries.size(); ++q) {
    const bool stranger = to_histograms && !queries[q].descriptor.has_value() &&
                          queries[q].histogram.words.empty();
    if (stranger) continue;
    if (absl::Status fits = CheckFits("", queries[q]); !fits.ok()) {
      return absl::InvalidArgumentError(absl::StrCat("query ", q, ": ", fits.message()));
    }
  }
  // Every model, or those asked for (exact distances from the forward
  // index, not a scan: what a fused query's candidates need).
  const bool subset = !model_ids.empty();
  const std::vector<uint32_t> docs = subset ? DocsInOrder(model_ids) : DocsInOrder();
  absl::flat_hash_map<uint32_t, std::size_t> column;
  for (std::size_t i = 0; i < docs.size(); ++i) {
    column[docs[i]] = i;
    const Model& model = models_.at(docs[i]);
    response->add_model_ids(model.model_id);
    response->add_ordinals(model.ordinal);
  }
  const std::size_t n = docs.size();
  response->mutable_distances()->Resize(static_cast<int>(queries.size() * n), 0.0f);
  float* out = response->mutable_distances()->mutable_data();
  std::vector<absl::Status> errors(queries.size());
  ParallelFor(queries.size(), num_threads, [&](std::size_t q) {
    const EngineQuery query{std::nullopt, &queries[q]};
    absl::StatusOr<std::vector<KlNeighbor>> row = std::visit(
        [&](const auto& engine) { return meshseek::Distances(engine, query, subset ? &docs : nullptr); },
        *engine_);
    if (!row.ok()) {
      errors[q] = row.status();
      return;
    }
    for (const KlNeighbor& nb : *row) out[q * n + column.at(nb.doc)] = nb.distance;
  });
  for (const absl::Status& error : errors) MESHSEEK_RETURN_IF_ERROR(error);
  return absl::OkStatus();
}

std::vector<v1::IndexedModel> IndexCollection::Export(
    const google::protobuf::RepeatedPtrField<std::string>& model_ids, bool signatures) const {
  if (empty()) return {};
  const std::vector<uint32_t> docs = model_ids.empty() ? DocsInOrder() : DocsInOrder(model_ids);
  std::vector<v1::IndexedModel> models(docs.size());
  absl::flat_hash_map<uint32_t, std::size_t> position;
  for (std::size_t i = 0; i < docs.size(); ++i) {
    position[docs[i]] = i;
    const Model& model = models_.at(docs[i]);
    models[i].set_model_id(model.model_id);
    models[i].set_ordinal(model.ordinal);
    models[i].set_label(model.label);
  }
  if (!signatures) return models;
  auto describe = [&](uint32_t doc) -> v1::IndexedModel& { return models[position.at(doc)]; };
  // Every model: one pass over the engine; a few: each read on its own.
  std::visit(
      [&](const auto& engine) {
        if (model_ids.empty()) {
          meshseek::Export(engine, describe);
        } else {
          for (uint32_t doc : docs) ExportOne(engine, doc, describe(doc));
        }
      },
      *engine_);
  return models;
}

std::vector<std::string> IndexCollection::ModelIds() const {
  std::vector<std::string> ids;
  for (uint32_t doc : DocsInOrder()) ids.push_back(models_.at(doc).model_id);
  return ids;
}

std::size_t IndexCollection::MemoryBytes() const {
  if (!engine_.has_value()) return 0;
  return std::visit([](const auto& engine) { return engine.MemoryBytes(); }, *engine_);
}

std::vector<uint32_t> IndexCollection::DocsInOrder() const {
  std::vector<uint32_t> docs;
  docs.reserve(models_.size());
  for (const auto& [doc, model] : models_) docs.push_back(doc);
  SortDocs(&docs);
  return docs;
}

std::vector<uint32_t> IndexCollection::DocsInOrder(
    const google::protobuf::RepeatedPtrField<std::string>& model_ids) const {
  std::vector<uint32_t> docs;
  for (const std::string& id : model_ids) {
    const auto it = docs_.find(id);
    if (it != docs_.end()) docs.push_back(it->second);
  }
  std::sort(docs.begin(), docs.end());
  docs.erase(std::unique(docs.begin(), docs.end()), docs.end());
  SortDocs(&docs);
  return docs;
}

void IndexCollection::SortDocs(std::vector<uint32_t>* docs) const {
  std::sort(docs->begin(), docs->end(), [&](uint32_t a, uint32_t b) {
    const Model& x = models_.at(a);
    const Model& y = models_.at(b);
    return std::tie(x.ordinal, x.model_id) < std::tie(y.ordinal, y.model_id);
  });
}

}  // namespace meshseek
