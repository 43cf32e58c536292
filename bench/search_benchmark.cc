// The index engine in process (KlInvertedIndex, no gRPC): exact Search and
// Search with candidates, top-10, over synthetic histograms shaped like real
// ones (synthetic_histograms.h). The service-level figures (add rate, memory,
// latency through gRPC) are index_benchmark's; this one isolates the engine
// so that two variants can be compared in one run.
//
//   build/bench/search_benchmark --models=100000 --vocabulary=2000 [--threads=2]
#include <benchmark/benchmark.h>

#include <cstdio>
#include <random>
#include <vector>

#include "absl/flags/flag.h"
#include "absl/flags/parse.h"
#include "bench/synthetic_histograms.h"
#include "common/search/kl_inverted_index.h"

ABSL_FLAG(int, models, 100000, "models in the index");
ABSL_FLAG(int, vocabulary, 2000, "vocabulary size V");
ABSL_FLAG(int, descriptors, 3000, "local features per synthetic model");
ABSL_FLAG(int, threads, 0, "search threads (0: all cores)");

namespace meshseek {
namespace {

const KlInvertedIndex& Index() {
  static const KlInvertedIndex index = [] {
    std::mt19937_64 rng(1);
    KlInvertedIndex built = *KlInvertedIndex::Create(absl::GetFlag(FLAGS_vocabulary));
    for (int i = 0; i < absl::GetFlag(FLAGS_models); ++i) {
      const SparseHistogram h = SyntheticHistogram(
          rng, absl::GetFlag(FLAGS_vocabulary), absl::GetFlag(FLAGS_descriptors));
      if (!built.Upsert(static_cast<uint32_t>(i), h).ok()) std::abort();
    }
    std::fprintf(stderr, "index: %zu models, %.0f MB\n", built.size(), built.MemoryBytes() / 1e6);
    return built;
  }();
  return index;
}

void BM_Search(benchmark::State& state) {
  const KlInvertedIndex& index = Index();
  std::mt19937_64 rng(2);
  std::vector<SparseHistogram> queries;
  for (int i = 0; i < 64; ++i) {
    queries.push_back(SyntheticHistogram(
        rng, absl::GetFlag(FLAGS_vocabulary), absl::GetFlag(FLAGS_descriptors)));
  }
  std::size_t q = 0;
  for (auto _ : state) {
    auto found = index.Search(queries[q++ % queries.size()], 10, absl::GetFlag(FLAGS_threads),
                              static_cast<std::size_t>(state.range(0)));
    benchmark::DoNotOptimize(found);
  }
}
// 0: exact; otherwise that many candidates re-ranked.
BENCHMARK(BM_Search)->Arg(0)->Arg(1000)->Arg(2000)->Arg(5000)->Unit(benchmark::kMillisecond)->UseRealTime();

}  // namespace
}  // namespace meshseek

int main(int argc, char** argv) {
  benchmark::Initialize(&argc, argv);
  absl::ParseCommandLine(argc, argv);
  benchmark::RunSpecifiedBenchmarks();
  return 0;
}
