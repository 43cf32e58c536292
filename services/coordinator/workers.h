// The coordinator's clients of the other services: resample and extract
// workers (stateless, behind round-robin), the codebook service and the index
// shards, with the deadlines and retries of CoordinatorOptions. The
// dispatchers, the build runner and queries all call the workers through
// this one place.
#ifndef MESHSEEK_SERVICES_COORDINATOR_WORKERS_H_
#define MESHSEEK_SERVICES_COORDINATOR_WORKERS_H_

#include <atomic>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "absl/status/statusor.h"
#include "common/pipeline/collection_options.h"
#include "common/pipeline/retrieval_pipeline.h"
#include "common/rpc/client.h"
#include "meshseek/v1/codebook.grpc.pb.h"
#include "meshseek/v1/extract.grpc.pb.h"
#include "meshseek/v1/resample.grpc.pb.h"
#include "services/coordinator/coordinator_options.h"
#include "services/coordinator/coordinator_store.h"
#include "services/coordinator/index_shards.h"

namespace meshseek {

/// One method's part of a collection as the workers need it: the collection
/// that holds the models (the collection itself, or a fused collection's
/// member), its method's canonical parameters (what extract and codebook
/// requests carry) and options, and its current codebook.
struct CollectionInfo {
  std::string name;
  v1::PipelineParams params;
  RetrievalPipelineOptions options;
  std::string codebook_id;  // "<name>@<build job>" of the last build; empty before
};

/// A collection with everything that ranks it (CollectionOptions): its
/// parts, one per method, and whether it ranks by its last build's
/// RankingState (ranking.h).
struct CollectionPlan {
  std::string name;
  v1::PipelineParams params;  // as stored: canonical
  CollectionOptions options;
  std::string codebook_id;  // "<name>@<build job>" of the last build; empty before
  /// The collection itself (one method), or its members (fused), in method order.
  std::vector<CollectionInfo> parts;
  /// A member of a fused collection: built, ranked and listed through it.
  bool member = false;

  bool fused() const { return options.fused(); }
  /// The build job of codebook_id ("" before the first build).
  std::string build() const;
  std::vector<std::string> PartNames() const;
};

/// A fused collection's member for `method`: "<fused>~<method>" ('~' is not
/// a character of the names clients give).
std::string MemberCollectionName(const std::string& fused, FeatureMethod method);
/// Whether `name` is a fused collection's member.
bool IsMemberCollection(const std::string& name);

/// NotFound when absent; the parameters' validation error when they no
/// longer validate.
absl::StatusOr<CollectionPlan> LoadCollectionPlan(CoordinatorStore* store, const std::string& name);
/// A collection of one method (or a member): its one part.
/// FailedPrecondition for a fused collection.
absl::StatusOr<CollectionInfo> OnlyPart(const CollectionPlan& plan);

/// What the index ranks a model by: its histogram over a codebook (bag of
/// features), or its descriptor (a global method: no codebook).
struct IndexSignature {
  v1::SparseHistogram histogram;
  std::optional<v1::GlobalDescriptor> descriptor;
};

class Workers {
 public:
  /// `stop` (not owned) ends retries early when the coordinator stops.
  Workers(const CoordinatorOptions& options, const std::atomic<bool>* stop);

  const CoordinatorOptions& options() const { return options_; }

  /// Resamples (RLD-SIFT) and extracts one mesh, on up to `threads` of the
  /// extract service's cores (ExtractRequest.threads; 0: one).
  absl::StatusOr<v1::LocalFeatures> Extract(const v1::Mesh& mesh,
                                            const CollectionInfo& collection,
                                            const std::string& model_id,
                                            uint32_t threads = 0);
  /// The signature of extracted features: encoded with `codebook_id` by the
  /// codebook service (on up to `threads` of its cores, as Extract), or, for
  /// a global method, the features' one descriptor.
  absl::StatusOr<IndexSignature> Encode(const CollectionInfo& collection,
                                        const std::string& codebook_id,
                                        const v1::LocalFeatures& features,
                                        uint32_t threads = 0);
  absl::Status AddToIndex(const std::string& collection,
                          const std::string& model_id,
                          uint64_t ordinal,
                          const std::string& label,
                          const IndexSignature& signature);

  /// An extracted model's features: as stored, or, once freed after
  /// indexing (CoordinatorStore::DropFeatures), extracted again from its
  /// stored mesh (the same features: extraction is deterministic).
  absl::StatusOr<v1::LocalFeatures> FeaturesOf(CoordinatorStore* store,
                                               const CollectionInfo& part,
                                               const ExtractedModel& model);

  v1::Codebook::Stub* codebook() { return codebook_.get(); }
  IndexShards* index() { return index_.get(); }
  const rpc::RetryOptions& retry() const { return retry_; }

 private:
  const CoordinatorOptions options_;
  const std::atomic<bool>* stop_;
  rpc::RetryOptions retry_;
  std::unique_ptr<v1::Resample::Stub> resample_;
  std::unique_ptr<v1::Extract::Stub> extract_;
  std::unique_ptr<v1::Codebook::Stub> codebook_;
  std::unique_ptr<IndexShards> index_;
};

}  // namespace meshseek

#endif  // MESHSEEK_SERVICES_COORDINATOR_WORKERS_H_
