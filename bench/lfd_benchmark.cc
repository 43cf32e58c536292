// Light Field Descriptor costs on one core: per-model extraction and one
// model-pair distance.
//
//   lfd_benchmark --models_dir=DIR [--max_models=N] [--benchmark_filter=...]
//
// BM_ExtractLfd/I extracts each of the first N meshes of DIR (sorted by
// path; McGill's are about 15,000 vertices and 30,000 triangles) at image
// size I; counters: median and 90th-percentile wall and thread-CPU
// milliseconds per model. BM_LfdDistance/<path> times LfdDistance on two
// real descriptors (scalar SAD and AVX2 SAD). Without --models_dir a
// level-5 icosphere (20,480 triangles) stands in.
#include <benchmark/benchmark.h>

#include <algorithm>
#include <chrono>
#include <cstdlib>
#include <ctime>
#include <filesystem>
#include <iostream>
#include <string>
#include <vector>

#include "absl/flags/flag.h"
#include "absl/flags/parse.h"
#include "common/base/cpu_features.h"
#include "common/geometry/icosphere.h"
#include "bench/bench_models.h"
#include "common/geometry/mesh_io.h"
#include "common/global/lfd.h"

ABSL_FLAG(std::string, models_dir, "", "folder of meshes to time (recursive)");
ABSL_FLAG(int, max_models, 10, "time at most this many models (the first by path)");

namespace meshseek {
namespace {

const std::vector<TriangleMesh>& Models() {
  static const std::vector<TriangleMesh> meshes =
      LoadBenchModels(absl::GetFlag(FLAGS_models_dir), absl::GetFlag(FLAGS_max_models));
  return meshes;
}

double ThreadCpuMs() {
  timespec t;
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &t);
  return t.tv_sec * 1e3 + t.tv_nsec * 1e-6;
}

void BM_ExtractLfd(benchmark::State& state) {
  LfdOptions options;
  options.image_size = static_cast<int>(state.range(0));
  const std::vector<TriangleMesh>& meshes = Models();
  std::vector<double> wall, cpu;
  double triangles = 0;
  for (const TriangleMesh& m : meshes) triangles += m.triangles.size();
  for (auto _ : state) {
    for (const TriangleMesh& mesh : meshes) {
      const auto start = std::chrono::steady_clock::now();
      const double cpu_start = ThreadCpuMs();
      auto d = ExtractLfd(mesh, options);
      cpu.push_back(ThreadCpuMs() - cpu_start);
      wall.push_back(
          std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start)
              .count());
      if (!d.ok()) {
        state.SkipWithError(std::string(d.status().message()).c_str());
        return;
      }
      benchmark::DoNotOptimize(d->data());
    }
  }
  std::sort(wall.begin(), wall.end());
  std::sort(cpu.begin(), cpu.end());
  state.counters["models"] = static_cast<double>(meshes.size());
  state.counters["mean_triangles"] = triangles / meshes.size();
  state.counters["median_ms_per_model"] = wall[wall.size() / 2];
  state.counters["p90_ms_per_model"] = wall[wall.size() * 9 / 10];
  state.counters["median_cpu_ms_per_model"] = cpu[cpu.size() / 2];
}
BENCHMARK(BM_ExtractLfd)->Arg(128)->Arg(256)->Unit(benchmark::kMillisecond)->Iterations(1);

const std::vector<std::vector<uint8_t>>& PairDescriptors() {
  static const std::vector<std::vector<uint8_t>> d = [] {
    const std::vector<TriangleMesh>& meshes = Models();
    std::vector<std::vector<uint8_t>> out;
    out.push_back(*ExtractLfd(meshes[0], LfdOptions()));
    out.push_back(*ExtractLfd(meshes[meshes.size() > 1 ? 1 : 0], LfdOptions()));
    return out;
  }();
  return d;
}

void BM_LfdDistance(benchmark::State& state, SimdLevel level) {
  const auto& d = PairDescriptors();
  state.SetLabel(SimdLevelName(static_cast<int>(level) <= static_cast<int>(DetectedSimdLevel())
                                   ? level
                                   : DetectedSimdLevel()));
  for (auto _ : state) {
    benchmark::DoNotOptimize(internal::LfdDistanceAtLevel(d[0].data(), d[1].data(), level));
  }
}
BENCHMARK_CAPTURE(BM_LfdDistance, scalar, SimdLevel::kSse2)->Unit(benchmark::kMicrosecond);
BENCHMARK_CAPTURE(BM_LfdDistance, avx2, SimdLevel::kAvx2)->Unit(benchmark::kMicrosecond);

}  // namespace
}  // namespace meshseek

int main(int argc, char** argv) {
  benchmark::Initialize(&argc, argv);
  absl::ParseCommandLine(argc, argv);
  benchmark::RunSpecifiedBenchmarks();
  benchmark::Shutdown();
  return 0;
}
