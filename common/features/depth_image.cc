#include "common/features/depth_image.h"

#include <algorithm>
#include <cmath>

#include "absl/strings/str_cat.h"

namespace meshseek {

absl::Status DepthImageOptions::Validate() const {
  if (image_size < 3 || image_size > 255 || image_size % 2 == 0) {
    return absl::InvalidArgumentError(
        absl::StrCat("depth image size must be odd and in [3, 255], got ", image_size));
  }
  return absl::OkStatus();
}

DepthImageRenderer::DepthImageRenderer(const TriangleMesh& mesh, const TriangleBvh& bvh,
                                       const DepthImageOptions& options)
    : mesh_(mesh),
      bvh_(bvh),
      options_(options),
      projected_(mesh.vertices.size()),
      stamp_(mesh.vertices.size(), 0) {}

void DepthImageRenderer::RenderPair(const ViewFrame& frame, DepthImage* front, DepthImage* back) {
  const int size = options_.image_size;
  const double s = frame.radius;
  const Vec3d up = frame.up, normal = frame.normal;
  const Vec3d right = Cross(up, normal);  // front camera: forward (-n) x up
  highest_.assign(static_cast<std::size_t>(size) * size, -std::numeric_limits<float>::infinity());
  lowest_.assign(static_cast<std::size_t>(size) * size, std::numeric_limits<float>::infinity());

  // The local cube |x|, |y|, |h| <= s.
  const OrientedBox cube{frame.point, {right, up, normal}, {s, s, s}};
  candidates_.clear();
  bvh_.Query(cube, &candidates_);

  // Pixel coordinates: pixel centre (col, row) at px = col, py = row.
  const double to_pixel = size / (2 * s);
  if (++current_stamp_ == 0) {  // wrapped: reset the cache marks
    std::fill(stamp_.begin(), stamp_.end(), 0);
    current_stamp_ = 1;
  }
  for (const uint32_t t : candidates_) {
    double px[3], py[3], h[3];
    bool all_above = true, all_below = true;
    for (int k = 0; k < 3; ++k) {
      const uint32_t v = mesh_.triangles[t][k];
      Projected& proj = projected_[v];
      if (stamp_[v] != current_stamp_) {
        stamp_[v] = current_stamp_;
        const Vec3d d = Vec3d(mesh_.vertices[v]) - frame.point;
        proj.px = (Dot(d, right) + s) * to_pixel - 0.5;
        proj.py = (s - Dot(d, up)) * to_pixel - 0.5;
        proj.h = Dot(d, normal);
      }
      px[k] = proj.px;
      py[k] = proj.py;
      h[k] = proj.h;
      all_above = all_above && h[k] > s;
      all_below = all_below && h[k] < -s;
    }
    if (all_above || all_below) continue;
    const double area = (px[1] - px[0]) * (py[2] - py[0]) - (px[2] - px[0]) * (py[1] - py[0]);
    if (std::abs(area) < 1e-12) continue;  // seen edge-on
    const int c0 = std::max(0, static_cast<int>(std::ceil(std::min({px[0], px[1], px[2]}))));
    const int c1 = std::min(size - 1, static_cast<int>(std::floor(std::max({px[0], px[1], px[2]}))));
    const int r0 = std::max(0, static_cast<int>(std::ceil(std::min({py[0], py[1], py[2]}))));
    const int r1 = std::min(size - 1, static_cast<int>(std::floor(std::max({py[0], py[1], py[2]}))));
    if (c0 > c1 || r0 > r1) continue;
    const double inv_area = 1.0 / area;
    for (int row = r0; row <= r1; ++row) {
      for (int col = c0; col <= c1; ++col) {
        // Barycentric weights from edge functions; inclusive of edges.
        const double w0 = ((px[1] - col) * (py[2] - row) - (px[2] - col) * (py[1] - row)) * inv_area;
        const double w1 = ((px[2] - col) * (py[0] - row) - (px[0] - col) * (py[2] - row)) * inv_area;
        const double w2 = 1.0 - w0 - w1;
        constexpr double kEdgeEps = -1e-9;
        if (w0 < kEdgeEps || w1 < kEdgeEps || w2 < kEdgeEps) continue;
        const double height = w0 * h[0] + w1 * h[1] + w2 * h[2];
        if (height > s || height < -s) continue;
        const std::size_t i = static_cast<std::size_t>(row) * size + col;
        const float hf = static_cast<float>(height);
        highest_[i] = std::max(highest_[i], hf);
        lowest_[i] = std::min(lowest_[i], hf);
      }
    }
  }

  const float sf = static_cast<float>(s);
  if (front != nullptr) {
    front->size = size;
    front->support_radius = sf;
    front->depth.resize(highest_.size());
    for (std::size_t i = 0; i < highest_.size(); ++i) {
      front->depth[i] = std::isfinite(highest_[i]) ? sf - highest_[i] : DepthImage::kEmpty;
    }
  }
  if (back != nullptr) {
    // The back camera's right vector is -right: its image is the mirror.
    back->size = size;
    back->support_radius = sf;
    back->depth.resize(lowest_.size());
    for (int row = 0; row < size; ++row) {
      for (int col = 0; col < size; ++col) {
        const float low = lowest_[static_cast<std::size_t>(row) * size + (size - 1 - col)];
        back->at(row, col) = std::isfinite(low) ? sf + low : DepthImage::kEmpty;
      }
    }
  }
}

bool FinishDepthImage(DepthImage* image) {
  float deepest = -1;
  for (const float d : image->depth) {
    if (d != DepthImage::kEmpty) deepest = std::max(deepest, d);
  }
  if (deepest < 0) return false;
  for (float& d : image->depth) {
    if (d == DepthImage::kEmpty) d = deepest;
  }
  const int c = image->size / 2;
  image->at(c, c) =
      0.25f * (image->at(c - 1, c) + image->at(c + 1, c) + image->at(c, c - 1) + image->at(c, c + 1));
  return true;
}

}  // namespace meshseek
