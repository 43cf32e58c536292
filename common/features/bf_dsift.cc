#include "common/features/bf_dsift.h"

#include <algorithm>
#include <cmath>

#include "absl/strings/str_cat.h"
#include "common/base/cpu_features.h"
#include "common/base/status_macros.h"
#include "common/geometry/icosphere.h"
#include "common/render/view_renderer.h"

namespace meshseek {
namespace {

// A view's distances from the camera plane (the sphere's near pole) in
// level-0 pixels, background at the far pole, and its 2x box-filtered
// coarser levels.
struct DistancePyramid {
  std::vector<std::vector<float>> levels;
  std::vector<int> sizes;
};

// Resamples patches from a pyramid level: each pixel centre of the patch is
// sampled bilinearly at continuous level-0 coordinates (pixel p spans
// [p, p + 1)), horizontally first, in double. What depends on one coordinate
// only is computed once: a column's source pixel and fraction, and a source
// row's horizontal interpolation, which consecutive patch rows share whenever
// the patch is finer than the level (the smaller radii). Holds its scratch:
// one per thread.
class PatchResampler {
 public:
  // The patch of `radius` level-0 pixels around pixel (px, py) from `level`,
  // as depths from the plane `near` clipped to [0, 2 radius], into `patch`
  // (patch->size pixels square, already sized).
  MESHSEEK_TARGET_CLONES_AVX void Resample(const DistancePyramid& pyramid,
                                           int level,
                                           int px,
                                           int py,
                                           double radius,
                                           double near,
                                           DepthImage* patch);

 private:
  void InterpolateRow(const float* source, std::vector<double>* out) const {
    for (std::size_t col = 0; col < x0_.size(); ++col) {
      (*out)[col] = (1 - fx_[col]) * source[x0_[col]] + fx_[col] * source[x0_[col] + 1];
    }
  }

  std::vector<int> x0_;
  std::vector<double> fx_;
  std::vector<double> upper_, lower_;  // source rows y0 and y0 + 1, interpolated
};

void PatchResampler::Resample(const DistancePyramid& pyramid,
                              int level,
                              int px,
                              int py,
                              double radius,
                              double near,
                              DepthImage* patch) {
  const int image = patch->size;
  const double scale = 1.0 / (1 << level);
  const int n = pyramid.sizes[level];
  const float* distances = pyramid.levels[level].data();
  x0_.resize(image);
  fx_.resize(image);
  upper_.resize(image);
  lower_.resize(image);
  for (int col = 0; col < image; ++col) {
    const double x = px + 0.5 + ((col + 0.5) / image * 2 - 1) * radius;
    const double u = std::clamp(x * scale - 0.5, 0.0, n - 1.0);
    x0_[col] = std::min(static_cast<int>(u), n - 2);
    fx_[col] = u - x0_[col];
  }
  int upper_row = -2;  // the source row upper_ holds
  for (int row = 0; row < image; ++row) {
    const double y = py + 0.5 + ((row + 0.5) / image * 2 - 1) * radius;
    const double v = std::clamp(y * scale - 0.5, 0.0, n - 1.0);
    const int y0 = std::min(static_cast<int>(v), n - 2);
    const double fy = v - y0;
    if (y0 == upper_row + 1) {
      std::swap(upper_, lower_);
      InterpolateRow(distances + static_cast<std::size_t>(y0 + 1) * n, &lower_);
    } else if (y0 != upper_row) {
      InterpolateRow(distances + static_cast<std::size_t>(y0) * n, &upper_);
      InterpolateRow(distances + static_cast<std::size_t>(y0 + 1) * n, &lower_);
    }
    upper_row = y0;
    float* out = &patch->depth[static_cast<std::size_t>(row) * image];
    for (int col = 0; col < image; ++col) {
      const float sampled = static_cast<float>((1 - fy) * upper_[col] + fy * lower_[col]);
      out[col] = static_cast<float>(std::clamp(sampled - near, 0.0, 2 * radius));
    }
  }
}

DistancePyramid BuildPyramid(const ViewImage& view, int max_levels) {
  DistancePyramid pyramid;
  const int n = view.size;
  std::vector<float> base(view.depth.size());
  for (std::size_t i = 0; i < base.size(); ++i) {
    // depth 1 at the near pole, 0 at the far one; the view spans 2 radii.
    base[i] = view.mask[i] ? (1.0f - view.depth[i]) * n : static_cast<float>(n);
  }
  pyramid.levels.push_back(std::move(base));
  pyramid.sizes.push_back(n);
  while (static_cast<int>(pyramid.levels.size()) < max_levels && pyramid.sizes.back() >= 16) {
    const int m = pyramid.sizes.back() / 2;
    const std::vector<float>& fine = pyramid.levels.back();
    const int fn = pyramid.sizes.back();
    std::vector<float> coarse(static_cast<std::size_t>(m) * m);
    for (int y = 0; y < m; ++y) {
      for (int x = 0; x < m; ++x) {
        const std::size_t i = static_cast<std::size_t>(2 * y) * fn + 2 * x;
        coarse[static_cast<std::size_t>(y) * m + x] =
            0.25f * (fine[i] + fine[i + 1] + fine[i + fn] + fine[i + fn + 1]);
      }
    }
    pyramid.levels.push_back(std::move(coarse));
    pyramid.sizes.push_back(m);
  }
  return pyramid;
}

// The dense patches of one view after another (ExtractBfDsift), with the
// scratch they share: one per thread.
class ViewDescriber {
 public:
  ViewDescriber(const ViewRenderer& renderer, const BfDsiftOptions& options)
      : renderer_(renderer), options_(options), describer_(options.descriptor) {
    const int image = options.patch_image.image_size;
    const double largest_radius =
        options.patch_radius * options.view_size * (1 << (options.patch_scales - 1));
    levels_ = 1 + std::max(0, static_cast<int>(std::floor(std::log2(2 * largest_radius / image))));
    patch_.size = image;
    patch_.depth.resize(static_cast<std::size_t>(image) * image);
  }

