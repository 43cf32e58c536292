// One entry point for every feature method, so the pipeline, the CLI and the
// extract service select a method by name and never depend on which one it
// is. The method table (FeatureMethods) is the one registration of a method:
// its name, kind, measured vocabulary, validation and extraction; its
// parameters are rows of common/pipeline/pipeline_param_table.cc.
#ifndef MESHSEEK_COMMON_FEATURES_LOCAL_FEATURE_EXTRACTOR_H_
#define MESHSEEK_COMMON_FEATURES_LOCAL_FEATURE_EXTRACTOR_H_

#include <string>
#include <vector>

#include "absl/status/status.h"
#include "absl/status/statusor.h"
#include "absl/strings/string_view.h"
#include "common/features/bf_dsift.h"
#include "common/features/dld_sift.h"
#include "common/features/ld_sift.h"
#include "common/features/local_features.h"
#include "common/features/lsf.h"
#include "common/features/rld_sift.h"
#include "common/geometry/mesh.h"
#include "common/global/lfd.h"

namespace meshseek {

enum class FeatureMethod { kDldSift, kLdSift, kRldSift, kBfDsift, kLsf, kLfd };

// How a method's features become a model's signature: a bag of features over
// a codebook learnt from the collection (the local methods), or one
// fixed-size descriptor per model compared by the method's own distance.
enum class DescriptorKind { kBagOfFeatures, kGlobal };

struct ExtractorOptions;

// The registration of one method: the table every name, listing and kind
// lookup consults (its parameters are rows of common/pipeline/pipeline_param_table.cc).
struct FeatureMethodInfo {
  FeatureMethod method;
  /// --method value, lower case.
  const char* name;
  /// What it is, for --help.
  const char* title;
  DescriptorKind kind;
  /// The codebook size measured best for its features (bag of features;
  /// 0 for a global method).
  int vocabulary;
  /// k-means trains on at most this many of the features per word
  /// (KMeansOptions::max_points_per_centroid; 0 for a global method).
  int kmeans_points_per_centroid;
  /// Lloyd iterations of its codebook (KMeansOptions::max_iterations; 0 for
  /// a global method): Faiss's 25, but 6 for BF-DSIFT's 40,000 words (with
  /// 40 features a word), where 25 on 50 took 2.5 minutes of 2 cores on
  /// McGill and 6 on 40 take 26 s, first tier 76.65 against 76.86 on McGill
  /// and 50.32 against 50.52 on PSB train (bench/results/codebook.txt).
  int kmeans_iterations;
  /// 0: a flat codebook, its words searched as KMeansOptions' auto
  /// assignment chooses. n > 0: a vocabulary tree (KMeansOptions::kTree) of
  /// kmeans_tree_depth levels whose search keeps n nodes a level. 4 for
  /// BF-DSIFT's 40,000 words (3 levels): its codebook and encoding in 0.44 of
  /// the flat codebook's time on McGill, the default fusion's first tier
  /// 94.10 against 94.15 (McGill) and 61.64 against 61.9 (PSB train). 4 for
  /// LSF's 2,000 words of 864 bytes (2 levels of ~45): its codebook 35 -> 6 s
  /// on McGill, alone 0.7 lower first tier on McGill and the same on PSB
  /// train, fused 94.27 against 94.10 (bench/results/codebook.txt).
  int kmeans_tree_probes;
  /// Levels of that tree (KMeansOptions::tree_depth); 0 with a flat codebook.
  int kmeans_tree_depth;
  /// Its default weight in a fused collection (CollectionOptions::weights):
  /// 2 for the methods strongest on the development sets (BF-DSIFT, RLD-SIFT),
  /// 1.5 for LSF (with its square-rooted histograms), 1 for the others
  /// (bench/results/fusion.txt).
  double fusion_weight;
  /// Its histograms' default power (HistogramWeighting::power): 0.5 (square
  /// root) for LSF, +0.8 / +1.1 first tier on McGill / PSB train under KL;
  /// 1 for the others, which it did not help (bench/results/weighting.txt).
  double histogram_power;
  /// Validates the method's options in ExtractorOptions.
  absl::Status (*validate)(const ExtractorOptions& options);
  /// Extracts one mesh's features (see ExtractLocalFeatures).
  absl::StatusOr<LocalFeatures> (*extract)(const TriangleMesh& mesh,
                                           const ExtractorOptions& options,
                                           const PointGraph* resampled);
  /// kGlobal: the distance of two models' descriptors (GlobalDescriptorFeatures)
  /// of `dimension` bytes; symmetric, 0 for equal ones. nullptr otherwise.
  float (*distance)(const uint8_t* a, const uint8_t* b, std::size_t dimension) = nullptr;
  /// kGlobal: the descriptor's size in bytes (what `distance` reads).
  std::size_t descriptor_bytes = 0;
  /// kGlobal methods whose descriptor is a model's views (LFD): the distance
  /// of one view of `view_bytes` (a picture's, picture_silhouette.h) to a
  /// model's descriptor, the model's nearest view deciding. nullptr and 0
  /// for the others, which cannot be queried by a picture.
  float (*view_distance)(const uint8_t* view, const uint8_t* descriptor) = nullptr;
  std::size_t view_bytes = 0;
};

/// The distance of a global method between two models' features; InvalidArgument
/// when the method is not global or either is not one descriptor of the same
/// dimension.
absl::StatusOr<float> GlobalDistance(FeatureMethod method,
                                     const LocalFeatures& a,
                                     const LocalFeatures& b);

/// Every method, in --help order.
const std::vector<FeatureMethodInfo>& FeatureMethods();
const FeatureMethodInfo& FeatureMethodInfoOf(FeatureMethod method);

// By name. InvalidArgument listing the known names otherwise.
absl::StatusOr<FeatureMethod> ParseFeatureMethod(absl::string_view name);
const char* FeatureMethodName(FeatureMethod method);

struct ExtractorOptions {
  /// Which method extracts the features.
  FeatureMethod method = FeatureMethod::kDldSift;
  /// Parameters of each method; only the selected method's are used.
  DldSiftOptions dld;
  LdSiftOptions ld;
  RldSiftOptions rld;
  BfDsiftOptions bfdsift;
  LsfOptions lsf;
  LfdOptions lfd;
  /// Not a parameter of the collection but of one call: the threads one
  /// model's extraction may use (<= 1: the calling thread). The features do
  /// not depend on it. DLD-, LD- and RLD-SIFT describe their points and
  /// BF-DSIFT its views in runs on that many threads (DescribeInRuns); LSF
  /// and LFD use one. Models extracted side by side (ingest, eval) keep 1; a
  /// query's extraction asks for the cores (docs/design.md 1.1).
  int num_threads = 1;

  /// Validates the options of the selected method.
  absl::Status Validate() const;
};

// Extracts the local features of one mesh with the selected method, on the
// calling thread (and options.num_threads - 1 more where it says). LD-SIFT and RLD-SIFT may return an empty set (nothing
// detected); DLD-SIFT always describes its points. For RLD-SIFT, `resampled`
// may carry the graph ResampleSurfaceGraph made for this mesh with the
// options' num_samples and neighbors (the resample service's output); the
// result is the same as without it. Other methods ignore it.
absl::StatusOr<LocalFeatures> ExtractLocalFeatures(const TriangleMesh& mesh,
                                                   const ExtractorOptions& options,
                                                   const PointGraph* resampled = nullptr);

}  // namespace meshseek

#endif  // MESHSEEK_COMMON_FEATURES_LOCAL_FEATURE_EXTRACTOR_H_
