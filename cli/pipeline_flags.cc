#include "cli/pipeline_flags.h"

#include <string>

#include "absl/flags/flag.h"
#include "absl/strings/str_cat.h"
#include "common/base/status_macros.h"

namespace {
const meshseek::RetrievalPipelineOptions kDefaults;
const meshseek::DldSiftOptions& kDld = kDefaults.extractor.dld;
}  // namespace

ABSL_FLAG(std::string, method, "dld", "local feature method: dld (DLD-SIFT)");
ABSL_FLAG(double, scale, kDld.scale,
          "support radius E relative to the minimum enclosing sphere (s = E * D / 2)");
ABSL_FLAG(int, points, kDld.num_points, "DLD-SIFT feature points per model (N_DLD)");
ABSL_FLAG(int, image_size, kDld.depth_image.image_size, "depth image side I in pixels (odd)");
ABSL_FLAG(int, frame_samples, kDld.frame_samples_per_support,
          "dense surface samples per support disc for the local PCA frame");
ABSL_FLAG(bool, weighted_frame, kDld.weighted_frame,
          "distance-weighted (SHOT-style) PCA frame instead of plain PCA");
ABSL_FLAG(std::string, orientation,
          kDld.descriptor.orientation == meshseek::ImageOrientation::kDominant ? "dominant" : "up",
          "descriptor rotation: dominant (Lowe's gradient peaks) | up (PCA up axis + 180-degree sum)");
ABSL_FLAG(std::string, depth_to_gray,
          kDld.descriptor.depth_to_gray == meshseek::DepthToGray::kStretch ? "stretch" : "fixed",
          "depth to grey mapping: fixed (2s range) | stretch (image range)");
ABSL_FLAG(double, blur_sigma, kDld.descriptor.blur_sigma, "SIFT blur sigma in pixels");
ABSL_FLAG(int, vocabulary, kDefaults.kmeans.num_centroids, "codebook size V (k-means centroids)");
ABSL_FLAG(uint64_t, seed, kDefaults.kmeans.seed,
          "seed of every random choice (k-means sampling and seeding; synth shapes)");
ABSL_FLAG(double, kl_epsilon, kDefaults.kl.epsilon,
          "mass added to every histogram bin before KL divergence (zero-bin rule)");
ABSL_FLAG(int, threads, kDefaults.num_threads, "threads (0: all cores)");
ABSL_FLAG(bool, progress, true, "show progress bars on stderr");

namespace meshseek::cli {

absl::StatusOr<RetrievalPipelineOptions> PipelineOptionsFromFlags() {
  RetrievalPipelineOptions options;
  MESHSEEK_ASSIGN_OR_RETURN(options.extractor.method, ParseFeatureMethod(absl::GetFlag(FLAGS_method)));
  DldSiftOptions& dld = options.extractor.dld;
  dld.scale = absl::GetFlag(FLAGS_scale);
  dld.num_points = absl::GetFlag(FLAGS_points);
  dld.depth_image.image_size = absl::GetFlag(FLAGS_image_size);
  dld.frame_samples_per_support = absl::GetFlag(FLAGS_frame_samples);
  dld.weighted_frame = absl::GetFlag(FLAGS_weighted_frame);
  const std::string orientation = absl::GetFlag(FLAGS_orientation);
  if (orientation == "dominant") {
    dld.descriptor.orientation = ImageOrientation::kDominant;
  } else if (orientation == "up") {
    dld.descriptor.orientation = ImageOrientation::kUpAxis;
  } else {
    return absl::InvalidArgumentError(
        absl::StrCat("--orientation must be 'dominant' or 'up', got '", orientation, "'"));
  }
  const std::string gray = absl::GetFlag(FLAGS_depth_to_gray);
  if (gray == "fixed") {
    dld.descriptor.depth_to_gray = DepthToGray::kFixedRange;
  } else if (gray == "stretch") {
    dld.descriptor.depth_to_gray = DepthToGray::kStretch;
  } else {
    return absl::InvalidArgumentError(
        absl::StrCat("--depth_to_gray must be 'fixed' or 'stretch', got '", gray, "'"));
  }
  dld.descriptor.blur_sigma = absl::GetFlag(FLAGS_blur_sigma);
  options.kmeans.num_centroids = absl::GetFlag(FLAGS_vocabulary);
  options.kmeans.seed = absl::GetFlag(FLAGS_seed);
  options.kl.epsilon = absl::GetFlag(FLAGS_kl_epsilon);
  options.num_threads = absl::GetFlag(FLAGS_threads);
  options.show_progress = absl::GetFlag(FLAGS_progress);
  MESHSEEK_RETURN_IF_ERROR(options.Validate());
  return options;
}

}  // namespace meshseek::cli
