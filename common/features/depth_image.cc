#include "common/features/depth_image.h"

#include <algorithm>
#include <cmath>

#include "absl/strings/str_cat.h"
#include "common/base/cpu_features.h"

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
    : mesh_(mesh), bvh_(bvh), options_(options) {
  // Vertices relative to the centre of the model's bounding box, so that the
  // projection can run in float even for a model far from the origin: the
  // rounding error is then relative to the model's size, not its position
  // (about 1e-7 of it, a ten-thousandth of a pixel at E = 0.2).
  Vec3d lo(1e300, 1e300, 1e300), hi(-1e300, -1e300, -1e300);
  for (const Vec3f& v : mesh.vertices) {
    for (int k = 0; k < 3; ++k) {
      lo[k] = std::min(lo[k], static_cast<double>(v[k]));
      hi[k] = std::max(hi[k], static_cast<double>(v[k]));
    }
  }
  origin_ = mesh.vertices.empty() ? Vec3d() : (lo + hi) * 0.5;
  centred_.reserve(mesh.vertices.size());
  for (const Vec3f& v : mesh.vertices) centred_.push_back(Vec3f(Vec3d(v) - origin_));
}

// Compiled for AVX-512 and AVX2 as well, picked at run time (the projection
// and culling loop vectorises wider); the same operations per lane, so the
// same images (the module keeps multiply and add apart: CMakeLists.txt).
MESHSEEK_TARGET_CLONES_AVX void DepthImageRenderer::RenderPair(
    const ViewFrame& frame, DepthImage* front, DepthImage* back) {
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

  // Pixel coordinates: pixel centre (col, row) at px = col, py = row; h is
  // the height along the normal. Each is an affine function of the centred
  // vertex position, set up in double and evaluated in float (image-sized
  // numbers).
  const double to_pixel = size / (2 * s);
  const Vec3d p = frame.point - origin_;
  const Vec3f to_px(right * to_pixel), to_py(up * -to_pixel), to_h(normal);
  const float px0 = static_cast<float>((s - Dot(p, right)) * to_pixel - 0.5);
  const float py0 = static_cast<float>((s + Dot(p, up)) * to_pixel - 0.5);
  const float h0 = static_cast<float>(-Dot(p, normal));
  // Per block of candidates: first project the corners and keep the
  // triangles whose bounding box holds a pixel centre and whose height range
  // meets the cube, then test the pixel centres of the kept ones. Most
  // candidates of a dense mesh fail (triangles smaller than pixels, or
  // outside the cube), unpredictably, so the first step has no branches: the
  // corners are gathered into one column per coordinate, projected and tested
  // by a loop the compiler vectorises (local arrays cannot alias), and the
  // kept ones listed.
  const float sf = static_cast<float>(s);
  const float last = static_cast<float>(size - 1);
  const float beyond = static_cast<float>(size);
  constexpr int kBlock = 64;
  for (std::size_t start = 0; start < candidates_.size(); start += kBlock) {
    const int m = static_cast<int>(std::min<std::size_t>(kBlock, candidates_.size() - start));
    float corner[9][kBlock];  // x, y, z of corner 0, then 1, then 2
    for (int j = 0; j < m; ++j) {
      const Triangle& t = mesh_.triangles[candidates_[start + j]];
      for (int k = 0; k < 3; ++k) {
        const Vec3f& c = centred_[t[k]];
        corner[3 * k][j] = c.x;
        corner[3 * k + 1][j] = c.y;
        corner[3 * k + 2][j] = c.z;
      }
    }
    float view[9][kBlock];  // column, row, height of corner 0, then 1, then 2
    int bounds[4][kBlock];  // first and last column, first and last row
    int keep[kBlock];
    for (int j = 0; j < m; ++j) {
      float x[3], y[3], h[3];
      for (int k = 0; k < 3; ++k) {
        const float cx = corner[3 * k][j], cy = corner[3 * k + 1][j], cz = corner[3 * k + 2][j];
        view[3 * k][j] = x[k] = px0 + to_px.x * cx + to_px.y * cy + to_px.z * cz;
        view[3 * k + 1][j] = y[k] = py0 + to_py.x * cx + to_py.y * cy + to_py.z * cz;
        view[3 * k + 2][j] = h[k] = h0 + to_h.x * cx + to_h.y * cy + to_h.z * cz;
      }
      // Clamped to [0, I] and [-1, I - 1] (vertices are finite: ValidateMesh)
      // so that truncation gives ceilings and floors: the first column is
      // I - floor(I - min_x), the last trunc(max_x), which is one too high
      // only for max_x in (-1, 0) (a triangle then tested in vain; the exact
      // floor defeats the vectoriser).
      const float min_x = std::min(std::max(std::min(std::min(x[0], x[1]), x[2]), 0.0f), beyond);
      const float max_x = std::max(std::min(std::max(std::max(x[0], x[1]), x[2]), last), -1.0f);
      const float min_y = std::min(std::max(std::min(std::min(y[0], y[1]), y[2]), 0.0f), beyond);
      const float max_y = std::max(std::min(std::max(std::max(y[0], y[1]), y[2]), last), -1.0f);
      const float min_h = std::min(std::min(h[0], h[1]), h[2]);
      const float max_h = std::max(std::max(h[0], h[1]), h[2]);
      bounds[0][j] = size - static_cast<int>(beyond - min_x);
      bounds[1][j] = static_cast<int>(max_x);
      bounds[2][j] = size - static_cast<int>(beyond - min_y);
      bounds[3][j] = static_cast<int>(max_y);
      keep[j] = (bounds[0][j] <= bounds[1][j]) & (bounds[2][j] <= bounds[3][j]) & (min_h <= sf) &
                (max_h >= -sf);
    }
    int kept[kBlock];
    int num_kept = 0;
    for (int j = 0; j < m; ++j) {
      kept[num_kept] = j;
      num_kept += keep[j];
    }

    for (int q = 0; q < num_kept; ++q) {
      const int j = kept[q];
      const float x[3] = {view[0][j], view[3][j], view[6][j]};
      const float y[3] = {view[1][j], view[4][j], view[7][j]};
      const float h[3] = {view[2][j], view[5][j], view[8][j]};
      const float area = (x[1] - x[0]) * (y[2] - y[0]) - (x[2] - x[0]) * (y[1] - y[0]);
      if (std::abs(area) < 1e-9f) continue;  // seen edge-on
      const float inv_area = 1.0f / area;
      for (int row = bounds[2][j]; row <= bounds[3][j]; ++row) {
        const float py = static_cast<float>(row);
        for (int col = bounds[0][j]; col <= bounds[1][j]; ++col) {
          const float px = static_cast<float>(col);
          // Barycentric weights from edge functions; inclusive of edges.
          const float w0 = ((x[1] - px) * (y[2] - py) - (x[2] - px) * (y[1] - py)) * inv_area;
          const float w1 = ((x[2] - px) * (y[0] - py) - (x[0] - px) * (y[2] - py)) * inv_area;
          const float w2 = 1.0f - w0 - w1;
          constexpr float kEdgeEps = -1e-6f;
          if (w0 < kEdgeEps || w1 < kEdgeEps || w2 < kEdgeEps) continue;
          const float height = w0 * h[0] + w1 * h[1] + w2 * h[2];
          if (height > sf || height < -sf) continue;
          const std::size_t i = static_cast<std::size_t>(row) * size + col;
          highest_[i] = std::max(highest_[i], height);
          lowest_[i] = std::min(lowest_[i], height);
        }
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
