// LSF on a labelled collection under the paper's protocol (docs/design.md 3.3):
// extract every model (in parallel over models), learn a codebook per
// vocabulary size from the collection's own features, encode, rank by
// symmetric KL and print NN / FT / ST / E / DCG, with each model's extraction
// time on one core (thread CPU time). The LSF options are flags so that the
// sweep in bench/results/lsf.txt is one command per variant.
//
//   lsf_eval --manifest FILE [--vocabularies 1000,2000] [--scale 0.3] ...
#include <time.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cstdio>
#include <numeric>
#include <string>
#include <thread>
#include <vector>

#include "absl/flags/flag.h"
#include "absl/flags/parse.h"
#include "absl/strings/numbers.h"
#include "absl/strings/str_join.h"
#include "absl/strings/str_split.h"
#include "common/eval/retrieval_metrics.h"
#include "common/features/lsf.h"
#include "common/geometry/mesh_io.h"
#include "common/pipeline/retrieval_pipeline.h"

ABSL_FLAG(std::string, manifest, "", "CSV manifest id,class,path");
ABSL_FLAG(std::string, vocabularies, "2000", "comma-separated vocabulary sizes V to evaluate");
ABSL_FLAG(int, threads, 2, "threads (extraction runs one model per thread)");
ABSL_FLAG(uint64_t, seed, 0, "k-means seed");
ABSL_FLAG(int, num_points, meshseek::LsfOptions().num_points, "feature centres per model");
ABSL_FLAG(double, scale, meshseek::LsfOptions().scale, "support radius / enclosing-sphere radius");
ABSL_FLAG(std::string,
          extra_scales,
          absl::StrJoin(meshseek::LsfOptions().extra_scales, ","),
          "comma-separated further support radii / R; replaces the default list (empty: none)");
ABSL_FLAG(int,
          samples_per_support,
          meshseek::LsfOptions().samples_per_support,
          "oriented samples in a flat disc of radius s");
ABSL_FLAG(int, min_samples, meshseek::LsfOptions().min_samples, "lower bound on samples");
ABSL_FLAG(int, max_samples, meshseek::LsfOptions().max_samples, "upper bound on samples");
ABSL_FLAG(int,
          min_support_samples,
          meshseek::LsfOptions().min_support_samples,
          "fewer support samples: no feature");
ABSL_FLAG(int,
          max_support_samples,
          meshseek::LsfOptions().max_support_samples,
          "support samples entering the relations at most");
ABSL_FLAG(std::string, relations, "default", "pairs, centre or both");
ABSL_FLAG(std::string, layout, "default", "concatenated, distance_joint or full_joint");
ABSL_FLAG(int, distance_bins, meshseek::LsfOptions().distance_bins, "bins over distance");
ABSL_FLAG(int, angle_bins, meshseek::LsfOptions().angle_bins, "bins over each angle");
ABSL_FLAG(bool,
          soft_binning,
          meshseek::LsfOptions().soft_binning,
          "linear interpolation between bins");
ABSL_FLAG(bool,
          pca_centre_normal,
          meshseek::LsfOptions().pca_centre_normal,
          "centre normal from the support's weighted PCA");
ABSL_FLAG(bool, root, meshseek::LsfOptions().root, "square-root (Hellinger) normalisation");

