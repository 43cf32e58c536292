#include "cli/pipeline_flags.h"

#include <string>

#include "absl/flags/flag.h"
#include "absl/strings/str_cat.h"
#include "common/base/status_macros.h"

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
          kRld.scale_space.scale_factor,
          "ld, rld: C in the feature scale s = C * d * sqrt(level)");
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
namespace {

absl::Status ApplyDescriptorFlags(SiftDescriptorOptions* descriptor) {
  const std::string orientation = absl::GetFlag(FLAGS_orientation);
  if (orientation == "dominant") {
    descriptor->orientation = ImageOrientation::kDominant;
  } else if (orientation == "up") {
    descriptor->orientation = ImageOrientation::kUpAxis;
  } else if (!orientation.empty()) {
    return absl::InvalidArgumentError(
        absl::StrCat("--orientation must be 'dominant' or 'up', got '", orientation, "'"));
  }
  const std::string gray = absl::GetFlag(FLAGS_depth_to_gray);
  if (gray == "fixed") {
    descriptor->depth_to_gray = DepthToGray::kFixedRange;
  } else if (gray == "stretch") {
    descriptor->depth_to_gray = DepthToGray::kStretch;
  } else if (!gray.empty()) {
    return absl::InvalidArgumentError(
        absl::StrCat("--depth_to_gray must be 'fixed' or 'stretch', got '", gray, "'"));
  }
  descriptor->blur_sigma = absl::GetFlag(FLAGS_blur_sigma);
  descriptor->max_orientations = absl::GetFlag(FLAGS_max_orientations);
  return absl::OkStatus();
}

void ApplyScaleSpaceFlags(ScaleSpaceOptions* scale_space) {
  scale_space->levels = absl::GetFlag(FLAGS_levels);
  if (absl::GetFlag(FLAGS_scale_factor) != 0) {
    scale_space->scale_factor = absl::GetFlag(FLAGS_scale_factor);
  }
}

}  // namespace

absl::StatusOr<RetrievalPipelineOptions> PipelineOptionsFromFlags() {
  RetrievalPipelineOptions options;
  ExtractorOptions& extractor = options.extractor;
  MESHSEEK_ASSIGN_OR_RETURN(extractor.method, ParseFeatureMethod(absl::GetFlag(FLAGS_method)));
  extractor.dld.scale = absl::GetFlag(FLAGS_scale);
  extractor.dld.num_points = absl::GetFlag(FLAGS_points);
  extractor.dld.frame_samples_per_support = absl::GetFlag(FLAGS_frame_samples);
  extractor.dld.weighted_frame = absl::GetFlag(FLAGS_weighted_frame);
  extractor.dld.frame_radius_factor = absl::GetFlag(FLAGS_frame_radius);
  extractor.rld.num_samples = absl::GetFlag(FLAGS_rld_samples);
  extractor.rld.neighbors = absl::GetFlag(FLAGS_rld_neighbors);
  extractor.rld.weighted_frame = absl::GetFlag(FLAGS_weighted_frame);
  ApplyScaleSpaceFlags(&extractor.ld.scale_space);
  ApplyScaleSpaceFlags(&extractor.rld.scale_space);
  for (DepthImageOptions* image :
       {&extractor.dld.depth_image, &extractor.ld.depth_image, &extractor.rld.depth_image}) {
    image->image_size = absl::GetFlag(FLAGS_image_size);
  }
  for (SiftDescriptorOptions* descriptor :
       {&extractor.dld.descriptor, &extractor.ld.descriptor, &extractor.rld.descriptor}) {
    MESHSEEK_RETURN_IF_ERROR(ApplyDescriptorFlags(descriptor));
  }
  options.kmeans.num_centroids = absl::GetFlag(FLAGS_vocabulary);
  options.kmeans.max_points_per_centroid = absl::GetFlag(FLAGS_kmeans_points_per_centroid);
  options.kmeans.max_iterations = absl::GetFlag(FLAGS_kmeans_iterations);
  options.kmeans.seed = absl::GetFlag(FLAGS_seed);
  options.kl.epsilon = absl::GetFlag(FLAGS_kl_epsilon);
  options.num_threads = absl::GetFlag(FLAGS_threads);
  options.show_progress = absl::GetFlag(FLAGS_progress);
  MESHSEEK_RETURN_IF_ERROR(options.Validate());
  return options;
}

}  // namespace meshseek::cli
