#include "common/features/dld_sift.h"

#include <algorithm>
#include <cmath>

#include "absl/strings/str_cat.h"
#include "common/base/status_macros.h"
#include "common/features/local_depth_sift.h"
#include "common/geometry/enclosing_sphere.h"
#include "common/geometry/point_grid.h"
#include "common/geometry/surface_sampler.h"

namespace meshseek {

absl::Status DldSiftOptions::Validate() const {
  if (num_points < 1 || num_points > 1000000) {
    return absl::InvalidArgumentError(
        absl::StrCat("DLD-SIFT num_points must be in [1, 1000000], got ", num_points));
  }
  if (!(scale > 0) || scale > 2) {
    return absl::InvalidArgumentError(
        absl::StrCat("DLD-SIFT scale E must be in (0, 2], got ", scale));
  }
  if (!(frame_radius_factor >= 0.25 && frame_radius_factor <= 4)) {
    return absl::InvalidArgumentError(absl::StrCat(
        "DLD-SIFT frame_radius_factor must be in [0.25, 4], got ", frame_radius_factor));
  }
  if (frame_samples_per_support < 8) {
    return absl::InvalidArgumentError(absl::StrCat(
        "DLD-SIFT frame_samples_per_support must be >= 8, got ", frame_samples_per_support));
  }
  if (min_frame_samples < 16 || max_frame_samples < min_frame_samples) {
    return absl::InvalidArgumentError(
        absl::StrCat("DLD-SIFT frame sample bounds must satisfy 16 <= min <= max, got min ",
                     min_frame_samples,
                     ", max ",
                     max_frame_samples));
  }
  MESHSEEK_RETURN_IF_ERROR(depth_image.Validate());
  return descriptor.Validate();
}

absl::StatusOr<LocalFeatures> ExtractDldSift(const TriangleMesh& mesh,
                                             const DldSiftOptions& options,
                                             int num_threads) {
  MESHSEEK_RETURN_IF_ERROR(options.Validate());
  MESHSEEK_RETURN_IF_ERROR(ValidateMesh(mesh));
  MESHSEEK_ASSIGN_OR_RETURN(const Sphere sphere, MinimumEnclosingSphere(mesh));
  const double s = options.scale * sphere.radius;
  if (!(s > 0)) {
    return absl::InvalidArgumentError("model has zero extent (all vertices coincide)");
  }
  MESHSEEK_ASSIGN_OR_RETURN(const SurfacePoints centres, SampleSurface(mesh, options.num_points));

  const double area = SurfaceArea(mesh);
  const double wanted = options.frame_samples_per_support * area / (M_PI * s * s);
  const int64_t frame_count = static_cast<int64_t>(
      std::clamp<double>(std::ceil(wanted), options.min_frame_samples, options.max_frame_samples));
  MESHSEEK_ASSIGN_OR_RETURN(const SurfacePoints dense, SampleSurface(mesh, frame_count));
  const double frame_radius = options.frame_radius_factor * s;
  const PointGrid grid(dense.positions, static_cast<float>(frame_radius));
  LocalFeatures features = DescribeFrames(
      mesh, centres.size(), options.two_views, options.depth_image, options.descriptor,
      num_threads,
      [&](std::size_t i, std::vector<uint32_t>* support) -> std::optional<LevelFrame> {
        const Vec3f& p = centres.positions[i];
        const auto axes =
            SupportAxes(dense.positions, grid, p, frame_radius, options.weighted_frame, support);
        if (!axes) return std::nullopt;
        return LevelFrame{{Vec3d(p), axes->axes[0], axes->axes[2], s}, 0};
      });
  if (features.keypoints.empty()) {
    return absl::InvalidArgumentError("DLD-SIFT found no usable feature point on the model");
  }
  return features;
}

}  // namespace meshseek
