// The Light Field Descriptor's model-pair distance on one core.
//
//   lfd_benchmark --models_dir=DIR [--benchmark_filter=...]
//
// BM_LfdDistance/<path> times LfdDistance on the descriptors of the first
// two meshes of DIR (scalar SAD and AVX2 SAD); without --models_dir a
// level-5 icosphere (20,480 triangles) stands in. Per-model extraction is
// extract_benchmark's BM_Extract/lfd (--method lfd --view_size N for
// another silhouette size).
#include <benchmark/benchmark.h>

#include <string>
#include <vector>

#include "absl/flags/flag.h"
#include "absl/flags/parse.h"
#include "bench/bench_models.h"
#include "common/base/cpu_features.h"
#include "common/global/lfd.h"

ABSL_FLAG(std::string, models_dir, "", "folder of meshes to time (recursive)");
ABSL_FLAG(int, max_models, 2, "read at most this many models (the first by path)");

namespace meshseek {
namespace {

const std::vector<TriangleMesh>& Models() {
  static const std::vector<TriangleMesh> meshes =
      LoadBenchModels(absl::GetFlag(FLAGS_models_dir), absl::GetFlag(FLAGS_max_models));
  return meshes;
}

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
