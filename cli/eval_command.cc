#include <cstdio>
#include <string>

#include "absl/flags/flag.h"
#include "absl/strings/str_cat.h"
#include "absl/strings/str_format.h"
#include "cli/commands.h"
#include "common/base/parallel.h"
#include "common/base/status_macros.h"
#include "common/pipeline/retrieval_pipeline.h"

ABSL_FLAG(std::string, manifest, "", "eval: CSV manifest with columns id,class,path (paths relative to it)");
ABSL_FLAG(std::string, method, "dld", "eval: local feature method (dld)");
ABSL_FLAG(std::string, out, "", "output folder");
ABSL_FLAG(double, scale, meshseek::DldSiftOptions().scale,
          "eval: support radius E relative to the minimum enclosing sphere (s = E * D / 2)");
ABSL_FLAG(int, points, meshseek::DldSiftOptions().num_points, "eval: DLD-SIFT feature points per model (N_DLD)");
ABSL_FLAG(int, image_size, meshseek::DepthImageOptions().image_size, "eval: depth image side I in pixels (odd)");
ABSL_FLAG(std::string, depth_to_gray, "fixed", "eval: depth to grey mapping: fixed | stretch");
ABSL_FLAG(int, vocabulary, meshseek::RetrievalPipelineOptions().kmeans.num_centroids,
          "eval: codebook size V (k-means centroids)");
ABSL_FLAG(uint64_t, seed, 0, "seed of every random choice (k-means sampling and seeding; synth shapes)");
ABSL_FLAG(double, kl_epsilon, meshseek::KlDivergenceOptions().epsilon,
          "eval: mass added to every histogram bin before KL divergence (zero-bin rule)");
ABSL_FLAG(int, threads, 0, "threads (0: all cores)");
ABSL_FLAG(bool, progress, true, "eval: show progress bars on stderr");

namespace meshseek::cli {

absl::Status RunEval() {
  const std::string manifest_path = absl::GetFlag(FLAGS_manifest);
  const std::string out_dir = absl::GetFlag(FLAGS_out);
  if (manifest_path.empty()) return absl::InvalidArgumentError("eval needs --manifest FILE");
  if (out_dir.empty()) return absl::InvalidArgumentError("eval needs --out DIR");

  RetrievalPipelineOptions options;
  MESHSEEK_ASSIGN_OR_RETURN(options.extractor.method, ParseFeatureMethod(absl::GetFlag(FLAGS_method)));
  options.extractor.dld.scale = absl::GetFlag(FLAGS_scale);
  options.extractor.dld.num_points = absl::GetFlag(FLAGS_points);
  options.extractor.dld.depth_image.image_size = absl::GetFlag(FLAGS_image_size);
  const std::string gray = absl::GetFlag(FLAGS_depth_to_gray);
  if (gray == "fixed") {
    options.extractor.dld.descriptor.depth_to_gray = DepthToGray::kFixedRange;
  } else if (gray == "stretch") {
    options.extractor.dld.descriptor.depth_to_gray = DepthToGray::kStretch;
  } else {
    return absl::InvalidArgumentError(
        absl::StrCat("--depth_to_gray must be 'fixed' or 'stretch', got '", gray, "'"));
  }
  options.kmeans.num_centroids = absl::GetFlag(FLAGS_vocabulary);
  options.kmeans.seed = absl::GetFlag(FLAGS_seed);
  options.kl.epsilon = absl::GetFlag(FLAGS_kl_epsilon);
  options.num_threads = absl::GetFlag(FLAGS_threads);
  options.show_progress = absl::GetFlag(FLAGS_progress);
  MESHSEEK_RETURN_IF_ERROR(options.Validate());

  MESHSEEK_ASSIGN_OR_RETURN(const std::vector<ManifestEntry> models, ReadManifest(manifest_path));
  std::fprintf(stderr, "meshseek eval: %zu models from %s, method %s, %d threads\n", models.size(),
               manifest_path.c_str(), FeatureMethodName(options.extractor.method),
               ResolveThreadCount(options.num_threads));
  MESHSEEK_ASSIGN_OR_RETURN(const CollectionEvaluation evaluation, EvaluateCollection(models, options));
  MESHSEEK_RETURN_IF_ERROR(WriteEvaluation(evaluation, options, out_dir));

  const StageTimings& t = evaluation.timings;
  std::printf("%s", FormatMetricsTable(evaluation.metrics).c_str());
  std::printf("R-precision (query excluded = first tier): %.1f %% micro, %.1f %% macro\n",
              100 * evaluation.metrics.micro.rp_excl, 100 * evaluation.metrics.macro.rp_excl);
  std::printf("%zu models, codebook V = %zu; time %.1f s (extract %.1f, codebook %.1f, encode %.1f, rank %.1f)\n",
              evaluation.models.size(), evaluation.codebook_size, t.total_seconds, t.extract_seconds,
              t.codebook_seconds, t.encode_seconds, t.rank_seconds);
  std::printf("wrote %s/distances.bin and %s/metrics.json\n", out_dir.c_str(), out_dir.c_str());
  return absl::OkStatus();
}

}  // namespace meshseek::cli
