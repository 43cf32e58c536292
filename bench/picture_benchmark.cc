// Query by picture on a labelled set (docs/design.md 2.7d; docs/results.md,
// "Query by picture"): how often a picture of a model finds models of its
// class, and what one query costs.
//
//   picture_benchmark --manifest FILE [--views 3] [--seed 1] [--picture_size 256]
//                     [--scale_to 10000] [--threads 2] [--write_pictures DIR]
//
// Every model's LFD descriptor is extracted, as a collection with lfd stores
// it. Each model is then drawn from --views seeded random directions (uniform
// on the sphere, so not LFD's own dodecahedron views) and each view becomes
// three pictures, black on white, PNG:
//   filled    the silhouette;
//   outline   its contours only, 2 or 3 pixels wide (a line drawing);
//   jittered  the silhouette with its outer contour displaced by smooth
//             noise of 3 pixels (a hand's tracing), holes lost.
// Each picture is queried as the coordinator queries (DecodePicture,
// PictureSilhouette, DescribeLfdSilhouette, LfdViewDistance to every model)
// against the collection without the pictured model: nearest neighbour,
// first tier and DCG per kind, the mean over views. The time per query is
// the median of its whole path, decoding to ranking, with the collection as
// it is and with its descriptors repeated to --scale_to models.
// --write_pictures DIR also writes each model's first filled picture as
// DIR/<id>.png (queries for bench/query_by_mesh.sh's picture mode).
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <opencv2/imgproc.hpp>
#include <random>
#include <string>
#include <vector>

#include "absl/flags/flag.h"
#include "absl/flags/parse.h"
#include "common/base/parallel.h"
#include "common/eval/manifest.h"
#include "common/eval/retrieval_metrics.h"
#include "common/geometry/mesh_io.h"
#include "common/global/lfd.h"
#include "common/global/picture_silhouette.h"
#include "common/render/png.h"
#include "common/render/view_renderer.h"

ABSL_FLAG(std::string, manifest, "", "CSV manifest id,class,path (research data: bench only)");
ABSL_FLAG(int, views, 3, "random views drawn per model");
ABSL_FLAG(uint64_t, seed, 1, "seed of the views and the jitter");
ABSL_FLAG(int, picture_size, 256, "side of the pictures in pixels");
ABSL_FLAG(int, scale_to, 10000, "also time queries against the descriptors repeated to this many");
ABSL_FLAG(int, threads, 2, "threads for extraction and queries");
ABSL_FLAG(std::string, write_pictures, "", "write each model's first filled picture here");

