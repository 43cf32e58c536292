#include "common/features/bf_dsift.h"

#include <algorithm>
#include <cmath>

#include "absl/strings/str_cat.h"
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

  float Sample(int level, double x, double y) const {
    // Bilinear at continuous coordinates of level 0 (pixel p spans [p, p+1)).
    const double scale = 1.0 / (1 << level);
    const int n = sizes[level];
    const double u = std::clamp(x * scale - 0.5, 0.0, n - 1.0);
    const double v = std::clamp(y * scale - 0.5, 0.0, n - 1.0);
    const int x0 = std::min(static_cast<int>(u), n - 2), y0 = std::min(static_cast<int>(v), n - 2);
    const double fx = u - x0, fy = v - y0;
    const std::vector<float>& d = levels[level];
    const auto at = [&](int xx, int yy) { return d[static_cast<std::size_t>(yy) * n + xx]; };
    return static_cast<float>((1 - fy) * ((1 - fx) * at(x0, y0) + fx * at(x0 + 1, y0)) +
                              fy * ((1 - fx) * at(x0, y0 + 1) + fx * at(x0 + 1, y0 + 1)));
  }
};

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
                                             const BfDsiftOptions& options) {
  MESHSEEK_RETURN_IF_ERROR(options.Validate());
  ViewRenderOptions render;
  render.image_size = options.view_size;
  MESHSEEK_ASSIGN_OR_RETURN(const ViewRenderer renderer, ViewRenderer::Create(mesh, render));
  const Sphere& sphere = renderer.sphere();
  const int n = options.view_size;
  const int image = options.patch_image.image_size;
  const double largest_radius = options.patch_radius * n * (1 << (options.patch_scales - 1));
  const int levels =
      1 + std::max(0, static_cast<int>(std::floor(std::log2(2 * largest_radius / image))));

  LocalFeatures features;
  DepthSiftDescriber describer(options.descriptor);
  DepthImage patch;
  patch.size = image;
  patch.depth.resize(static_cast<std::size_t>(image) * image);
  for (const Vec3d& direction : IcosphereDirections(options.view_level)) {
    const ViewCamera camera = CameraFor(direction);
    const ViewImage view = renderer.Render(camera);
    const DistancePyramid pyramid = BuildPyramid(view, levels);
    std::size_t covered = 0;
    for (const uint8_t m : view.mask) covered += m;
    if (covered == 0) continue;
    // A grid step that puts about points_per_view points in the silhouette.
    const double step =
        std::max(1.0, std::sqrt(static_cast<double>(covered) / options.points_per_view));
    for (double gy = step / 2; gy < n; gy += step) {
      for (double gx = step / 2; gx < n; gx += step) {
        const int px = static_cast<int>(gx), py = static_cast<int>(gy);
        if (!view.Covered(px, py)) continue;
        const float centre = pyramid.levels[0][static_cast<std::size_t>(py) * n + px];
        for (int s = 0; s < options.patch_scales; ++s) {
          const double radius = options.patch_radius * n * (1 << s);  // level-0 pixels
          // The pyramid level whose pixels are no larger than the patch's.
          const double pixel = 2 * radius / image;
          const int level =
              std::clamp(static_cast<int>(std::floor(std::log2(std::max(pixel, 1.0)))),
                         0,
                         static_cast<int>(pyramid.levels.size()) - 1);
          patch.support_radius = static_cast<float>(radius);
          const double near = centre - radius;
          for (int row = 0; row < image; ++row) {
            const double y = py + 0.5 + ((row + 0.5) / image * 2 - 1) * radius;
            for (int col = 0; col < image; ++col) {
              const double x = px + 0.5 + ((col + 0.5) / image * 2 - 1) * radius;
              const double d = pyramid.Sample(level, x, y) - near;
              patch.at(row, col) = static_cast<float>(std::clamp(d, 0.0, 2 * radius));
            }
          }
          const int added = describer.Describe(patch, &features.descriptors);
          // The surface point at the patch centre, back in model units.
          const double a = (px + 0.5) / n * 2 - 1, b = 1 - (py + 0.5) / n * 2;
          const double c = 1 - 2 * view.DepthAt(px, py);
          const Vec3d q = sphere.center +
                          (camera.right * a + camera.up * b + camera.direction * c) * sphere.radius;
          Keypoint k;
          k.position =
              Vec3f(static_cast<float>(q.x), static_cast<float>(q.y), static_cast<float>(q.z));
          k.view = Vec3f(static_cast<float>(camera.direction.x),
                         static_cast<float>(camera.direction.y),
                         static_cast<float>(camera.direction.z));
          k.up = Vec3f(static_cast<float>(camera.up.x),
                       static_cast<float>(camera.up.y),
                       static_cast<float>(camera.up.z));
          k.scale = static_cast<float>(radius / n * sphere.diameter());
          k.level = s;
          features.keypoints.insert(features.keypoints.end(), added, k);
        }
      }
    }
  }
  return features;
}

}  // namespace meshseek
