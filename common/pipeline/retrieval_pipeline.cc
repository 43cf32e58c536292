#include "common/pipeline/retrieval_pipeline.h"

#include <algorithm>
#include <chrono>
#include <filesystem>
#include <limits>
#include <numeric>
#include <optional>

#include "absl/strings/str_cat.h"
#include "common/base/file_io.h"
#include "common/base/logging.h"
#include "common/base/parallel.h"
#include "common/base/progress.h"
#include "common/base/status_macros.h"
#include "common/eval/distance_matrix.h"
#include "common/geometry/mesh_io.h"
#include "common/pipeline/pipeline_params.h"
#include "common/search/kl_inverted_index.h"
#include "common/search/sparse_histogram.h"

namespace meshseek {
namespace {

double SecondsSince(std::chrono::steady_clock::time_point start) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

// The codebook the method's features were measured best with
// (FeatureMethodInfo); a global method has none and keeps KMeansOptions'.
void SetMethodCodebook(FeatureMethod method, KMeansOptions* kmeans) {
  const FeatureMethodInfo& info = FeatureMethodInfoOf(method);
  if (info.vocabulary == 0) return;
  kmeans->num_centroids = info.vocabulary;
  kmeans->max_points_per_centroid = info.kmeans_points_per_centroid;
  kmeans->max_iterations = info.kmeans_iterations;
  const KMeansOptions flat;
  kmeans->assignment =
      info.kmeans_tree_probes > 0 ? KMeansOptions::Assignment::kTree : flat.assignment;
  kmeans->tree_probes = info.kmeans_tree_probes > 0 ? info.kmeans_tree_probes : flat.tree_probes;
  kmeans->tree_depth = info.kmeans_tree_probes > 0 ? info.kmeans_tree_depth : flat.tree_depth;
}

}  // namespace

RetrievalPipelineOptions::RetrievalPipelineOptions() {
  // Measured on McGill articulated and PSB train (README, bench/results):
  // V = 2,000 is at or near the best on both; 100 training features per
  // centroid cost 0.2 points of R-precision against 256 (below the spread
  // between k-means seeds) and make k-means 2.5 times faster. Other methods
  // have their own measured figures (FeatureMethodInfo).
  SetMethodCodebook(extractor.method, &kmeans);
}

RetrievalPipelineOptions RetrievalPipelineOptions::ForMethod(FeatureMethod method) {
  RetrievalPipelineOptions options;
  options.extractor.method = method;
  SetMethodCodebook(method, &options.kmeans);
  if (FeatureMethodInfoOf(method).vocabulary > 0) {
    options.weighting.power = FeatureMethodInfoOf(method).histogram_power;
  }
  return options;
}

absl::Status RetrievalPipelineOptions::Validate() const {
  MESHSEEK_RETURN_IF_ERROR(extractor.Validate());
  MESHSEEK_RETURN_IF_ERROR(kmeans.Validate());
  MESHSEEK_RETURN_IF_ERROR(weighting.Validate());
  // Histograms of a larger vocabulary would be refused by the index
  // (SparseHistogram::Validate) only after the whole codebook was learnt.
  if (kmeans.num_centroids > static_cast<int64_t>(kMaxVocabulary)) {
    return absl::InvalidArgumentError(absl::StrCat("vocabulary size V = ",
                                                   kmeans.num_centroids,
                                                   " is more than the index's limit of ",
                                                   kMaxVocabulary,
                                                   " words"));
  }
  return kl.Validate();
}

Json RetrievalPipelineOptions::ToJson(bool with_threads) const {
  Json json = PipelineParamsToJson(*this);
  if (FeatureMethodInfoOf(extractor.method).kind == DescriptorKind::kBagOfFeatures) {
    json.Set("nearest_word_search",
             kmeans.assignment == KMeansOptions::Assignment::kTree ? "tree"
             : kmeans.UsesApproximateAssignment()                  ? "approximate"
                                                                   : "exact");
    json.Set("distance", "symmetric KL divergence");
  }
  if (with_threads) json.Set("threads", ResolveThreadCount(num_threads));
  return json;
}

absl::StatusOr<std::vector<LocalFeatures>> ExtractCollection(
    const std::vector<ManifestEntry>& models, const RetrievalPipelineOptions& options) {
  MESHSEEK_RETURN_IF_ERROR(options.Validate());
  std::vector<LocalFeatures> features(models.size());
  std::vector<absl::Status> errors(models.size());
  ProgressBar progress("extract", models.size(), options.show_progress);
  ParallelFor(models.size(), options.num_threads, [&](std::size_t i) {
    absl::StatusOr<TriangleMesh> mesh = ReadMesh(models[i].path);
    if (mesh.ok()) {
      absl::StatusOr<LocalFeatures> extracted = ExtractLocalFeatures(*mesh, options.extractor);
      if (extracted.ok()) {
        features[i] = *std::move(extracted);
      } else {
        errors[i] = extracted.status();
      }
    } else {
      errors[i] = mesh.status();
    }
    progress.Advance();
  });
  progress.Finish();
  for (std::size_t i = 0; i < models.size(); ++i) {
    if (errors[i].ok()) continue;
    const std::size_t failed =
        std::count_if(errors.begin(), errors.end(), [](const absl::Status& s) { return !s.ok(); });
    return absl::Status(
        errors[i].code(),
        absl::StrCat("model '",
                     models[i].id,
                     "' (manifest line ",
                     models[i].line,
                     "): ",
                     errors[i].message(),
                     failed > 1 ? absl::StrCat(" [and ", failed - 1, " more failed models]") : ""));
  }
  return features;
}

absl::StatusOr<Codebook> TrainCollectionCodebook(const std::vector<LocalFeatures>& features,
                                                 const RetrievalPipelineOptions& options) {
  std::size_t total = 0;
  std::size_t dimension = 0;
  for (const LocalFeatures& f : features) {
    if (f.size() == 0) continue;
    if (dimension != 0 && f.dimension != dimension) {
      return absl::InvalidArgumentError(absl::StrCat(
          "codebook: local features of dimensions ", dimension, " and ", f.dimension, " mixed"));
    }
    dimension = f.dimension;
    total += f.size();
  }
  std::vector<uint8_t> descriptors;
  descriptors.reserve(total * dimension);
  for (const LocalFeatures& f : features) {
    descriptors.insert(descriptors.end(), f.descriptors.begin(), f.descriptors.end());
  }
  KMeansOptions kmeans = options.kmeans;
  kmeans.num_threads = options.num_threads;
  return Codebook::Train(descriptors.data(), total, dimension, kmeans);
}

absl::StatusOr<std::vector<std::vector<float>>> EncodeCollection(
    const Codebook& codebook,
    const std::vector<LocalFeatures>& features,
    const RetrievalPipelineOptions& options) {
  std::vector<std::vector<float>> histograms(features.size());
  std::vector<absl::Status> errors(features.size());
  ParallelFor(features.size(), options.num_threads, [&](std::size_t i) {
    if (features[i].size() == 0) return;  // no histogram: see RankCollection
    auto histogram =
        codebook.Encode(features[i].descriptors.data(), features[i].size(), features[i].dimension);
    if (histogram.ok()) {
      histograms[i] = *std::move(histogram);
    } else {
      errors[i] = histogram.status();
    }
  });
  for (std::size_t i = 0; i < errors.size(); ++i) {
    if (!errors[i].ok()) {
      return absl::Status(errors[i].code(), absl::StrCat("model ", i, ": ", errors[i].message()));
    }
  }
  MESHSEEK_RETURN_IF_ERROR(WeightCollection(options.weighting, &histograms));
  return histograms;
}

namespace {

// The histograms in an inverted index, doc i = histograms[i] (empty ones as
// models without features); nullopt when every histogram is empty.
absl::StatusOr<std::optional<KlInvertedIndex>> IndexHistograms(
    const std::vector<std::vector<float>>& histograms, const RetrievalPipelineOptions& options) {
  const auto first = std::find_if(histograms.begin(), histograms.end(),
                                  [](const std::vector<float>& h) { return !h.empty(); });
  if (first == histograms.end()) return std::nullopt;
  MESHSEEK_ASSIGN_OR_RETURN(
      KlInvertedIndex index,
      KlInvertedIndex::Create(static_cast<uint32_t>(first->size()), options.kl));
  SparseHistogram empty;
  empty.vocabulary = index.vocabulary();
  for (std::size_t i = 0; i < histograms.size(); ++i) {
    MESHSEEK_RETURN_IF_ERROR(index.Upsert(
        static_cast<uint32_t>(i), histograms[i].empty() ? empty : SparseFromDense(histograms[i])));
  }
  return std::optional<KlInvertedIndex>(std::move(index));
}

}  // namespace

absl::StatusOr<std::vector<float>> RankCollection(const std::vector<std::vector<float>>& histograms,
                                                  const RetrievalPipelineOptions& options) {
  const std::size_t n = histograms.size();
  MESHSEEK_ASSIGN_OR_RETURN(const std::optional<KlInvertedIndex> index,
                            IndexHistograms(histograms, options));
  if (!index.has_value()) {
    std::vector<float> distances(n * n, std::numeric_limits<float>::infinity());
    for (std::size_t i = 0; i < n; ++i) distances[i * n + i] = 0;
    return distances;
  }
  std::vector<uint32_t> docs(n);
  std::iota(docs.begin(), docs.end(), 0u);
  return index->DistanceMatrix(docs, options.num_threads);
}

absl::StatusOr<std::vector<float>> RankGlobalCollection(const std::vector<LocalFeatures>& features,
                                                        const RetrievalPipelineOptions& options) {
  const std::size_t n = features.size();
  const FeatureMethod method = options.extractor.method;
  std::vector<float> distances(n * n, 0.0f);
  std::vector<absl::Status> errors(n);
  // Row i computes the pairs (i, j > i); rows are interleaved so that both
  // ends of the triangle share the threads.
  ParallelFor(n, options.num_threads, [&](std::size_t k) {
    const std::size_t i = k % 2 == 0 ? k / 2 : n - 1 - k / 2;
    for (std::size_t j = i + 1; j < n; ++j) {
      absl::StatusOr<float> d = GlobalDistance(method, features[i], features[j]);
      if (!d.ok()) {
        errors[i] = d.status();
        return;
      }
      distances[i * n + j] = distances[j * n + i] = *d;
    }
  });
  for (std::size_t i = 0; i < n; ++i) {
    if (!errors[i].ok()) {
      return absl::Status(errors[i].code(), absl::StrCat("model ", i, ": ", errors[i].message()));
    }
  }
  return distances;
}

absl::StatusOr<MethodEvaluation> EvaluateMethod(const std::vector<ManifestEntry>& models,
                                                const RetrievalPipelineOptions& options) {
  MESHSEEK_RETURN_IF_ERROR(options.Validate());
  if (models.empty()) return absl::InvalidArgumentError("the collection has no models");
  const auto start = std::chrono::steady_clock::now();
  MethodEvaluation result;
  result.method = options.extractor.method;
  const char* name = FeatureMethodName(result.method);

  auto stage = std::chrono::steady_clock::now();
  MESHSEEK_ASSIGN_OR_RETURN(const std::vector<LocalFeatures> features,
                            ExtractCollection(models, options));
  result.timings.extract_seconds = SecondsSince(stage);
  for (const LocalFeatures& f : features) {
    result.features_per_model.push_back(f.size());
    if (f.size() == 0) ++result.models_without_features;
  }
  if (result.models_without_features > 0) {
    MESHSEEK_LOG(WARNING) << name << ": " << result.models_without_features << " of "
                          << models.size()
                          << " models have no local features; they are ranked last for every query";
  }

  if (FeatureMethodInfoOf(options.extractor.method).kind == DescriptorKind::kGlobal) {
    stage = std::chrono::steady_clock::now();
    MESHSEEK_ASSIGN_OR_RETURN(result.distances, RankGlobalCollection(features, options));
    result.timings.rank_seconds = SecondsSince(stage);
  } else {
    stage = std::chrono::steady_clock::now();
    MESHSEEK_ASSIGN_OR_RETURN(const Codebook codebook, TrainCollectionCodebook(features, options));
    result.codebook_size = codebook.size();
    result.timings.codebook_seconds = SecondsSince(stage);

    stage = std::chrono::steady_clock::now();
    MESHSEEK_ASSIGN_OR_RETURN(const auto histograms, EncodeCollection(codebook, features, options));
    result.timings.encode_seconds = SecondsSince(stage);

    stage = std::chrono::steady_clock::now();
    MESHSEEK_ASSIGN_OR_RETURN(result.distances, RankCollection(histograms, options));
    result.timings.rank_seconds = SecondsSince(stage);
  }
  result.timings.total_seconds = SecondsSince(start);
  return result;
}

}  // namespace meshseek