namespace meshseek {
namespace {

enum Kind { kFilled, kOutline, kJittered, kKinds };
constexpr const char* kKindNames[kKinds] = {"filled", "outline", "jittered"};

double Seconds(std::chrono::steady_clock::time_point start) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

Vec3d RandomDirection(std::mt19937_64& rng) {
  std::normal_distribution<double> normal;
  for (;;) {
    const Vec3d v(normal(rng), normal(rng), normal(rng));
    const double length = std::sqrt(Dot(v, v));
    if (length > 1e-6) return v * (1 / length);
  }
}

// The three pictures of one view's silhouette (255 background, 0 object).
std::vector<cv::Mat> Pictures(const ViewImage& view, std::mt19937_64& rng) {
  const cv::Mat mask(view.size, view.size, CV_8UC1, const_cast<uint8_t*>(view.mask.data()));
  std::vector<cv::Mat> out(kKinds);
  out[kFilled] = cv::Mat(view.size, view.size, CV_8UC1, cv::Scalar(255));
  out[kFilled].setTo(0, mask);

  std::vector<std::vector<cv::Point>> contours;
  cv::findContours(mask.clone(), contours, cv::RETR_LIST, cv::CHAIN_APPROX_NONE);
  out[kOutline] = cv::Mat(view.size, view.size, CV_8UC1, cv::Scalar(255));
  const int width = std::uniform_int_distribution<int>(2, 3)(rng);
  cv::drawContours(out[kOutline], contours, -1, cv::Scalar(0), width);

  std::vector<std::vector<cv::Point>> outer;
  cv::findContours(mask.clone(), outer, cv::RETR_EXTERNAL, cv::CHAIN_APPROX_NONE);
  std::normal_distribution<double> noise(0, 3.0);
  for (std::vector<cv::Point>& contour : outer) {
    // Noise every 8 points, linearly interpolated between: smooth wobbles.
    const std::size_t n = contour.size(), knots = n / 8 + 2;
    std::vector<cv::Point2d> offset(knots);
    for (cv::Point2d& o : offset) o = {noise(rng), noise(rng)};
    for (std::size_t i = 0; i < n; ++i) {
      const double t = i / 8.0, f = t - std::floor(t);
      const std::size_t k = static_cast<std::size_t>(t);
      const cv::Point2d d = offset[k] * (1 - f) + offset[k + 1] * f;
      contour[i] += cv::Point(static_cast<int>(std::lround(d.x)), static_cast<int>(std::lround(d.y)));
    }
  }
  out[kJittered] = cv::Mat(view.size, view.size, CV_8UC1, cv::Scalar(255));
  cv::fillPoly(out[kJittered], outer, cv::Scalar(0));
  return out;
}

// A picture's view block, as the coordinator computes it from the file.
std::array<uint8_t, kLfdViewStride> Describe(const std::string& png, const LfdOptions& lfd) {
  const cv::Mat picture = *DecodePicture(png);
  PictureSilhouetteOptions options;
  options.image_size = lfd.image_size;
  const std::vector<uint8_t> silhouette = *PictureSilhouette(picture, options);
  return *DescribeLfdSilhouette({silhouette.data(), lfd.image_size, lfd.image_size}, lfd);
}

int Run() {
  const auto entries = ReadManifest(absl::GetFlag(FLAGS_manifest));
  if (!entries.ok()) {
    std::fprintf(stderr, "%s\n", entries.status().ToString().c_str());
    return 1;
  }
  const std::size_t n = entries->size();
  const int views = absl::GetFlag(FLAGS_views), threads = absl::GetFlag(FLAGS_threads);
  const LfdOptions lfd;
  ViewRenderOptions render;
  render.image_size = absl::GetFlag(FLAGS_picture_size);
  render.window_scale = 1.2;

  // Descriptors and pictures (PNG bytes), per model, view and kind.
  std::vector<std::vector<uint8_t>> descriptors(n);
  std::vector<std::string> pictures(n * views * kKinds);
  std::vector<std::string> labels(n);
  auto start = std::chrono::steady_clock::now();
  ParallelFor(n, threads, [&](std::size_t m) {
    const ManifestEntry& e = (*entries)[m];
    labels[m] = e.label;
    const TriangleMesh mesh = *ReadMesh(e.path);
    descriptors[m] = *ExtractLfd(mesh, lfd);
    const ViewRenderer renderer = *ViewRenderer::Create(mesh, render);
    std::mt19937_64 rng(absl::GetFlag(FLAGS_seed) * 1000003 + m);
    for (int v = 0; v < views; ++v) {
      const std::vector<cv::Mat> kinds = Pictures(renderer.Render(RandomDirection(rng)), rng);
      for (int k = 0; k < kKinds; ++k) pictures[(m * views + v) * kKinds + k] = *EncodePng(kinds[k]);
    }
  });
  std::printf("%zu models: descriptors and %zu pictures in %.1f s\n", n, pictures.size(),
              Seconds(start));
  if (const std::string dir = absl::GetFlag(FLAGS_write_pictures); !dir.empty()) {
    std::filesystem::create_directories(dir);
    for (std::size_t m = 0; m < n; ++m) {
      std::ofstream(dir + "/" + (*entries)[m].id + ".png", std::ios::binary)
          << pictures[m * views * kKinds + kFilled];
    }
  }

  // Per kind and view, an N x N matrix: row q is q's picture against every
  // model (its own entry, the diagonal, is ignored by the evaluation).
  std::printf("kind       NN      FT      DCG   (percent, mean over %d views)\n", views);
  for (int k = 0; k < kKinds; ++k) {
    RetrievalScores sum;
    for (int v = 0; v < views; ++v) {
      std::vector<float> distances(n * n);
      ParallelFor(n, threads, [&](std::size_t q) {
        const auto block = Describe(pictures[(q * views + v) * kKinds + k], lfd);
        for (std::size_t j = 0; j < n; ++j) {
          distances[q * n + j] = LfdViewDistance(block.data(), descriptors[j].data());
        }
      });
      const RetrievalMetrics metrics = *EvaluateRetrieval(labels, distances, threads);
      sum.nn += metrics.micro.nn / views;
      sum.first_tier += metrics.micro.first_tier / views;
      sum.dcg += metrics.micro.dcg / views;
    }
    std::printf("%-8s %6.2f  %6.2f  %6.2f\n", kKindNames[k], 100 * sum.nn, 100 * sum.first_tier,
                100 * sum.dcg);
  }

  // One query's whole path, one thread, at N and at scale_to models.
  for (const std::size_t models : {n, static_cast<std::size_t>(absl::GetFlag(FLAGS_scale_to))}) {
    std::vector<double> times;
    for (std::size_t q = 0; q < std::min<std::size_t>(n, 50); ++q) {
      const auto t = std::chrono::steady_clock::now();
      const auto block = Describe(pictures[q * views * kKinds], lfd);
      std::vector<std::pair<float, uint32_t>> ranked(models);
      for (std::size_t j = 0; j < models; ++j) {
        ranked[j] = {LfdViewDistance(block.data(), descriptors[j % n].data()),
                     static_cast<uint32_t>(j)};
      }
      std::partial_sort(ranked.begin(), ranked.begin() + std::min<std::size_t>(10, models),
                        ranked.end());
      times.push_back(Seconds(t));
    }
    std::sort(times.begin(), times.end());
    std::printf("query at %zu models: median %.1f ms (decode, silhouette, describe, scan, top 10)\n",
                models, 1000 * times[times.size() / 2]);
  }
  return 0;
}

}  // namespace
}  // namespace meshseek

int main(int argc, char** argv) {
  absl::ParseCommandLine(argc, argv);
  return meshseek::Run();
}
