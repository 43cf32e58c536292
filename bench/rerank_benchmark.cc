// The cost of k-reciprocal re-ranking (common/search/rerank.h) at the
// shipped defaults (k1 20, k2 4, lambda 0.1, depth 200), on synthetic
// collections shaped like a benchmark's: models in classes of --class_size,
// each model a point near its class centre in R^8, Euclidean distances
// divided by their mean (as fusion.h rescales every method).
//
//   BM_RerankQuery/N      one query from outside the collection joining the
//                         graph of N models (the services' Query): its row of
//                         N distances is given, the time is the re-ranking.
//   BM_RerankMatrix/N     every row of an N x N matrix (eval), graph included.
//
//   build/bench/rerank_benchmark [--class_size=20] [--benchmark_filter=...]
//
// The graph of the 100,000-model collection is built once (a few seconds)
// from rows that are finite only within the model's class (the classes lie
// far apart: its nearest k1 + 1 are there); its memory is printed.
#include <benchmark/benchmark.h>

#include <cmath>
#include <cstdio>
#include <limits>
#include <map>
#include <random>
#include <vector>

#include "absl/flags/flag.h"
#include "absl/flags/parse.h"
#include "common/search/neighbor_graph.h"
#include "common/search/rerank.h"

ABSL_FLAG(int, class_size, 20, "models per class of the synthetic collection");

namespace meshseek {
namespace {

constexpr int kDim = 8;

struct Collection {
  std::vector<float> points;  // n x kDim
  double scale = 1.0;         // mean distance between models
  std::size_t size() const { return points.size() / kDim; }
  std::vector<float> Row(const float* q) const {
    std::vector<float> row(size());
    for (std::size_t j = 0; j < size(); ++j) {
      double s = 0;
      for (int d = 0; d < kDim; ++d) {
        const double x = q[d] - points[j * kDim + d];
        s += x * x;
      }
      row[j] = static_cast<float>(std::sqrt(s) / scale);
    }
    return row;
  }
};

Collection MakeCollection(std::size_t n, uint64_t seed) {
  const int class_size = absl::GetFlag(FLAGS_class_size);
  std::mt19937_64 rng(seed);
  std::normal_distribution<float> centre(0.0f, 10.0f), noise(0.0f, 1.0f);
  Collection c;
  c.points.resize(n * kDim);
  std::vector<float> at(kDim);
  for (std::size_t i = 0; i < n; ++i) {
    if (i % class_size == 0) {
      for (float& x : at) x = centre(rng);
    }
    for (int d = 0; d < kDim; ++d) c.points[i * kDim + d] = at[d] + noise(rng);
  }
  // The mean distance, from the first 500 models' rows.
  double sum = 0;
  std::size_t count = 0;
  for (std::size_t i = 0; i < std::min<std::size_t>(n, 500); ++i) {
    for (float x : c.Row(&c.points[i * kDim])) sum += x, ++count;
  }
  c.scale = sum / count;
  return c;
}

// The graph; rows finite within the model's class only when `local`.
NeighborGraph Graph(const Collection& c, int k, bool local) {
  const std::size_t n = c.size();
  const int class_size = absl::GetFlag(FLAGS_class_size);
  NeighborGraph graph = *NeighborGraph::Create(n, k);
  std::vector<float> row(n, std::numeric_limits<float>::infinity());
  for (std::size_t i = 0; i < n; ++i) {
    if (local) {
      const std::size_t first = i / class_size * class_size;
      const std::size_t last = std::min(n, first + class_size);
      std::fill(row.begin(), row.end(), std::numeric_limits<float>::infinity());
      for (std::size_t j = first; j < last; ++j) {
        double s = 0;
        for (int d = 0; d < kDim; ++d) {
          const double x = c.points[i * kDim + d] - c.points[j * kDim + d];
          s += x * x;
        }
        row[j] = static_cast<float>(std::sqrt(s) / c.scale);
      }
    } else {
      row = c.Row(&c.points[i * kDim]);
    }
    graph.SetRow(static_cast<uint32_t>(i), row);
  }
  return graph;
}

void BM_RerankQuery(benchmark::State& state) {
  const std::size_t n = static_cast<std::size_t>(state.range(0));
  static std::map<std::size_t, std::pair<Collection, NeighborGraph>> built;
  const RerankOptions options;
  if (!built.count(n)) {
    Collection c = MakeCollection(n, 7);
    NeighborGraph g = Graph(c, options.graph_k(), n > 20000);
    std::fprintf(stderr,
                 "graph of %zu models, lists of %d: %.1f MB\n",
                 n,
                 g.k(),
                 n * g.k() * sizeof(GraphNeighbor) / 1e6);
    built.emplace(n, std::make_pair(std::move(c), std::move(g)));
  }
  const auto& [collection, graph] = built.at(n);
  // A query near model 123's class centre, not a model of the collection.
  std::vector<float> q(collection.points.begin() + 123 * kDim,
                       collection.points.begin() + 124 * kDim);
  for (float& x : q) x += 0.25f;
  const std::vector<float> row = collection.Row(q.data());
  for (auto _ : state) {
    auto ranked = RerankRow(graph, row, std::nullopt, options);
    if (!ranked.ok()) state.SkipWithError(std::string(ranked.status().message()).c_str());
    benchmark::DoNotOptimize(ranked);
  }
}
BENCHMARK(BM_RerankQuery)->Arg(1000)->Arg(10000)->Arg(100000)->Unit(benchmark::kMillisecond);

void BM_RerankMatrix(benchmark::State& state) {
  const std::size_t n = static_cast<std::size_t>(state.range(0));
  const Collection c = MakeCollection(n, 11);
  std::vector<float> matrix;
  for (std::size_t i = 0; i < n; ++i) {
    const std::vector<float> row = c.Row(&c.points[i * kDim]);
    matrix.insert(matrix.end(), row.begin(), row.end());
  }
  const RerankOptions options;
  for (auto _ : state) {
    auto graph = NeighborGraph::FromMatrix(matrix, n, options.graph_k(), 1);
    auto ranked = RerankMatrix(*graph, matrix, options, 1);
    benchmark::DoNotOptimize(ranked);
  }
}
// 907: PSB train; 1,814 and 3,628: twice and four times (quadratic).
BENCHMARK(BM_RerankMatrix)->Arg(907)->Arg(1814)->Arg(3628)->Unit(benchmark::kMillisecond);

}  // namespace
}  // namespace meshseek

int main(int argc, char** argv) {
  benchmark::Initialize(&argc, argv);
  absl::ParseCommandLine(argc, argv);
  benchmark::RunSpecifiedBenchmarks();
  return 0;
}
