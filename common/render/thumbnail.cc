#include "common/render/thumbnail.h"

#include <algorithm>
#include <cmath>
#include <opencv2/core.hpp>
#include <opencv2/imgproc.hpp>
#include <vector>

#include "absl/strings/str_cat.h"
#include "common/base/status_macros.h"
#include "common/render/png.h"
#include "common/render/view_renderer.h"

namespace meshseek {

absl::Status ThumbnailOptions::Validate() const {
  if (size < 16 || size > 1024) {
    return absl::InvalidArgumentError(
        absl::StrCat("thumbnail: size must be in [16, 1024], got ", size));
  }
  if (supersample < 1 || supersample > 4) {
    return absl::InvalidArgumentError(
        absl::StrCat("thumbnail: supersample must be in [1, 4], got ", supersample));
  }
  const Vec3d e = Normalized(eye), u = Normalized(up);
  if (!IsFinite(eye) || !IsFinite(up) || Norm(e) == 0 || Norm(u) == 0 || Norm(Cross(e, u)) < 1e-3) {
    return absl::InvalidArgumentError(
        "thumbnail: eye and up must be finite, non-zero and not "
        "parallel");
  }
  for (int c = 0; c < 3; ++c) {
    if (!(colour[c] >= 0 && colour[c] <= 1)) {
      return absl::InvalidArgumentError("thumbnail: colour components must be in [0, 1]");
    }
  }
  return absl::OkStatus();
}

absl::StatusOr<std::string> RenderThumbnailPng(const TriangleMesh& mesh,
                                               const ThumbnailOptions& options) {
  MESHSEEK_RETURN_IF_ERROR(options.Validate());
  ViewRenderOptions view;
  view.image_size = options.size * options.supersample;
  view.window_scale = 1.02;  // a hair of margin: no silhouette touches the border
  view.record_faces = true;
  MESHSEEK_ASSIGN_OR_RETURN(const ViewRenderer renderer, ViewRenderer::Create(mesh, view));

  // The camera sits at `eye` and looks at the centre (view_renderer.h: a
  // view looking along d sees the pole at -d nearest).
  ViewCamera camera;
  camera.direction = -Normalized(options.eye);
  camera.up = Normalized(options.up - camera.direction * Dot(options.up, camera.direction));
  camera.right = Cross(camera.direction, camera.up);
  const ViewImage image = renderer.Render(camera);

  const Vec3d to_camera = -camera.direction;
  const Vec3d key = Normalized(to_camera + camera.up * 1.2 - camera.right * 0.6);
  std::vector<float> shade(mesh.triangles.size(), -1.0f);  // per face, on first use
  const int n = image.size;
  cv::Mat big(n, n, CV_32FC4, cv::Scalar(0, 0, 0, 0));  // premultiplied BGRA
  for (int y = 0; y < n; ++y) {
    for (int x = 0; x < n; ++x) {
      const int32_t f = image.face[static_cast<std::size_t>(y) * n + x];
      if (f < 0) continue;
      if (shade[f] < 0) {
        const Triangle& t = mesh.triangles[f];
        const Vec3d a(mesh.vertices[t[0]]), b(mesh.vertices[t[1]]), c(mesh.vertices[t[2]]);
        Vec3d normal = Normalized(Cross(b - a, c - a));
        if (Dot(normal, to_camera) < 0) normal = -normal;  // two-sided
        shade[f] = static_cast<float>(0.22 + 0.58 * std::max(0.0, Dot(normal, key)) +
                                      0.30 * std::max(0.0, Dot(normal, to_camera)));
      }
      const float s = std::min(1.0f, shade[f]);
      big.at<cv::Vec4f>(y, x) = cv::Vec4f(static_cast<float>(options.colour.z) * s,
                                          static_cast<float>(options.colour.y) * s,
                                          static_cast<float>(options.colour.x) * s,
                                          1.0f);
    }
  }
  cv::Mat small;
  cv::resize(big, small, cv::Size(options.size, options.size), 0, 0, cv::INTER_AREA);
  cv::Mat bgra(options.size, options.size, CV_8UC4);
  for (int y = 0; y < options.size; ++y) {
    for (int x = 0; x < options.size; ++x) {
      const cv::Vec4f p = small.at<cv::Vec4f>(y, x);
      const float alpha = p[3];
      cv::Vec4b& out = bgra.at<cv::Vec4b>(y, x);
      for (int c = 0; c < 3; ++c) {  // un-premultiply the averaged edge pixels
        out[c] = cv::saturate_cast<uint8_t>(alpha > 0 ? 255.0f * p[c] / alpha : 0.0f);
      }
      out[3] = cv::saturate_cast<uint8_t>(255.0f * alpha);
    }
  }
  return EncodePng(bgra);
}

}  // namespace meshseek