  // Appends the features of the view along `direction`.
  void Describe(const Vec3d& direction, LocalFeatures* features);

 private:
  const ViewRenderer& renderer_;
  const BfDsiftOptions& options_;
  int levels_ = 1;
  DepthSiftDescriber describer_;
  PatchResampler resampler_;
  DepthImage patch_;
};

void ViewDescriber::Describe(const Vec3d& direction, LocalFeatures* features) {
  const Sphere& sphere = renderer_.sphere();
  const int n = options_.view_size;
  const int image = options_.patch_image.image_size;
  const ViewCamera camera = CameraFor(direction);
  const ViewImage view = renderer_.Render(camera);
  const DistancePyramid pyramid = BuildPyramid(view, levels_);
  std::size_t covered = 0;
  for (const uint8_t m : view.mask) covered += m;
  if (covered == 0) return;
  // A grid step that puts about points_per_view points in the silhouette.
  const double step =
      std::max(1.0, std::sqrt(static_cast<double>(covered) / options_.points_per_view));
  for (double gy = step / 2; gy < n; gy += step) {
    for (double gx = step / 2; gx < n; gx += step) {
      const int px = static_cast<int>(gx), py = static_cast<int>(gy);
      if (!view.Covered(px, py)) continue;
      const float centre = pyramid.levels[0][static_cast<std::size_t>(py) * n + px];
      for (int s = 0; s < options_.patch_scales; ++s) {
        const double radius = options_.patch_radius * n * (1 << s);  // level-0 pixels
        // The pyramid level whose pixels are no larger than the patch's.
        const double pixel = 2 * radius / image;
        const int level =
            std::clamp(static_cast<int>(std::floor(std::log2(std::max(pixel, 1.0)))),
                       0,
                       static_cast<int>(pyramid.levels.size()) - 1);
        patch_.support_radius = static_cast<float>(radius);
        resampler_.Resample(pyramid, level, px, py, radius, centre - radius, &patch_);
        const int added = describer_.Describe(patch_, &features->descriptors);
        // The surface point at the patch centre, back in model units.
        const double a = (px + 0.5) / n * 2 - 1, b = 1 - (py + 0.5) / n * 2;
        const double c = 1 - 2 * view.DepthAt(px, py);
        const Vec3d q = sphere.center +
                        (camera.right * a + camera.up * b + camera.direction * c) * sphere.radius;
        Keypoint k;
        k.position = Vec3f(static_cast<float>(q.x), static_cast<float>(q.y), static_cast<float>(q.z));
        k.view = Vec3f(static_cast<float>(camera.direction.x),
                       static_cast<float>(camera.direction.y),
                       static_cast<float>(camera.direction.z));
        k.up = Vec3f(static_cast<float>(camera.up.x),
                     static_cast<float>(camera.up.y),
                     static_cast<float>(camera.up.z));
        k.scale = static_cast<float>(radius / n * sphere.diameter());
        k.level = s;
        features->keypoints.insert(features->keypoints.end(), added, k);
      }
    }
  }
}

}  // namespace

absl::Status BfDsiftOptions::Validate() const {
  if (view_level < 0 || view_level > 3) {
    return absl::InvalidArgumentError(
        absl::StrCat("BF-DSIFT view_level must be in [0, 3], got ", view_level));
  }
  if (view_size < 32 || view_size > 1024) {
    return absl::InvalidArgumentError(
        absl::StrCat("BF-DSIFT view_size must be in [32, 1024], got ", view_size));
  }
  if (points_per_view < 1 || points_per_view > 100000) {
    return absl::InvalidArgumentError(
        absl::StrCat("BF-DSIFT points_per_view must be in [1, 100000], got ", points_per_view));
  }
  if (!(patch_radius > 0 && patch_radius <= 0.5)) {
    return absl::InvalidArgumentError(
        absl::StrCat("BF-DSIFT patch_radius must be in (0, 0.5], got ", patch_radius));
  }
  if (patch_scales < 1 || patch_scales > 4) {
    return absl::InvalidArgumentError(
        absl::StrCat("BF-DSIFT patch_scales must be in [1, 4], got ", patch_scales));
  }
  MESHSEEK_RETURN_IF_ERROR(patch_image.Validate());
  return descriptor.Validate();
}

absl::StatusOr<LocalFeatures> ExtractBfDsift(const TriangleMesh& mesh,
                                             const BfDsiftOptions& options,
                                             int num_threads) {
  MESHSEEK_RETURN_IF_ERROR(options.Validate());
  ViewRenderOptions render;
  render.image_size = options.view_size;
  MESHSEEK_ASSIGN_OR_RETURN(const ViewRenderer renderer, ViewRenderer::Create(mesh, render));
  const std::vector<Vec3d> directions = IcosphereDirections(options.view_level);
  return DescribeInRuns(directions.size(), num_threads, [&](std::size_t begin, std::size_t end,
                                                            LocalFeatures* out) {
    ViewDescriber describer(renderer, options);
    for (std::size_t v = begin; v < end; ++v) describer.Describe(directions[v], out);
  });
}

}  // namespace meshseek
