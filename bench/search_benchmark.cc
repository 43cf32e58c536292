// The index engine in process (KlInvertedIndex, no gRPC): exact Search and
// Search with candidates, top-10, and a fused query member's distances
// (every model, or a union of candidates), over synthetic histograms shaped like real
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
#include "common/search/synthetic_histograms.h"
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

std::vector<SparseHistogram> Queries() {
  std::mt19937_64 rng(2);
  std::vector<SparseHistogram> queries;
  for (int i = 0; i < 64; ++i) {
    queries.push_back(SyntheticHistogram(
        rng, absl::GetFlag(FLAGS_vocabulary), absl::GetFlag(FLAGS_descriptors)));
  }
  return queries;
}

void BM_Search(benchmark::State& state) {
  const KlInvertedIndex& index = Index();
  const std::vector<SparseHistogram> queries = Queries();
  std::size_t q = 0;
  for (auto _ : state) {
    auto found = index.Search(queries[q++ % queries.size()], 10, absl::GetFlag(FLAGS_threads),
                              static_cast<std::size_t>(state.range(0)));
    benchmark::DoNotOptimize(found);
  }
}
// 0: exact; otherwise that many candidates re-ranked.
BENCHMARK(BM_Search)->Arg(0)->Arg(1000)->Arg(2000)->Arg(5000)->Unit(benchmark::kMillisecond)->UseRealTime();

// What one member of a fused query computes: its distance to every model
// (exact, arg 0), or to a union of that many candidates (DistancesTo, the
// second round of fused candidates), spread over the collection.
void BM_FusedMemberDistances(benchmark::State& state) {
  const KlInvertedIndex& index = Index();
  const std::vector<SparseHistogram> queries = Queries();
  const std::size_t asked = static_cast<std::size_t>(state.range(0));
  std::mt19937_64 rng(3);
  std::vector<uint32_t> docs(asked);
  for (uint32_t& d : docs) d = static_cast<uint32_t>(rng() % index.size());
  std::size_t q = 0;
  for (auto _ : state) {
    const SparseHistogram& query = queries[q++ % queries.size()];
    auto distances = asked == 0 ? index.Distances(query, absl::GetFlag(FLAGS_threads))
                                : index.DistancesTo(query, docs, absl::GetFlag(FLAGS_threads));
    benchmark::DoNotOptimize(distances);
  }
}
BENCHMARK(BM_FusedMemberDistances)->Arg(0)->Arg(400)->Arg(800)->Arg(1600)->Unit(benchmark::kMillisecond)->UseRealTime();

}  // namespace
}  // namespace meshseek

int main(int argc, char** argv) {
  benchmark::Initialize(&argc, argv);
  absl::ParseCommandLine(argc, argv);
  benchmark::RunSpecifiedBenchmarks();
  return 0;
}
