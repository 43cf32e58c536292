// What a collection is: one or more feature methods, each with its own
// pipeline (RetrievalPipelineOptions), and how their distances become one
// ranking (docs/design.md 2.7, 2.7c).
//
//   one method, no re-ranking   the method's own distance, as the paper ranks
//                               (symmetric KL of BoF histograms, LFD's own);
//   several methods ("a+b")     each method's distances divided by their mean
//                               over the collection and averaged with the
//                               weights (common/search/fusion.h);
//   re-ranking                  k-reciprocal re-ranking over the collection's
//                               neighbour graph (common/search/rerank.h), on
//                               the fused (or one method's scaled) distances.
//
// Defaults, measured on the development sets (bench/results/fusion.txt): a
// collection of one method ranks as the paper does, with no re-ranking; a
// collection of several re-ranks by default, each method weighted by its
// FeatureMethodInfo::fusion_weight.
#ifndef MESHSEEK_COMMON_PIPELINE_COLLECTION_OPTIONS_H_
#define MESHSEEK_COMMON_PIPELINE_COLLECTION_OPTIONS_H_

#include <string>
#include <vector>

#include "absl/status/status.h"
#include "common/base/json.h"
#include "common/pipeline/retrieval_pipeline.h"
#include "common/search/rerank.h"

namespace meshseek {

struct CollectionOptions {
  /// Most methods one collection may fuse.
  static constexpr std::size_t kMaxMethods = 8;

  /// DLD-SIFT alone.
  CollectionOptions();
  /// Each method with its defaults, in this order, the fusion and re-ranking
  /// defaults for that many methods. Several methods are each a FusedMember.
  static CollectionOptions ForMethods(const std::vector<FeatureMethod>& methods);
  /// A method's defaults as a member of a fusion: its own (ForMethod) but for
  /// RLD-SIFT and BF-DSIFT.
  ///
  /// RLD-SIFT resamples kFusedRldSamples points and trains its
  /// codebook in kFusedRldKMeansIterations Lloyd iterations. Half the paper's
  /// N_RLD detects half the points (the supports s = C d sqrt(l) follow the
  /// graph's spacing d) and halves RLD-SIFT's extraction (137 -> 77 ms a
  /// McGill model). Alone that costs RLD-SIFT 2.6 points of first tier on
  /// McGill (80.6 -> 78.0), so the method alone keeps the paper's 15,000 and
  /// 25 iterations; in the default fusion first tier is 94.51 against 94.27
  /// (McGill) and 62.53 against 62.40 (PSB train), nearest neighbour 99.22
  /// and 78.76 against 98.82 and 77.54 (bench/results/speed_extract_fused.txt).
  ///
  /// BF-DSIFT resamples each of its ~25,000 patches a model into a
  /// kFusedBfDsiftPatchSize-pixel square instead of 21 (the same patches,
  /// radii and points; SIFT's 4 x 4 cells over 17 pixels instead of 21):
  /// SIFT's work, most of BF-DSIFT's extraction, follows the pixels (0.66).
  /// BF-DSIFT's extraction 0.79 of the time (mean of two alternated runs
  /// on McGill's first 50), the whole fused McGill eval 0.88; the default
  /// fusion's first tier 94.43 against 94.51 (McGill) and 62.23 against
  /// 62.53 (PSB train), nearest neighbour the same (99.22, 78.76): within
  /// the 0.3 issue 38 allows (bench/results/bfdsift.txt, round 4). 15 pixels
  /// lost 0.18 on McGill; BF-DSIFT alone keeps 21 (not measured alone at 17).
  static RetrievalPipelineOptions FusedMember(FeatureMethod method);
  static constexpr int kFusedRldSamples = 7500;
  static constexpr int kFusedRldKMeansIterations = 6;
  static constexpr int kFusedBfDsiftPatchSize = 17;
  /// One method with these options, no re-ranking.
  static CollectionOptions Of(const RetrievalPipelineOptions& method);

  /// One pipeline per method, in the order named: distinct methods.
  std::vector<RetrievalPipelineOptions> methods;
  /// Fusion weights, one per method (>= 0, not all 0); default: each
  /// method's fusion_weight.
  std::vector<double> weights;
  /// Re-ranking over the collection's neighbour graph.
  RerankOptions rerank;

  bool fused() const { return methods.size() > 1; }
  /// Distances are rescaled (each method's by its collection mean): when
  /// fused or re-ranked. Otherwise a collection ranks by its method's own.
  bool rescaled() const { return fused() || rerank.enabled(); }
  /// "dld", or the methods joined by '+' ("bfdsift+rld").
  std::string MethodName() const;
  /// Threads and progress bars of every method's pipeline.
  void SetRunOptions(int num_threads, bool show_progress);
  int num_threads() const { return methods.empty() ? 0 : methods.front().num_threads; }
  bool show_progress() const { return !methods.empty() && methods.front().show_progress; }

  /// Each method's Validate, then: 1 to kMaxMethods distinct methods, one
  /// weight per method, and the re-ranking options; InvalidArgument naming
  /// what is wrong.
  absl::Status Validate() const;
  /// Every parameter (pipeline_params.h) and the threads, for metrics.json:
  /// a method's block as RetrievalPipelineOptions::ToJson, a fused
  /// collection's blocks under each method's name beside the weights and the
  /// re-ranking.
  Json ToJson() const;
};

}  // namespace meshseek

#endif  // MESHSEEK_COMMON_PIPELINE_COLLECTION_OPTIONS_H_
