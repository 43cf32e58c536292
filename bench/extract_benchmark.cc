// Per-model local-feature extraction time on one core, for every method.
//
//   extract_benchmark --models_dir=DIR [--max_models=N] [pipeline flags, e.g. --scale=E]
//                     [--benchmark_filter=...] [--benchmark_format=json]
//
// Reads up to N meshes (sorted by path) from DIR once, then times extraction
// of each on the calling thread. Counters: median and 90th-percentile
// milliseconds per model over the set (wall clock, and the thread's CPU time,
// which other processes on a shared machine disturb less), mean vertices, and
// local features per model; on stderr, a fingerprint of every feature of the
// set (FNV-1a 64 of keypoints and descriptors, model by model), so that a
// change meant to leave features bit-identical can be checked on real meshes. BM_ExtractRldSamples/N times RLD-SIFT at N
// resample points (how its cost grows with N_RLD). Without --models_dir, a
// built-in lumpy sphere is used (a smoke run).
#include <benchmark/benchmark.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdlib>
#include <ctime>
#include <filesystem>
#include <iostream>
#include <string>
#include <vector>

#include "absl/flags/flag.h"
#include "absl/flags/parse.h"
#include "absl/strings/str_cat.h"
#include "bench/bench_models.h"
#include "common/flags/pipeline_flags.h"
#include "common/base/hash.h"
#include "common/features/local_feature_extractor.h"
#include "common/geometry/mesh_io.h"
#include "common/geometry/test_meshes.h"
#include "common/render/thumbnail.h"

ABSL_FLAG(std::string, models_dir, "", "folder of meshes to time (recursive)");
ABSL_FLAG(int, max_models, 20, "time at most this many models (the first by path)");

namespace meshseek {
namespace {

const std::vector<TriangleMesh>& Models() {
  static const std::vector<TriangleMesh> meshes =
      LoadBenchModels(absl::GetFlag(FLAGS_models_dir), absl::GetFlag(FLAGS_max_models));
  return meshes;
}

ExtractorOptions& BaseOptions() {
  static ExtractorOptions options;
  return options;
}

// CPU time of the calling thread, in milliseconds.
double ThreadCpuMs() {
  timespec t;
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &t);
  return t.tv_sec * 1e3 + t.tv_nsec * 1e-6;
}

void TimeExtraction(benchmark::State& state, const ExtractorOptions& options) {
  const std::vector<TriangleMesh>& meshes = Models();
  std::vector<double> per_model_ms, per_model_cpu_ms;
  double vertices = 0, features = 0;
  uint64_t fingerprint = kFnv1a64OffsetBasis;
  for (const auto& m : meshes) vertices += m.vertices.size();
  for (auto _ : state) {
    for (const TriangleMesh& mesh : meshes) {
      const auto start = std::chrono::steady_clock::now();
      const double cpu_start = ThreadCpuMs();
      auto extracted = ExtractLocalFeatures(mesh, options);
      per_model_cpu_ms.push_back(ThreadCpuMs() - cpu_start);
      per_model_ms.push_back(
          std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start)
              .count());
      if (!extracted.ok()) {
        state.SkipWithError(std::string(extracted.status().message()).c_str());
        return;
      }
      features += extracted->size();
      fingerprint = Fnv1a64(
          absl::string_view(reinterpret_cast<const char*>(extracted->keypoints.data()),
                            extracted->keypoints.size() * sizeof(Keypoint)),
          fingerprint);
      fingerprint = Fnv1a64(
          absl::string_view(reinterpret_cast<const char*>(extracted->descriptors.data()),
                            extracted->descriptors.size()),
          fingerprint);
    }
  }
  std::cerr << FeatureMethodInfoOf(options.method).name << " on " << meshes.size()
            << " models: features fingerprint " << std::hex << fingerprint << std::dec
            << "\n";
  std::sort(per_model_ms.begin(), per_model_ms.end());
  std::sort(per_model_cpu_ms.begin(), per_model_cpu_ms.end());
  state.counters["models"] = static_cast<double>(meshes.size());
  state.counters["mean_vertices"] = vertices / meshes.size();
  state.counters["features_per_model"] = features / per_model_ms.size();
  state.counters["median_ms_per_model"] = per_model_ms[per_model_ms.size() / 2];
  state.counters["p90_ms_per_model"] = per_model_ms[per_model_ms.size() * 9 / 10];
  state.counters["median_cpu_ms_per_model"] = per_model_cpu_ms[per_model_cpu_ms.size() / 2];
  state.counters["p90_cpu_ms_per_model"] = per_model_cpu_ms[per_model_cpu_ms.size() * 9 / 10];
}

void BM_Extract(benchmark::State& state, FeatureMethod method) {
  ExtractorOptions options = BaseOptions();
  options.method = method;
  TimeExtraction(state, options);
}
// BM_Extract/<name> for every registered method (FeatureMethods()).
void RegisterMethodBenchmarks() {
  for (const FeatureMethodInfo& info : FeatureMethods()) {
    benchmark::RegisterBenchmark(
        absl::StrCat("BM_Extract/", info.name).c_str(),
        [method = info.method](benchmark::State& state) { BM_Extract(state, method); })
        ->Unit(benchmark::kMillisecond)
        ->Iterations(1);
  }
}

// What ingest adds per model: the coordinator draws each model's thumbnail.
void BM_Thumbnail(benchmark::State& state) {
  const std::vector<TriangleMesh>& meshes = Models();
  std::vector<double> per_model_ms;
  double bytes = 0;
  for (auto _ : state) {
    for (const TriangleMesh& mesh : meshes) {
      const auto start = std::chrono::steady_clock::now();
      auto png = RenderThumbnailPng(mesh);
      per_model_ms.push_back(
          std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start)
              .count());
      if (!png.ok()) {
        state.SkipWithError(std::string(png.status().message()).c_str());
        return;
      }
      bytes += png->size();
    }
  }
  std::sort(per_model_ms.begin(), per_model_ms.end());
  state.counters["models"] = static_cast<double>(meshes.size());
  state.counters["median_ms_per_model"] = per_model_ms[per_model_ms.size() / 2];
  state.counters["p90_ms_per_model"] = per_model_ms[per_model_ms.size() * 9 / 10];
  state.counters["mean_png_bytes"] = bytes / per_model_ms.size();
}
BENCHMARK(BM_Thumbnail)->Unit(benchmark::kMillisecond)->Iterations(1);

void BM_ExtractRldSamples(benchmark::State& state) {
  ExtractorOptions options = BaseOptions();
  options.method = FeatureMethod::kRldSift;
  options.rld.num_samples = static_cast<int>(state.range(0));
  TimeExtraction(state, options);
}
BENCHMARK(BM_ExtractRldSamples)
    ->Arg(2500)
    ->Arg(5000)
    ->Arg(10000)
    ->Arg(15000)
    ->Arg(30000)
    ->Unit(benchmark::kMillisecond)
    ->Iterations(1);

}  // namespace
}  // namespace meshseek

int main(int argc, char** argv) {
  benchmark::Initialize(&argc, argv);
  const meshseek::flags::CommandLine line =
      meshseek::flags::ParseCommandLineWithParams(argc, argv, "");
  auto options = meshseek::flags::PipelineOptionsFromFlags(line.params);
  if (!options.ok()) {
    std::cerr << options.status() << "\n";
    return 2;
  }
  meshseek::BaseOptions() = options->extractor;
  meshseek::RegisterMethodBenchmarks();
  benchmark::RunSpecifiedBenchmarks();
  benchmark::Shutdown();
  return 0;
}
