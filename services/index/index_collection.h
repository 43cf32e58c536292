// One collection of the index service in memory: its models (id, ordinal,
// label) and the engine that ranks them, whichever of the two it is:
//   - an inverted file over bag-of-features histograms, ranked by exact
//     symmetric KL divergence (common/search/kl_inverted_index.h), for the
//     local-feature methods;
//   - a flat table of global descriptors ranked by the method's own distance
//     (common/search/global_descriptor_index.h), for a global method (LFD).
// The first model placed chooses the engine, its vocabulary or its method and
// size; every later model must fit them (CheckFits). The only model may
// replace itself with another kind.
//
// Models get dense internal docs in the order first placed; every answer is
// in (ordinal, model id) order, the collection's ingest order, so a matrix or
// a tie does not depend on the order models arrived in.
//
// Not thread-safe for writers; const methods may run concurrently (the
// service holds a reader lock for them, index_service.h).
#ifndef MESHSEEK_SERVICES_INDEX_INDEX_COLLECTION_H_
#define MESHSEEK_SERVICES_INDEX_INDEX_COLLECTION_H_

#include <cstdint>
#include <optional>
#include <string>
#include <variant>
#include <vector>

#include "absl/container/flat_hash_map.h"
#include "absl/status/statusor.h"
#include "absl/strings/string_view.h"
#include "common/search/global_descriptor_index.h"
#include "common/search/kl_inverted_index.h"
#include "meshseek/v1/index.pb.h"

namespace meshseek {

/// What one model (or a query) is ranked by: a histogram, or a global
/// descriptor.
struct ModelSignature {
  SparseHistogram histogram;
  std::optional<v1::GlobalDescriptor> descriptor;

  /// The signature of a request, checked: InvalidArgument naming `what`.
  /// `descriptor` nullptr: a histogram.
  static absl::StatusOr<ModelSignature> Parse(const v1::SparseHistogram& histogram,
                                              const v1::GlobalDescriptor* descriptor,
                                              const std::string& what);
};

struct EngineQuery;  // index_collection.cc

class IndexCollection {
 public:
  /// Where its histogram engine keeps what grows (kl_inverted_index.h).
  explicit IndexCollection(KlIndexStorage storage = {}) : storage_(std::move(storage)) {}

  struct Model {
    std::string model_id;
    uint64_t ordinal = 0;
    std::string label;
  };
  struct Hit {
    float distance = 0;
    const Model* model = nullptr;
  };

  std::size_t size() const { return docs_.size(); }
  bool empty() const { return docs_.empty(); }

  /// Why `signature` cannot join (another kind, vocabulary, method or size),
  /// or OK. `model_id` may replace the only model.
  absl::Status CheckFits(const std::string& model_id, const ModelSignature& signature) const;
  /// Adds or replaces `model_id` (what CheckFits refuses, refused alike).
  absl::Status Place(const std::string& model_id,
                     uint64_t ordinal,
                     const std::string& label,
                     const ModelSignature& signature);
  /// False if it was not there.
  bool Remove(const std::string& model_id);

  /// The KL epsilon histograms are ranked with; nullopt for descriptors (no
  /// epsilon) and before the first model.
  std::optional<double> epsilon() const;
  /// Ranks histograms with `epsilon` from now on, rebuilding the inverted
  /// file (collections keep one epsilon, so this happens once if ever). No-op
  /// for descriptors.
  absl::Status SetEpsilon(double epsilon);

  /// The `top_k` nearest models to a query that fits, in (distance, ordinal,
  /// model id) order. `candidates` > 0: the inverted file's approximate first
  /// stage (kl_inverted_index.h); descriptors are always scanned exactly.
  absl::StatusOr<std::vector<Hit>> Search(const ModelSignature& query,
                                          std::size_t top_k,
                                          std::size_t candidates,
                                          int num_threads) const;
  /// The `top_k` nearest models to one view of a picture (`view`, the
  /// method's view_bytes: lfd.h DescribeLfdSilhouette) in a collection of
  /// views (LFD), each model at its nearest view, in (distance, ordinal,
  /// model id) order. InvalidArgument for a collection of another kind or a
  /// view of another size.
  absl::StatusOr<std::vector<Hit>> SearchView(absl::string_view view,
                                              std::size_t top_k,
                                              int num_threads) const;
  /// Each query's distance to every model, or to those of `model_ids` held
  /// (each once) when it is not empty, as the Distances RPC answers: the
  /// models in order, then the row-major matrix. An empty histogram query
  /// (a model without features) skips the fit check: it is every model's
  /// stranger, whatever the vocabulary.
  absl::Status Distances(const std::vector<ModelSignature>& queries,
                         const google::protobuf::RepeatedPtrField<std::string>& model_ids,
                         int num_threads,
                         v1::DistancesResponse* response) const;
  /// A query of Neighbors or PairDistances: a model held here, by id
  /// (`signature` empty), or one given whole.
  struct Query {
    std::string model_id;
    std::optional<ModelSignature> signature;
  };
  /// The query's `count` nearest models in (distance, ordinal, model id)
  /// order, exact on `candidates` proposals when > 0 (as Search); one
  /// thread, so a caller runs many queries in parallel. NotFound for a query
  /// by id not held here; InvalidArgument for one given whole that does not
  /// fit (an empty histogram fits: every model's stranger).
  absl::StatusOr<std::vector<Hit>> Neighbors(const Query& query,
                                             std::size_t count,
                                             std::size_t candidates) const;
  /// The query's exact distances to those of `model_ids` held here, in
  /// (ordinal, model id) order; one thread. Errors as Neighbors.
  absl::StatusOr<std::vector<Hit>> PairDistances(
      const Query& query, const google::protobuf::RepeatedPtrField<std::string>& model_ids) const;
  /// Every model as added, in order, or those of `model_ids` held (each
  /// once); without their histograms or descriptors unless `signatures`.
  std::vector<v1::IndexedModel> Export(
      const google::protobuf::RepeatedPtrField<std::string>& model_ids = {},
      bool signatures = true) const;
  /// Every model id, in order.
  std::vector<std::string> ModelIds() const;
  /// Bytes held by the engine.
  std::size_t MemoryBytes() const;

 private:
  using Engine = std::variant<KlInvertedIndex, GlobalDescriptorIndex>;

  // The query as the engine takes it (index_collection.cc).
  absl::StatusOr<EngineQuery> Resolve(const Query& query) const;
  // Engine answers as hits, by (distance, ordinal, model id), the first top_k.
  std::vector<Hit> Ranked(const std::vector<KlNeighbor>& found, std::size_t top_k) const;

  // Docs in (ordinal, model id) order: all, or those of `model_ids` held.
  std::vector<uint32_t> DocsInOrder() const;
  std::vector<uint32_t> DocsInOrder(
      const google::protobuf::RepeatedPtrField<std::string>& model_ids) const;
  void SortDocs(std::vector<uint32_t>* docs) const;
  // Makes the engine one `signature` belongs in, new and empty when the
  // collection is new or its only model replaces itself with another kind.
  absl::Status PrepareEngine(const std::string& model_id, const ModelSignature& signature);

  KlIndexStorage storage_;
  absl::flat_hash_map<std::string, uint32_t> docs_;  // model id -> doc
  absl::flat_hash_map<uint32_t, Model> models_;      // doc -> model
  uint32_t next_doc_ = 0;
  std::optional<Engine> engine_;  // made by the first Place
};

}  // namespace meshseek

#endif  // MESHSEEK_SERVICES_INDEX_INDEX_COLLECTION_H_