namespace meshseek {
namespace {

double ThreadCpuSeconds() {
  timespec t;
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &t);
  return t.tv_sec + 1e-9 * t.tv_nsec;
}

double Since(std::chrono::steady_clock::time_point start) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

absl::StatusOr<LsfOptions> OptionsFromFlags() {
  LsfOptions o;
  o.num_points = absl::GetFlag(FLAGS_num_points);
  o.scale = absl::GetFlag(FLAGS_scale);
  o.samples_per_support = absl::GetFlag(FLAGS_samples_per_support);
  o.min_samples = absl::GetFlag(FLAGS_min_samples);
  o.max_samples = absl::GetFlag(FLAGS_max_samples);
  o.min_support_samples = absl::GetFlag(FLAGS_min_support_samples);
  o.max_support_samples = absl::GetFlag(FLAGS_max_support_samples);
  o.distance_bins = absl::GetFlag(FLAGS_distance_bins);
  o.angle_bins = absl::GetFlag(FLAGS_angle_bins);
  o.root = absl::GetFlag(FLAGS_root);
  o.soft_binning = absl::GetFlag(FLAGS_soft_binning);
  o.extra_scales.clear();
  for (absl::string_view part :
       absl::StrSplit(absl::GetFlag(FLAGS_extra_scales), ',', absl::SkipEmpty())) {
    double v = 0;
    if (!absl::SimpleAtod(part, &v)) return absl::InvalidArgumentError("bad --extra_scales");
    o.extra_scales.push_back(v);
  }
  o.pca_centre_normal = absl::GetFlag(FLAGS_pca_centre_normal);
  const std::string relations = absl::GetFlag(FLAGS_relations);
  if (relations == "pairs") {
    o.relations = LsfOptions::Relations::kPairs;
  } else if (relations == "centre") {
    o.relations = LsfOptions::Relations::kCentre;
  } else if (relations == "both") {
    o.relations = LsfOptions::Relations::kBoth;
  } else if (relations != "default") {
    return absl::InvalidArgumentError("--relations must be pairs, centre or both, got " +
                                      relations);
  }
  const std::string layout = absl::GetFlag(FLAGS_layout);
  if (layout == "concatenated") {
    o.layout = LsfOptions::Layout::kConcatenated;
  } else if (layout == "distance_joint") {
    o.layout = LsfOptions::Layout::kDistanceJoint;
  } else if (layout == "full_joint") {
    o.layout = LsfOptions::Layout::kFullJoint;
  } else if (layout != "default") {
    return absl::InvalidArgumentError("--layout: unknown " + layout);
  }
  if (absl::Status status = o.Validate(); !status.ok()) return status;
  return o;
}

double Median(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  return v.empty() ? 0 : v[v.size() / 2];
}

int Run() {
  auto models = ReadManifest(absl::GetFlag(FLAGS_manifest));
  auto options = OptionsFromFlags();
  if (!models.ok() || !options.ok()) {
    std::fprintf(
        stderr, "%s %s\n", models.status().ToString().c_str(), options.status().ToString().c_str());
    return 2;
  }
  std::vector<int> vocabularies;
  for (absl::string_view part : absl::StrSplit(absl::GetFlag(FLAGS_vocabularies), ',')) {
    int v = 0;
    if (!absl::SimpleAtoi(part, &v) || v < 1) {
      std::fprintf(stderr, "bad --vocabularies entry '%s'\n", std::string(part).c_str());
      return 2;
    }
    vocabularies.push_back(v);
  }
  const std::size_t n = models->size();
  const int threads = std::max(1, absl::GetFlag(FLAGS_threads));

  // Read first so that the extraction times are extraction only.
  std::vector<TriangleMesh> meshes(n);
  for (std::size_t i = 0; i < n; ++i) {
    auto mesh = ReadMesh((*models)[i].path);
    if (!mesh.ok()) {
      std::fprintf(
          stderr, "model %s: %s\n", (*models)[i].id.c_str(), mesh.status().ToString().c_str());
      return 1;
    }
    meshes[i] = *std::move(mesh);
  }

  std::vector<LocalFeatures> features(n);
  std::vector<absl::Status> errors(n);
  std::vector<double> cpu_seconds(n);
  std::atomic<std::size_t> next{0};
  auto start = std::chrono::steady_clock::now();
  std::vector<std::thread> pool;
  for (int t = 0; t < threads; ++t) {
    pool.emplace_back([&] {
      for (std::size_t i; (i = next++) < n;) {
        const double before = ThreadCpuSeconds();
        auto extracted = ExtractLsf(meshes[i], *options);
        cpu_seconds[i] = ThreadCpuSeconds() - before;
        if (extracted.ok()) {
          features[i] = *std::move(extracted);
        } else {
          errors[i] = extracted.status();
        }
      }
    });
  }
  for (auto& thread : pool) thread.join();
  const double extract_wall = Since(start);
  std::size_t total_features = 0;
  for (std::size_t i = 0; i < n; ++i) {
    if (!errors[i].ok()) {
      std::fprintf(stderr,
                   "model %s (%s): %s\n",
                   (*models)[i].id.c_str(),
                   (*models)[i].path.c_str(),
                   errors[i].ToString().c_str());
      return 1;
    }
    total_features += features[i].size();
  }
  const std::size_t slowest =
      std::max_element(cpu_seconds.begin(), cpu_seconds.end()) - cpu_seconds.begin();
  std::printf(
      "%s: %zu models, dim %zu, %.0f features per model; extraction per model on one "
      "core: median %.3f s, mean %.3f s, max %.3f s (%s); wall %.1f s on %d threads\n",
      absl::GetFlag(FLAGS_manifest).c_str(),
      n,
      options->Dimension(),
      static_cast<double>(total_features) / n,
      Median(cpu_seconds),
      std::accumulate(cpu_seconds.begin(), cpu_seconds.end(), 0.0) / n,
      cpu_seconds[slowest],
      (*models)[slowest].id.c_str(),
      extract_wall,
      threads);

  std::vector<std::string> labels;
  for (const auto& m : *models) labels.push_back(m.label);
  for (int v : vocabularies) {
    RetrievalPipelineOptions pipeline;
    pipeline.kmeans.num_centroids = v;
    pipeline.kmeans.seed = absl::GetFlag(FLAGS_seed);
    pipeline.num_threads = threads;
    start = std::chrono::steady_clock::now();
    auto codebook = TrainCollectionCodebook(features, pipeline);
    if (!codebook.ok()) {
      std::fprintf(stderr, "V = %d: %s\n", v, codebook.status().ToString().c_str());
      return 1;
    }
    const double codebook_s = Since(start);
    auto histograms = EncodeCollection(*codebook, features, pipeline);
    if (!histograms.ok()) return 1;
    auto distances = RankCollection(*histograms, pipeline);
    if (!distances.ok()) return 1;
    auto metrics = EvaluateRetrieval(labels, *distances, threads);
    if (!metrics.ok()) {
      std::fprintf(stderr, "%s\n", metrics.status().ToString().c_str());
      return 1;
    }
    const RetrievalScores& m = metrics->micro;
    std::printf(
        "  V %5d  NN %.1f  FT %.1f  ST %.1f  E %.1f  DCG %.1f  (macro FT %.1f)  "
        "codebook %.1f s, all %.1f s\n",
        v,
        100 * m.nn,
        100 * m.first_tier,
        100 * m.second_tier,
        100 * m.e_measure,
        100 * m.dcg,
        100 * metrics->macro.first_tier,
        codebook_s,
        Since(start));
    std::fflush(stdout);
  }
  return 0;
}

}  // namespace
}  // namespace meshseek

int main(int argc, char** argv) {
  absl::ParseCommandLine(argc, argv);
  return meshseek::Run();
}
