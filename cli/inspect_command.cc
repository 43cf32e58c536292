// `meshseek inspect MODEL --method METHOD --out DIR`: what the detector and
// the renderer did on one model, for a person to look at.
//   DIR/points.ply        the feature points, coloured by scale-space level
//   DIR/points.png        the model seen along its smallest principal axis,
//                         shaded by depth, with the visible feature points
//   DIR/depth_images.png  a montage of depth images of a sample of features
//                         (local methods)
//   DIR/views.png         the whole-model views the method describes: BF-DSIFT's
//                         depth images with their sample points, LFD's
//                         silhouettes of its first light field
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <map>
#include <opencv2/core.hpp>
#include <opencv2/imgproc.hpp>
#include <string>
#include <vector>

#include "absl/strings/str_cat.h"
#include "cli/commands.h"
#include "common/base/status_macros.h"
#include "common/features/depth_image.h"
#include "common/geometry/enclosing_sphere.h"
#include "common/geometry/icosphere.h"
#include "common/geometry/mesh_io.h"
#include "common/geometry/principal_axes.h"
#include "common/geometry/triangle_bvh.h"
#include "common/global/lfd_cameras.h"
#include "common/render/png.h"
#include "common/render/view_renderer.h"


namespace meshseek::cli {
namespace {

// Level 1, 2, 3, ... -> distinct colours (BGR); level 0 (dense points) red.
cv::Scalar LevelColour(int level) {
  static const cv::Scalar kPalette[] = {{40, 40, 230},
                                        {230, 120, 30},
                                        {40, 180, 40},
                                        {200, 60, 200},
                                        {30, 200, 230},
                                        {200, 200, 40},
                                        {120, 60, 20},
                                        {90, 90, 90}};
  return kPalette[std::min<std::size_t>(std::max(level - 1, 0), std::size(kPalette) - 1)];
}

absl::Status WritePointsPly(const std::string& path, const LocalFeatures& features) {
  // One point per feature site (a site may carry several descriptors).
  std::map<std::tuple<float, float, float>, int> sites;
  for (const Keypoint& k : features.keypoints) {
    sites.emplace(std::make_tuple(k.position.x, k.position.y, k.position.z), k.level);
  }
  std::ofstream out(path);
  out << "ply\nformat ascii 1.0\ncomment meshseek inspect: feature points, colour = level\n"
      << "element vertex " << sites.size() << "\nproperty float x\nproperty float y\n"
      << "property float z\nproperty int level\nproperty uchar red\nproperty uchar green\n"
      << "property uchar blue\nend_header\n";
  for (const auto& [p, level] : sites) {
    const cv::Scalar c = LevelColour(level);
    out << std::get<0>(p) << ' ' << std::get<1>(p) << ' ' << std::get<2>(p) << ' ' << level << ' '
        << static_cast<int>(c[2]) << ' ' << static_cast<int>(c[1]) << ' ' << static_cast<int>(c[0])
        << '\n';
  }
  if (!out) return absl::PermissionDeniedError(absl::StrCat(path, ": cannot write"));
  return absl::OkStatus();
}

// Depths to grey, near = light, empty = black.
cv::Mat ShadeDepth(const DepthImage& image) {
  float lo = 1e30f, hi = -1e30f;
  for (float d : image.depth) {
    if (d != DepthImage::kEmpty) lo = std::min(lo, d), hi = std::max(hi, d);
  }
  cv::Mat grey(image.size, image.size, CV_8U, cv::Scalar(0));
  for (int r = 0; r < image.size; ++r) {
    for (int c = 0; c < image.size; ++c) {
      const float d = image.at(r, c);
      if (d == DepthImage::kEmpty) continue;
      grey.at<uint8_t>(r, c) =
          static_cast<uint8_t>(hi > lo ? 235 - 200 * (d - lo) / (hi - lo) : 200);
    }
  }
  return grey;
}

absl::Status WriteOverview(const std::string& path,
                           const TriangleMesh& mesh,
                           const LocalFeatures& features) {
  MESHSEEK_ASSIGN_OR_RETURN(const Sphere sphere, MinimumEnclosingSphere(mesh));
  const PrincipalAxes axes = ComputePrincipalAxes(mesh.vertices);
  const TriangleBvh bvh(mesh);
  DepthImageOptions options;
  options.image_size = 255;
  DepthImageRenderer renderer(mesh, bvh, options);
  const double s = sphere.radius * 1.02;
  const ViewFrame frame{sphere.center, axes.axes[0], axes.axes[2], s};
  DepthImage view;
  renderer.RenderPair(frame, &view, nullptr);
  constexpr int kZoom = 3;
  cv::Mat grey;
  cv::resize(ShadeDepth(view), grey, cv::Size(), kZoom, kZoom, cv::INTER_NEAREST);
  cv::Mat canvas;
  cv::cvtColor(grey, canvas, cv::COLOR_GRAY2BGR);
  const Vec3d right = Cross(frame.up, frame.normal);
  const double to_pixel = options.image_size / (2 * s);
  for (const Keypoint& k : features.keypoints) {
    const Vec3d d = Vec3d(k.position) - frame.point;
    const double col = (Dot(d, right) + s) * to_pixel - 0.5,
                 row = (s - Dot(d, frame.up)) * to_pixel - 0.5;
    const int ci = static_cast<int>(std::lround(col)), ri = static_cast<int>(std::lround(row));
    if (ci < 0 || ri < 0 || ci >= options.image_size || ri >= options.image_size) continue;
    // Visible: not behind the surface the camera sees at that pixel.
    const double depth = s - Dot(d, frame.normal);
    if (view.at(ri, ci) != DepthImage::kEmpty && depth > view.at(ri, ci) + 0.02 * s) continue;
    cv::circle(canvas,
               cv::Point(static_cast<int>(col * kZoom), static_cast<int>(row * kZoom)),
               2,
               LevelColour(k.level),
               cv::FILLED);
  }
  return WritePng(path, canvas);
}

absl::Status WriteMontage(const std::string& path,
                          const TriangleMesh& mesh,
                          const LocalFeatures& features,
                          const DepthImageOptions& options,
                          int count) {
  const TriangleBvh bvh(mesh);
  DepthImageRenderer renderer(mesh, bvh, options);
  const int n = std::min<int>(count, static_cast<int>(features.size()));
  const int columns = 8, rows = (n + columns - 1) / columns, cell = options.image_size * 4 + 4;
  cv::Mat montage(std::max(rows, 1) * cell, columns * cell, CV_8UC3, cv::Scalar(40, 40, 40));
  DepthImage image;
  for (int i = 0; i < n; ++i) {
    // Evenly spaced over the features; each is re-rendered from its keypoint:
    // the front view of (p, up, -view) is exactly the image it was described from.
    const Keypoint& k = features.keypoints[static_cast<std::size_t>(i) * features.size() / n];
    renderer.RenderPair({Vec3d(k.position), Vec3d(k.up), -Vec3d(k.view), k.scale}, &image, nullptr);
    if (!FinishDepthImage(&image)) continue;
    cv::Mat big, colour;
    cv::resize(ShadeDepth(image), big, cv::Size(), 4, 4, cv::INTER_NEAREST);
    cv::cvtColor(big, colour, cv::COLOR_GRAY2BGR);
    cv::rectangle(colour, cv::Rect(0, 0, colour.cols, colour.rows), LevelColour(k.level), 2);
    colour.copyTo(montage(
        cv::Rect((i % columns) * cell + 2, (i / columns) * cell + 2, colour.cols, colour.rows)));
  }
  return WritePng(path, montage);
}

// The whole-model views of bfdsift (depth, with the points sampled in each)
// and lfd (the first light field's silhouettes), side by side.
absl::Status WriteViews(const std::string& path,
                        const TriangleMesh& mesh,
                        const RetrievalPipelineOptions& options,
                        const LocalFeatures& features) {
  const bool lfd = options.extractor.method == FeatureMethod::kLfd;
  ViewRenderOptions render;
  render.image_size = lfd ? options.extractor.lfd.image_size : options.extractor.bfdsift.view_size;
  MESHSEEK_ASSIGN_OR_RETURN(const ViewRenderer renderer, ViewRenderer::Create(mesh, render));
  std::vector<Vec3d> directions;
  if (lfd) {
    for (const Vec3d& d : LightFieldViewDirections()) directions.push_back(d);
  } else {
    directions = IcosphereDirections(options.extractor.bfdsift.view_level);
  }
  const int n = render.image_size, columns = std::min<int>(7, directions.size());
  const int rows = (static_cast<int>(directions.size()) + columns - 1) / columns;
  cv::Mat montage(rows * (n + 4), columns * (n + 4), CV_8UC3, cv::Scalar(255, 255, 255));
  for (std::size_t v = 0; v < directions.size(); ++v) {
    const ViewCamera camera = CameraFor(directions[v]);
    const ViewImage view = renderer.Render(camera);
    cv::Mat image(n, n, CV_8UC3);
    for (int y = 0; y < n; ++y) {
      for (int x = 0; x < n; ++x) {
        const uint8_t g =
            lfd ? (view.Covered(x, y) ? 0 : 255)
                : static_cast<uint8_t>(view.Covered(x, y) ? 40 + 215 * view.DepthAt(x, y) : 0);
        image.at<cv::Vec3b>(y, x) = cv::Vec3b(g, g, g);
      }
    }
    if (!lfd) {
      // The sample points of this view (keypoints carry its direction).
      const Vec3d centre = renderer.sphere().center;
      const double radius = renderer.sphere().radius;
      for (const Keypoint& k : features.keypoints) {
        if (Dot(Vec3d(k.view.x, k.view.y, k.view.z), camera.direction) < 0.9999) continue;
        const Vec3d q = (Vec3d(k.position.x, k.position.y, k.position.z) - centre) / radius;
        const int px = static_cast<int>((Dot(q, camera.right) + 1) / 2 * n);
        const int py = static_cast<int>((1 - Dot(q, camera.up)) / 2 * n);
        cv::circle(image, cv::Point(px, py), 1, cv::Scalar(40, 40, 230), cv::FILLED);
      }
    }
    image.copyTo(montage(cv::Rect(static_cast<int>(v % columns) * (n + 4) + 2,
                                  static_cast<int>(v / columns) * (n + 4) + 2,
                                  n,
                                  n)));
  }
  return WritePng(path, montage);
}

}  // namespace

absl::Status RunInspect(const CliFlags& flags, const std::string& model_path) {
  const std::string& out_dir = flags.out;
  if (out_dir.empty()) return absl::InvalidArgumentError("inspect needs --out DIR");
  MESHSEEK_ASSIGN_OR_RETURN(const RetrievalPipelineOptions options, flags::PipelineOptionsFromFlags(flags.params));
  MeshReadReport report;
  MESHSEEK_ASSIGN_OR_RETURN(const TriangleMesh mesh,
                            ReadMesh(model_path, &report, flags.client.mesh_limits));
  MESHSEEK_ASSIGN_OR_RETURN(const LocalFeatures features,
                            ExtractLocalFeatures(mesh, options.extractor));
  std::error_code ec;
  std::filesystem::create_directories(out_dir, ec);
  if (ec) return absl::PermissionDeniedError(absl::StrCat(out_dir, ": cannot create folder"));
  const FeatureMethod method = options.extractor.method;
  if (method == FeatureMethod::kBfDsift || method == FeatureMethod::kLfd) {
    MESHSEEK_RETURN_IF_ERROR(WriteViews(out_dir + "/views.png", mesh, options, features));
    std::printf("%s: %s\n%s: %zu features (%zu bytes each)\nwrote %s/views.png\n",
                model_path.c_str(),
                report.Summary().c_str(),
                FeatureMethodName(method),
                features.size(),
                features.dimension,
                out_dir.c_str());
    return absl::OkStatus();
  }
  MESHSEEK_RETURN_IF_ERROR(WritePointsPly(out_dir + "/points.ply", features));
  MESHSEEK_RETURN_IF_ERROR(WriteOverview(out_dir + "/points.png", mesh, features));
  MESHSEEK_RETURN_IF_ERROR(WriteMontage(out_dir + "/depth_images.png",
                                        mesh,
                                        features,
                                        options.extractor.dld.depth_image,
                                        flags.montage_images));
  std::map<int, int> per_level;
  for (const Keypoint& k : features.keypoints) per_level[k.level]++;
  std::printf("%s: %s\n%s: %zu local features",
              model_path.c_str(),
              report.Summary().c_str(),
              FeatureMethodName(options.extractor.method),
              features.size());
  for (const auto& [level, count] : per_level) std::printf(", level %d: %d", level, count);
  std::printf("\nwrote %s/points.ply, points.png and depth_images.png\n", out_dir.c_str());
  return absl::OkStatus();
}

}  // namespace meshseek::cli
