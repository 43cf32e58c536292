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

DepthImageRenderer::DepthImageRenderer(const TriangleMesh& mesh,
                                       const TriangleBvh& bvh,
                                       const DepthImageOptions& options)
    : mesh_(mesh), bvh_(bvh), options_(options), projected_(mesh.vertices.size()) {}

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

  // Pixel coordinates: pixel centre (col, row) at px = col, py = row. The
  // projection is done in double (models may sit far from the origin), the
  // per-pixel work in float (image-sized numbers).
  const double to_pixel = size / (2 * s);
  if (++current_stamp_ == 0) {  // wrapped: reset the cache marks
    for (Projected& p : projected_) p.stamp = 0;
    current_stamp_ = 1;
  }
  const float sf = static_cast<float>(s);
  const float last = static_cast<float>(size - 1);
  for (const uint32_t t : candidates_) {
    const Projected* corner[3];
    for (int k = 0; k < 3; ++k) {
      const uint32_t v = mesh_.triangles[t][k];
      Projected& proj = projected_[v];
      if (proj.stamp != current_stamp_) {
        proj.stamp = current_stamp_;
        const Vec3d d = Vec3d(mesh_.vertices[v]) - frame.point;
        proj.px = static_cast<float>((Dot(d, right) + s) * to_pixel - 0.5);
        proj.py = static_cast<float>((s - Dot(d, up)) * to_pixel - 0.5);
        proj.h = static_cast<float>(Dot(d, normal));
      }
      corner[k] = &proj;
    }
    const Projected &a = *corner[0], &b = *corner[1], &c = *corner[2];
    if ((a.h > sf && b.h > sf && c.h > sf) || (a.h < -sf && b.h < -sf && c.h < -sf)) continue;
    // Pixel centres inside the triangle's bounding box; most triangles of a
    // dense mesh cover none and stop here.
    const float min_x = std::max(0.0f, std::ceil(std::min({a.px, b.px, c.px})));
    const float max_x = std::min(last, std::floor(std::max({a.px, b.px, c.px})));
    if (min_x > max_x) continue;
    const float min_y = std::max(0.0f, std::ceil(std::min({a.py, b.py, c.py})));
    const float max_y = std::min(last, std::floor(std::max({a.py, b.py, c.py})));
    if (min_y > max_y) continue;
    const float area = (b.px - a.px) * (c.py - a.py) - (c.px - a.px) * (b.py - a.py);
    if (std::abs(area) < 1e-9f) continue;  // seen edge-on
    const float inv_area = 1.0f / area;
    const int c0 = static_cast<int>(min_x), c1 = static_cast<int>(max_x);
    const int r0 = static_cast<int>(min_y), r1 = static_cast<int>(max_y);
    for (int row = r0; row <= r1; ++row) {
      const float y = static_cast<float>(row);
      for (int col = c0; col <= c1; ++col) {
        const float x = static_cast<float>(col);
        // Barycentric weights from edge functions; inclusive of edges.
        const float w0 = ((b.px - x) * (c.py - y) - (c.px - x) * (b.py - y)) * inv_area;
        const float w1 = ((c.px - x) * (a.py - y) - (a.px - x) * (c.py - y)) * inv_area;
        const float w2 = 1.0f - w0 - w1;
        constexpr float kEdgeEps = -1e-6f;
        if (w0 < kEdgeEps || w1 < kEdgeEps || w2 < kEdgeEps) continue;
        const float height = w0 * a.h + w1 * b.h + w2 * c.h;
        if (height > sf || height < -sf) continue;
        const std::size_t i = static_cast<std::size_t>(row) * size + col;
        highest_[i] = std::max(highest_[i], height);
        lowest_[i] = std::min(lowest_[i], height);
      }
    }
  }

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
  image->at(c, c) = 0.25f * (image->at(c - 1, c) + image->at(c + 1, c) + image->at(c, c - 1) +
                             image->at(c, c + 1));
  return true;
}

}  // namespace meshseek
