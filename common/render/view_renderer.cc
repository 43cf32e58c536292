#include "common/render/view_renderer.h"

#include <algorithm>
#include <cmath>

#include "absl/strings/str_cat.h"
#include "common/base/cpu_features.h"
#include "common/base/status_macros.h"

namespace meshseek {

absl::Status ViewRenderOptions::Validate() const {
  if (image_size < 8 || image_size > 4096) {
    return absl::InvalidArgumentError(
        absl::StrCat("view renderer: image_size must be in [8, 4096], got ", image_size));
  }
  if (!(window_scale > 0 && window_scale <= 16)) {
    return absl::InvalidArgumentError(
        absl::StrCat("view renderer: window_scale must be in (0, 16], got ", window_scale));
  }
  return absl::OkStatus();
}

ViewCamera CameraFor(const Vec3d& direction) {
  ViewCamera frame;
  frame.direction = Normalized(direction);
  const Vec3d& d = frame.direction;
  // The world axis least aligned with d, made orthogonal to it.
  Vec3d axis(0, 0, 0);
  const double ax = std::abs(d.x), ay = std::abs(d.y), az = std::abs(d.z);
  if (ay <= ax && ay <= az) {
    axis.y = 1;
  } else if (az <= ax) {
    axis.z = 1;
  } else {
    axis.x = 1;
  }
  frame.up = Normalized(axis - d * Dot(axis, d));
  // right x up = (d x up) x up = -d, up being a unit vector orthogonal to d.
  frame.right = Cross(d, frame.up);
  return frame;
}

absl::StatusOr<ViewRenderer> ViewRenderer::Create(const TriangleMesh& mesh,
                                                  const ViewRenderOptions& options) {
  MESHSEEK_RETURN_IF_ERROR(options.Validate());
  if (mesh.triangles.empty()) return absl::InvalidArgumentError("view renderer: mesh has no triangles");
  MESHSEEK_ASSIGN_OR_RETURN(const Sphere sphere, MinimumEnclosingSphere(mesh));
  if (!(sphere.radius > 0)) {
    return absl::InvalidArgumentError("view renderer: model has zero extent (all vertices coincide)");
  }
  ViewRenderer renderer(options, sphere);
  for (auto* axis : {&renderer.x_, &renderer.y_, &renderer.z_}) axis->reserve(mesh.vertices.size());
  for (const Vec3f& v : mesh.vertices) {
    const Vec3d unit = (Vec3d(v) - sphere.center) / sphere.radius;
    renderer.x_.push_back(unit.x);
    renderer.y_.push_back(unit.y);
    renderer.z_.push_back(unit.z);
  }
  renderer.triangles_.reserve(mesh.triangles.size());
  for (const Triangle& t : mesh.triangles) {
    if (t[0] >= mesh.vertices.size() || t[1] >= mesh.vertices.size() ||
        t[2] >= mesh.vertices.size()) {
      return absl::InvalidArgumentError(absl::StrCat(
          "view renderer: triangle ", &t - mesh.triangles.data(), " has a vertex index past ",
          mesh.vertices.size()));
    }
    renderer.triangles_.push_back(t);
  }
  return renderer;
}

namespace {

// Screen position (pixel units, centres at k + 0.5) and depth of each of `n`
// vertices (x, y, z arrays) for the camera (r: right, u: up, d: direction),
// one vertex at a time so that it vectorises (compiled wider; multiply and
// add kept apart, so every variant computes the same doubles).
MESHSEEK_TARGET_CLONES_AVX void ProjectVertices(std::size_t n,
                                                const double* __restrict x,
                                                const double* __restrict y,
                                                const double* __restrict z,
                                                Vec3d r,
                                                Vec3d u,
                                                Vec3d d,
                                                double half,
                                                double to_pixels,
                                                double* __restrict px,
                                                double* __restrict py,
                                                double* __restrict pz) {
  for (std::size_t i = 0; i < n; ++i) {
    px[i] = half + (x[i] * r.x + y[i] * r.y + z[i] * r.z) * to_pixels;
    py[i] = half - (x[i] * u.x + y[i] * u.y + z[i] * u.z) * to_pixels;
    pz[i] = 0.5 * (1.0 - (x[i] * d.x + y[i] * d.y + z[i] * d.z));
  }
}

// The pixel centres k + 0.5 a vertex at screen coordinate p could bound: a
// triangle's first column is the least of its corners' ceil(p - 0.5), its
// last the greatest floor(p - 0.5) (rounding is monotone, so the minimum
// commutes with it: the same columns as rounding the triangle's extremes).
// Clamped to [0, size] and [-1, size - 1], which keeps every decision of the
// cull (a first column past the image stays past the last one) and fits an
// int16 for any image_size (at most 4096).
MESHSEEK_TARGET_CLONES_AVX void PixelSpans(std::size_t n,
                                           const double* __restrict p,
                                           int size,
                                           int16_t* __restrict first,
                                           int16_t* __restrict last) {
  const double beyond = size, end = size - 1;
  for (std::size_t i = 0; i < n; ++i) {
    const double q = p[i] - 0.5;
    first[i] = static_cast<int16_t>(std::min(std::max(std::ceil(q), 0.0), beyond));
    last[i] = static_cast<int16_t>(std::min(std::max(std::floor(q), -1.0), end));
  }
}

// The vertices of one view: screen x, y (pixel units) and depth, and each
// one's span of pixel columns and rows (PixelSpans).
struct Projection {
  std::vector<double> x, y, depth;
  std::vector<int16_t> first_col, last_col, first_row, last_row;
};

Projection Project(const std::vector<double>& x,
                   const std::vector<double>& y,
                   const std::vector<double>& z,
                   const ViewCamera& frame,
                   const ViewRenderOptions& options) {
  const int n = options.image_size;
  const double half = 0.5 * n;
  const double to_pixels = half / options.window_scale;
  const std::size_t count = x.size();
  Projection p{std::vector<double>(count), std::vector<double>(count), std::vector<double>(count),
               std::vector<int16_t>(count), std::vector<int16_t>(count),
               std::vector<int16_t>(count), std::vector<int16_t>(count)};
  ProjectVertices(count, x.data(), y.data(), z.data(), frame.right, frame.up, frame.direction,
                  half, to_pixels, p.x.data(), p.y.data(), p.depth.data());
  PixelSpans(count, p.x.data(), n, p.first_col.data(), p.last_col.data());
  PixelSpans(count, p.y.data(), n, p.first_row.data(), p.last_row.data());
  return p;
}

// The pixel centres of one triangle's box (x0..x1, y0..y1) that its closure
// holds take its interpolated depth where it is the nearest surface so far
// (largest depth; the earlier triangle on ties). kSilhouette: only the mask,
// and a pixel already covered is not tested again (it stays covered whatever
// the test says), so the mask is Render's.
template <bool kSilhouette>
inline void RasterizeTriangle(const double (&a)[3],
                              const double (&b)[3],
                              const double (&c)[3],
                              int32_t index,
                              int x0,
                              int x1,
                              int y0,
                              int y1,
                              int n,
                              float* depth,
                              uint8_t* mask,
                              int32_t* face) {
  const double ax = a[0], ay = a[1], bx = b[0], by = b[1], cx = c[0], cy = c[1];
  const double area = (bx - ax) * (cy - ay) - (by - ay) * (cx - ax);
  if (!(std::abs(area) > 1e-12)) return;  // edge-on, or degenerate
  const double inverse = 1.0 / area;
  for (int y = y0; y <= y1; ++y) {
    const double sy = y + 0.5;
    for (int x = x0; x <= x1; ++x) {
      const std::size_t at = static_cast<std::size_t>(y) * n + x;
      if (kSilhouette && mask[at] != 0) continue;
      const double sx = x + 0.5;
      // Barycentric weights as signed sub-areas over the whole.
      const double wa = ((bx - sx) * (cy - sy) - (by - sy) * (cx - sx)) * inverse;
      const double wb = ((cx - sx) * (ay - sy) - (cy - sy) * (ax - sx)) * inverse;
      const double wc = 1.0 - wa - wb;
      if (wa < 0 || wb < 0 || wc < 0) continue;
      if (kSilhouette) {
        mask[at] = 1;
        continue;
      }
      const auto z = static_cast<float>(wa * a[2] + wb * b[2] + wc * c[2]);
      if (mask[at] == 0 || z > depth[at]) {
        depth[at] = z;
        mask[at] = 1;
        if (face != nullptr) face[at] = index;
      }
    }
  }
}

// Whether every pixel of the box is covered already (kSilhouette: then the
// triangle can change nothing).
inline bool BoxCovered(const uint8_t* mask, int n, int x0, int x1, int y0, int y1) {
  for (int y = y0; y <= y1; ++y) {
    const uint8_t* row = mask + static_cast<std::size_t>(y) * n;
    for (int x = x0; x <= x1; ++x) {
      if (row[x] == 0) return false;
    }
  }
  return true;
}

// Z-buffers the triangles, their vertices projected (p), into the n x n
// image: a pixel takes the triangle nearest the camera (largest depth) whose
// closure holds its centre, the first such in triangle order on ties.
// Most triangles of a detailed mesh are smaller than a pixel and hold no
// pixel centre, unpredictably: blocks of triangles are first culled without
// branches from their corners' integer spans (PixelSpans), then the few left
// are rasterised; for a silhouette, those whose box is covered already (the
// surfaces behind the first) are skipped too.
template <bool kSilhouette>
[[gnu::always_inline]] inline void RasterizeBlocks(const std::vector<Triangle>& triangles,
                                                   const Projection& p,
                                                   int n,
                                                   float* depth,
                                                   uint8_t* mask,
                                                   int32_t* face) {
  // Raw pointers, loaded once: `mask` is bytes, and a store through it could
  // otherwise be the vectors' own pointers as far as the compiler knows.
  const std::size_t count = triangles.size();
  const Triangle* tri = triangles.data();
  const double *px = p.x.data(), *py = p.y.data(), *pz = p.depth.data();
  const int16_t *first_col = p.first_col.data(), *last_col = p.last_col.data();
  const int16_t *first_row = p.first_row.data(), *last_row = p.last_row.data();
  constexpr int kBlock = 64;
  for (std::size_t start = 0; start < count; start += kBlock) {
    const int m = static_cast<int>(std::min<std::size_t>(kBlock, count - start));
    int16_t box[4][kBlock];  // first and last column, first and last row
    int kept[kBlock];
    int num_kept = 0;
    for (int j = 0; j < m; ++j) {
      const Triangle& t = tri[start + j];
      box[0][j] = std::min({first_col[t[0]], first_col[t[1]], first_col[t[2]]});
      box[1][j] = std::max({last_col[t[0]], last_col[t[1]], last_col[t[2]]});
      box[2][j] = std::min({first_row[t[0]], first_row[t[1]], first_row[t[2]]});
      box[3][j] = std::max({last_row[t[0]], last_row[t[1]], last_row[t[2]]});
      kept[num_kept] = j;
      num_kept += (box[0][j] <= box[1][j]) & (box[2][j] <= box[3][j]);
    }
    for (int q = 0; q < num_kept; ++q) {
      const int j = kept[q];
      if (kSilhouette && BoxCovered(mask, n, box[0][j], box[1][j], box[2][j], box[3][j])) continue;
      const Triangle& t = tri[start + j];
      const double a[3] = {px[t[0]], py[t[0]], pz[t[0]]};
      const double b[3] = {px[t[1]], py[t[1]], pz[t[1]]};
      const double c[3] = {px[t[2]], py[t[2]], pz[t[2]]};
      RasterizeTriangle<kSilhouette>(a, b, c, static_cast<int32_t>(start + j), box[0][j],
                                     box[1][j], box[2][j], box[3][j], n, depth, mask, face);
    }
  }
}

// Compiled wider too (gathers, and the rasteriser's rounding).
MESHSEEK_TARGET_CLONES_AVX void Rasterize(const std::vector<Triangle>& triangles,
                                          const Projection& p,
                                          int n,
                                          float* depth,
                                          uint8_t* mask,
                                          int32_t* face) {
  RasterizeBlocks<false>(triangles, p, n, depth, mask, face);
}

MESHSEEK_TARGET_CLONES_AVX void RasterizeSilhouette(const std::vector<Triangle>& triangles,
                                                    const Projection& p,
                                                    int n,
                                                    uint8_t* mask) {
  RasterizeBlocks<true>(triangles, p, n, nullptr, mask, nullptr);
}

}  // namespace

ViewImage ViewRenderer::Render(const ViewCamera& frame) const {
  const int n = options_.image_size;
  ViewImage image;
  image.size = n;
  image.depth.assign(static_cast<std::size_t>(n) * n, 0.0f);
  image.mask.assign(static_cast<std::size_t>(n) * n, 0);
  if (options_.record_faces) image.face.assign(static_cast<std::size_t>(n) * n, -1);
  const Projection p = Project(x_, y_, z_, frame, options_);
  Rasterize(triangles_, p, n, image.depth.data(), image.mask.data(),
            options_.record_faces ? image.face.data() : nullptr);
  return image;
}

std::vector<uint8_t> ViewRenderer::RenderSilhouette(const ViewCamera& frame) const {
  const int n = options_.image_size;
  std::vector<uint8_t> mask(static_cast<std::size_t>(n) * n, 0);
  const Projection p = Project(x_, y_, z_, frame, options_);
  RasterizeSilhouette(triangles_, p, n, mask.data());
  return mask;
}

}  // namespace meshseek
