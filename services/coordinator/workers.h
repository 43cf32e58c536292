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

#include "absl/status/statusor.h"
#include "common/pipeline/retrieval_pipeline.h"
#include "common/rpc/client.h"
#include "meshseek/v1/codebook.grpc.pb.h"
#include "meshseek/v1/extract.grpc.pb.h"
#include "meshseek/v1/resample.grpc.pb.h"
#include "services/coordinator/coordinator_options.h"
#include "services/coordinator/coordinator_store.h"
#include "services/coordinator/index_shards.h"

namespace meshseek {

/// A collection as the workers need it: stored parameters, the pipeline
/// options they validate to, the current codebook.
struct CollectionInfo {
  v1::PipelineParams params;
  RetrievalPipelineOptions options;
  std::string codebook_id;
};

/// NotFound when absent; the parameters' validation error when they no
/// longer validate.
absl::StatusOr<CollectionInfo> LoadCollection(CoordinatorStore* store, const std::string& name);

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

  /// Resamples (RLD-SIFT) and extracts one mesh.
  absl::StatusOr<v1::LocalFeatures> Extract(const v1::Mesh& mesh,
                                            const CollectionInfo& collection,
                                            const std::string& model_id);
  /// The signature of extracted features: encoded with `codebook_id` by the
  /// codebook service, or, for a global method, the features' one descriptor.
  absl::StatusOr<IndexSignature> Encode(const CollectionInfo& collection,
                                        const std::string& codebook_id,
                                        const v1::LocalFeatures& features);
  absl::Status AddToIndex(const std::string& collection,
                          const std::string& model_id,
                          uint64_t ordinal,
                          const std::string& label,
                          const IndexSignature& signature);

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
