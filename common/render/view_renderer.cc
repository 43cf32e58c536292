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

// Z-buffers `count` triangles of projected vertices (px, py, pz) into the
// n x n image: a pixel takes the triangle nearest the camera (largest depth)
// whose closure holds its centre, the first such in triangle order on ties.
// Compiled wider too, for its rounding instructions (ceil and floor are
// library calls on baseline x86-64).
MESHSEEK_TARGET_CLONES_AVX void Rasterize(const Triangle* triangles,
                                          std::size_t count,
                                          const double* px,
                                          const double* py,
                                          const double* pz,
                                          int n,
                                          float* depth,
                                          uint8_t* mask,
                                          int32_t* face) {
  for (std::size_t f = 0; f < count; ++f) {
    const Triangle& t = triangles[f];
    const double ax = px[t[0]], ay = py[t[0]], az = pz[t[0]];
    const double bx = px[t[1]], by = py[t[1]], bz = pz[t[1]];
    const double cx = px[t[2]], cy = py[t[2]], cz = pz[t[2]];
    // Pixels whose centre can be inside: k + 0.5 in [min, max]. Most
    // triangles of a detailed mesh are smaller than a pixel and hold none.
    const int x0 = std::max(0, static_cast<int>(std::ceil(std::min({ax, bx, cx}) - 0.5)));
    const int x1 = std::min(n - 1, static_cast<int>(std::floor(std::max({ax, bx, cx}) - 0.5)));
    if (x0 > x1) continue;
    const int y0 = std::max(0, static_cast<int>(std::ceil(std::min({ay, by, cy}) - 0.5)));
    const int y1 = std::min(n - 1, static_cast<int>(std::floor(std::max({ay, by, cy}) - 0.5)));
    if (y0 > y1) continue;
    const double area = (bx - ax) * (cy - ay) - (by - ay) * (cx - ax);
    if (!(std::abs(area) > 1e-12)) continue;  // edge-on, or degenerate
    const double inverse = 1.0 / area;
    for (int y = y0; y <= y1; ++y) {
      const double sy = y + 0.5;
      for (int x = x0; x <= x1; ++x) {
        const double sx = x + 0.5;
        // Barycentric weights as signed sub-areas over the whole.
        const double wa = ((bx - sx) * (cy - sy) - (by - sy) * (cx - sx)) * inverse;
        const double wb = ((cx - sx) * (ay - sy) - (cy - sy) * (ax - sx)) * inverse;
        const double wc = 1.0 - wa - wb;
        if (wa < 0 || wb < 0 || wc < 0) continue;
        const auto z = static_cast<float>(wa * az + wb * bz + wc * cz);
        const std::size_t at = static_cast<std::size_t>(y) * n + x;
        if (mask[at] == 0 || z > depth[at]) {
          depth[at] = z;
          mask[at] = 1;
          if (face != nullptr) face[at] = static_cast<int32_t>(f);
        }
      }
    }
  }
}

}  // namespace

ViewImage ViewRenderer::Render(const ViewCamera& frame) const {
  const int n = options_.image_size;
  const double half = 0.5 * n;
  const double to_pixels = half / options_.window_scale;
  ViewImage image;
  image.size = n;
  image.depth.assign(static_cast<std::size_t>(n) * n, 0.0f);
  image.mask.assign(static_cast<std::size_t>(n) * n, 0);
  if (options_.record_faces) image.face.assign(static_cast<std::size_t>(n) * n, -1);
  const std::size_t count = x_.size();
  std::vector<double> projected(3 * count);
  double* px = projected.data();
  double* py = px + count;
  double* pz = py + count;
  ProjectVertices(count, x_.data(), y_.data(), z_.data(), frame.right, frame.up, frame.direction,
                  half, to_pixels, px, py, pz);
  Rasterize(triangles_.data(), triangles_.size(), px, py, pz, n, image.depth.data(),
            image.mask.data(), options_.record_faces ? image.face.data() : nullptr);
  return image;
}

}  // namespace meshseek
