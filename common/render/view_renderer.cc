#include "common/render/view_renderer.h"

#include <algorithm>
#include <cmath>

#include "absl/strings/str_cat.h"
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
  renderer.vertices_.reserve(mesh.vertices.size());
  for (const Vec3f& v : mesh.vertices) {
    renderer.vertices_.push_back((Vec3d(v) - sphere.center) / sphere.radius);
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

ViewImage ViewRenderer::Render(const ViewCamera& frame) const {
  const int n = options_.image_size;
  const double half = 0.5 * n;
  const double to_pixels = half / options_.window_scale;
  ViewImage image;
  image.size = n;
  image.depth.assign(static_cast<std::size_t>(n) * n, 0.0f);
  image.mask.assign(static_cast<std::size_t>(n) * n, 0);
  if (options_.record_faces) image.face.assign(static_cast<std::size_t>(n) * n, -1);
  // Screen position (pixel units, centres at k + 0.5) and depth per vertex.
  struct Projected {
    double x, y, z;
  };
  std::vector<Projected> p(vertices_.size());
  for (std::size_t i = 0; i < vertices_.size(); ++i) {
    const Vec3d& v = vertices_[i];
    p[i] = {half + Dot(v, frame.right) * to_pixels, half - Dot(v, frame.up) * to_pixels,
            0.5 * (1.0 - Dot(v, frame.direction))};
  }
  for (const Triangle& t : triangles_) {
    const Projected& a = p[t[0]];
    const Projected& b = p[t[1]];
    const Projected& c = p[t[2]];
    const double area = (b.x - a.x) * (c.y - a.y) - (b.y - a.y) * (c.x - a.x);
    if (!(std::abs(area) > 1e-12)) continue;  // edge-on, or degenerate
    // Pixels whose centre can be inside: k + 0.5 in [min, max].
    const int x0 = std::max(0, static_cast<int>(std::ceil(std::min({a.x, b.x, c.x}) - 0.5)));
    const int x1 = std::min(n - 1, static_cast<int>(std::floor(std::max({a.x, b.x, c.x}) - 0.5)));
    const int y0 = std::max(0, static_cast<int>(std::ceil(std::min({a.y, b.y, c.y}) - 0.5)));
    const int y1 = std::min(n - 1, static_cast<int>(std::floor(std::max({a.y, b.y, c.y}) - 0.5)));
    const double inverse = 1.0 / area;
    for (int y = y0; y <= y1; ++y) {
      const double cy = y + 0.5;
      for (int x = x0; x <= x1; ++x) {
        const double cx = x + 0.5;
        // Barycentric weights as signed sub-areas over the whole.
        const double wa = ((b.x - cx) * (c.y - cy) - (b.y - cy) * (c.x - cx)) * inverse;
        const double wb = ((c.x - cx) * (a.y - cy) - (c.y - cy) * (a.x - cx)) * inverse;
        const double wc = 1.0 - wa - wb;
        if (wa < 0 || wb < 0 || wc < 0) continue;
        const auto z = static_cast<float>(wa * a.z + wb * b.z + wc * c.z);
        const std::size_t at = static_cast<std::size_t>(y) * n + x;
        if (image.mask[at] == 0 || z > image.depth[at]) {
          image.depth[at] = z;
          image.mask[at] = 1;
          if (!image.face.empty()) image.face[at] = static_cast<int32_t>(&t - triangles_.data());
        }
      }
    }
  }
  return image;
}

}  // namespace meshseek
