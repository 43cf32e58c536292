// Per-model local-feature extraction time, single-threaded.
//
//   extract_benchmark --models_dir=DIR [--max_models=N] [--scale=E] [--benchmark_...]
//
// Reads up to N meshes (sorted by file name) from DIR, then times extraction
// of each on the calling thread. Reported counters: median and 90th
// percentile milliseconds per model over the set, and the mean vertex count.
// Without --models_dir it times a built-in lumpy sphere (CI smoke use).
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <iostream>
#include <string>
#include <vector>

#include <benchmark/benchmark.h>
#include <opencv2/core.hpp>

#include "common/features/dld_sift.h"
#include "common/geometry/mesh_io.h"
#include "common/geometry/test_meshes.h"

namespace meshseek {
namespace {

struct BenchConfig {
  std::string models_dir;
  int max_models = 20;
  double scale = DldSiftOptions().scale;
};

BenchConfig& Config() {
  static BenchConfig config;
  return config;
}

std::vector<TriangleMesh> LoadModels() {
  std::vector<TriangleMesh> meshes;
  const BenchConfig& config = Config();
  if (config.models_dir.empty()) {
    meshes.push_back(testing_meshes::Icosphere(5));
    return meshes;
  }
  std::vector<std::string> paths;
  for (const auto& entry : std::filesystem::recursive_directory_iterator(config.models_dir)) {
    if (entry.is_regular_file() && MeshFormatFromPath(entry.path().string()).ok()) {
      paths.push_back(entry.path().string());
    }
  }
  std::sort(paths.begin(), paths.end());
  if (static_cast<int>(paths.size()) > config.max_models) paths.resize(config.max_models);
  for (const std::string& path : paths) {
    auto mesh = ReadMesh(path);
    if (!mesh.ok()) {
      std::cerr << mesh.status() << "\n";
      std::exit(1);
    }
    meshes.push_back(*std::move(mesh));
  }
  return meshes;
}

void BM_ExtractDldSift(benchmark::State& state) {
  static const std::vector<TriangleMesh> meshes = LoadModels();
  DldSiftOptions options;
  options.scale = Config().scale;
  std::vector<double> per_model_ms;
  double vertices = 0;
  for (const auto& m : meshes) vertices += m.vertices.size();
  for (auto _ : state) {
    for (const TriangleMesh& mesh : meshes) {
      const auto start = std::chrono::steady_clock::now();
      auto features = ExtractDldSift(mesh, options);
      per_model_ms.push_back(
          std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count());
      benchmark::DoNotOptimize(features);
    }
  }
  std::sort(per_model_ms.begin(), per_model_ms.end());
  state.counters["models"] = static_cast<double>(meshes.size());
  state.counters["mean_vertices"] = vertices / meshes.size();
  state.counters["median_ms_per_model"] = per_model_ms[per_model_ms.size() / 2];
  state.counters["p90_ms_per_model"] = per_model_ms[per_model_ms.size() * 9 / 10];
}
BENCHMARK(BM_ExtractDldSift)->Unit(benchmark::kMillisecond)->Iterations(1);

}  // namespace
}  // namespace meshseek

int main(int argc, char** argv) {
  cv::setNumThreads(0);  // one core: no OpenCV worker threads either
  benchmark::Initialize(&argc, argv);
  for (int i = 1; i < argc; ++i) {
    const std::string arg = argv[i];
    auto value = [&](const std::string& flag) { return arg.substr(flag.size()); };
    if (arg.rfind("--models_dir=", 0) == 0) meshseek::Config().models_dir = value("--models_dir=");
    else if (arg.rfind("--max_models=", 0) == 0) meshseek::Config().max_models = std::atoi(value("--max_models=").c_str());
    else if (arg.rfind("--scale=", 0) == 0) meshseek::Config().scale = std::atof(value("--scale=").c_str());
    else { std::cerr << "unknown flag " << arg << "\n"; return 2; }
  }
  benchmark::RunSpecifiedBenchmarks();
  benchmark::Shutdown();
  return 0;
}
