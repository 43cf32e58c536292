// The in-process retrieval pipeline: local features -> visual codebook ->
// bag-of-features histograms -> symmetric-KL ranking -> metrics, for a labelled
// collection, under the paper's protocol (docs/design.md 3.3): every model is a
// query against all others, and the codebook is learnt from the collection's
// own local features.
//
// Each stage is a function of its own so that the distributed services run the
// same code stage by stage; EvaluateMethod chains them for one method, and
// EvaluateCollection (collection_evaluation.h) combines the methods of a
// collection for the CLI's `eval` and the end-to-end tests.
#ifndef MESHSEEK_COMMON_PIPELINE_RETRIEVAL_PIPELINE_H_
#define MESHSEEK_COMMON_PIPELINE_RETRIEVAL_PIPELINE_H_

#include <string>
#include <vector>

#include "absl/status/status.h"
#include "absl/status/statusor.h"
#include "common/base/json.h"
#include "common/bof/codebook.h"
#include "common/bof/histogram_weighting.h"
#include "common/bof/kl_divergence.h"
#include "common/bof/kmeans.h"
#include "common/eval/manifest.h"
#include "common/features/local_feature_extractor.h"

namespace meshseek {

struct RetrievalPipelineOptions {
  /// The defaults of DLD-SIFT.
  RetrievalPipelineOptions();
  /// The defaults of `method`: its extractor options and its vocabulary
  /// (FeatureMethodInfo). Selecting a method by name (pipeline_params.h)
  /// starts from these.
  static RetrievalPipelineOptions ForMethod(FeatureMethod method);

  /// Local features: the method and its parameters.
  ExtractorOptions extractor;
  /// Codebook learning; kmeans.num_centroids is the vocabulary size V. The
  /// defaults (V = 2,000, k-means on 100 sampled features per word) were
  /// chosen on the development sets (README, bench/results).
  KMeansOptions kmeans;
  /// Histogram weighting before ranking (idf, power); off by default.
  HistogramWeighting weighting;
  /// Ranking: symmetric KL divergence and its zero-bin rule.
  KlDivergenceOptions kl;
  /// Threads (<= 0: all cores). Extraction runs one model per thread; k-means,
  /// encoding and ranking use them too. Results do not depend on it.
  int num_threads = 0;
  /// Progress bars with rate and time left on stderr.
  bool show_progress = false;

  absl::Status Validate() const;
  /// Every parameter that affects the result (pipeline_params.h) and the
  /// threads, for metrics.json.
  Json ToJson(bool with_threads = true) const;
};

// Reads and extracts every model, in parallel across models. The first
// failing model (in input order) fails the whole call with an error naming its
// id, manifest line and the problem; a silently skipped model would change
// every metric.
absl::StatusOr<std::vector<LocalFeatures>> ExtractCollection(
    const std::vector<ManifestEntry>& models, const RetrievalPipelineOptions& options);

// Learns the codebook from all local descriptors of `features` (k-means
// sub-samples them; see kmeans.h).
absl::StatusOr<Codebook> TrainCollectionCodebook(const std::vector<LocalFeatures>& features,
                                                 const RetrievalPipelineOptions& options);

// One normalised histogram per model, weighted as options.weighting says (idf
// over these histograms); an empty one for a model without local features
// (LD-SIFT and RLD-SIFT may detect nothing on a model).
absl::StatusOr<std::vector<std::vector<float>>> EncodeCollection(
    const Codebook& codebook,
    const std::vector<LocalFeatures>& features,
    const RetrievalPipelineOptions& options);

// All-pairs symmetric KL distances, N x N row-major, by the exact inverted
// file (common/search/kl_inverted_index.h). A model without features
// (empty histogram) cannot be compared: its distance to every other model is
// +infinity (0 to itself), so it is ranked last by every query and, as a
// query, finds all others tied (broken by index). Such models are counted in
// the report rather than silently given an arbitrary histogram.
absl::StatusOr<std::vector<float>> RankCollection(const std::vector<std::vector<float>>& histograms,
                                                  const RetrievalPipelineOptions& options);

// All-pairs distances of a global method (FeatureMethodInfo::distance), N x N
// row-major, each pair computed once, rows in parallel.
absl::StatusOr<std::vector<float>> RankGlobalCollection(const std::vector<LocalFeatures>& features,
                                                        const RetrievalPipelineOptions& options);

struct StageTimings {
  double extract_seconds = 0;
  double codebook_seconds = 0;
  double encode_seconds = 0;
  double rank_seconds = 0;
  double total_seconds = 0;
};

// One method's all-pairs distances over a collection, with what it took.
struct MethodEvaluation {
  FeatureMethod method = FeatureMethod::kDldSift;
  std::vector<std::size_t> features_per_model;  // input order
  std::size_t models_without_features = 0;
  std::size_t codebook_size = 0;  // 0 for a global method
  /// N x N row-major, entry i*N+j = D(model i, model j), the method's own
  /// distance (empty when the services computed the collection's ranking).
  std::vector<float> distances;
  /// What the distances are divided by in a rescaled collection (fusion.h).
  double scale = 1.0;
  StageTimings timings;
};

// Extracts, learns the codebook, encodes and ranks every pair (a global
// method skips the codebook and encoding) with one method.
absl::StatusOr<MethodEvaluation> EvaluateMethod(const std::vector<ManifestEntry>& models,
                                                const RetrievalPipelineOptions& options);

}  // namespace meshseek

#endif  // MESHSEEK_COMMON_PIPELINE_RETRIEVAL_PIPELINE_H_
