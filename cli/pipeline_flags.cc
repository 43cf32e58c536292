#include "cli/pipeline_flags.h"

#include <string>

#include "absl/flags/flag.h"
#include "absl/strings/str_cat.h"
#include "common/base/status_macros.h"
#include "common/rpc/convert.h"

namespace {
const meshseek::RetrievalPipelineOptions kDefaults;
const meshseek::DldSiftOptions& kDld = kDefaults.extractor.dld;
const meshseek::RldSiftOptions& kRld = kDefaults.extractor.rld;
}  // namespace

ABSL_FLAG(std::string,
          method,
          "dld",
          "local feature method: dld (DLD-SIFT, dense) | rld (RLD-SIFT, resampled) | ld (LD-SIFT)");
ABSL_FLAG(double,
          scale,
          kDld.scale,
          "dld: support radius E relative to the minimum enclosing sphere (s = E * D / 2)");
ABSL_FLAG(int, points, kDld.num_points, "dld: feature points per model (N_DLD)");
ABSL_FLAG(int,
          frame_samples,
          kDld.frame_samples_per_support,
          "dld: dense surface samples per support disc for the local PCA frame");
ABSL_FLAG(double,
          frame_radius,
          kDld.frame_radius_factor,
          "dld: the local frame uses the samples within this many times the support radius");
ABSL_FLAG(int, rld_samples, kRld.num_samples, "rld: resample points (N_RLD)");
ABSL_FLAG(int, rld_neighbors, kRld.neighbors, "rld: k of the k-nearest-neighbour graph");
ABSL_FLAG(int, levels, kRld.scale_space.levels, "ld, rld: scale-space levels L");
ABSL_FLAG(double,
          scale_factor,
          0,
          "ld, rld: C in the feature scale s = C * d * sqrt(level); 0 keeps each "
          "method's measured default (ld 20, rld 15)");
ABSL_FLAG(bool,
          weighted_frame,
          kDld.weighted_frame,
          "dld, rld: distance-weighted (SHOT-style) PCA frame instead of plain PCA");
ABSL_FLAG(int, image_size, kDld.depth_image.image_size, "depth image side I in pixels (odd)");
ABSL_FLAG(std::string,
          orientation,
          "",
          "descriptor rotation: dominant (Lowe's gradient peaks) | up (PCA up axis + 180-degree "
          "sum); empty: the method's default");
ABSL_FLAG(std::string,
          depth_to_gray,
          "",
          "depth to grey mapping: fixed (2s range) | stretch (image range); empty: the method's "
          "default");
ABSL_FLAG(int,
          max_orientations,
          kDld.descriptor.max_orientations,
          "with --orientation dominant: at most this many descriptors per depth image (0: all "
          "peaks within 80 % of the highest)");
ABSL_FLAG(double, blur_sigma, kDld.descriptor.blur_sigma, "SIFT blur sigma in pixels");
ABSL_FLAG(int, vocabulary, kDefaults.kmeans.num_centroids, "codebook size V (k-means centroids)");
ABSL_FLAG(int,
          kmeans_points_per_centroid,
          kDefaults.kmeans.max_points_per_centroid,
          "k-means trains on at most this many sampled local features per centroid");
ABSL_FLAG(int, kmeans_iterations, kDefaults.kmeans.max_iterations, "maximum k-means iterations");
ABSL_FLAG(std::string,
          kmeans_assignment,
          meshseek::KMeansAssignmentName(kDefaults.kmeans.assignment),
          "nearest-word search of k-means and encoding: auto (exact below V = 1,000, "
          "approximate from there), exact or approximate");
ABSL_FLAG(uint64_t,
          seed,
          kDefaults.kmeans.seed,
          "seed of every random choice (k-means sampling and seeding; synth shapes)");
ABSL_FLAG(double,
          kl_epsilon,
          kDefaults.kl.epsilon,
          "mass added to every histogram bin before KL divergence (zero-bin rule)");
ABSL_FLAG(int, threads, kDefaults.num_threads, "threads (0: all cores)");
ABSL_FLAG(bool, progress, true, "show progress bars on stderr");

namespace meshseek::cli {

v1::PipelineParams PipelineParamsFromFlags() {
  v1::PipelineParams p;
  const std::string method = absl::GetFlag(FLAGS_method);
  p.set_method(method == "ld"    ? v1::FEATURE_METHOD_LD
               : method == "rld" ? v1::FEATURE_METHOD_RLD
               : method == "dld" ? v1::FEATURE_METHOD_DLD
                                 : v1::FeatureMethod(-1));  // rejected with the name below
  p.set_scale(absl::GetFlag(FLAGS_scale));
  p.set_num_points(absl::GetFlag(FLAGS_points));
  p.set_frame_samples_per_support(absl::GetFlag(FLAGS_frame_samples));
  p.set_frame_radius_factor(absl::GetFlag(FLAGS_frame_radius));
  p.set_weighted_frame(absl::GetFlag(FLAGS_weighted_frame));
  p.set_rld_samples(absl::GetFlag(FLAGS_rld_samples));
  p.set_rld_neighbors(absl::GetFlag(FLAGS_rld_neighbors));
  p.set_levels(absl::GetFlag(FLAGS_levels));
  p.set_ld_scale_factor(absl::GetFlag(FLAGS_scale_factor));
  p.set_rld_scale_factor(absl::GetFlag(FLAGS_scale_factor));
  p.set_image_size(absl::GetFlag(FLAGS_image_size));
  p.set_orientation(absl::GetFlag(FLAGS_orientation));
  p.set_depth_to_gray(absl::GetFlag(FLAGS_depth_to_gray));
  p.set_blur_sigma(absl::GetFlag(FLAGS_blur_sigma));
  p.set_max_orientations(absl::GetFlag(FLAGS_max_orientations));
  p.set_vocabulary(absl::GetFlag(FLAGS_vocabulary));
  p.set_kmeans_points_per_centroid(absl::GetFlag(FLAGS_kmeans_points_per_centroid));
  p.set_kmeans_iterations(absl::GetFlag(FLAGS_kmeans_iterations));
  p.set_kmeans_assignment(absl::GetFlag(FLAGS_kmeans_assignment));
  p.set_seed(absl::GetFlag(FLAGS_seed));
  p.set_kl_epsilon(absl::GetFlag(FLAGS_kl_epsilon));
  return p;
}

absl::StatusOr<RetrievalPipelineOptions> PipelineOptionsFromFlags() {
  // Validates the method name first so the error names the flag.
  MESHSEEK_RETURN_IF_ERROR(ParseFeatureMethod(absl::GetFlag(FLAGS_method)).status());
  MESHSEEK_ASSIGN_OR_RETURN(RetrievalPipelineOptions options,
                            rpc::PipelineOptionsFromParams(PipelineParamsFromFlags()));
  options.num_threads = absl::GetFlag(FLAGS_threads);
  options.show_progress = absl::GetFlag(FLAGS_progress);
  MESHSEEK_RETURN_IF_ERROR(options.Validate());
  return options;
}

}  // namespace meshseek::cli
