// Recall of fused candidates (docs/design.md "Fused candidates",
// services/coordinator/fused_candidates.h) on a labelled collection, from the
// per-method matrices an in-process `meshseek eval` of a fused collection
// wrote (distances.METHOD.bin beside distances.bin):
//
//   fused_candidates --manifest SET/manifest.csv --eval OUT
//     --method bfdsift+rld+lsf+lfd [any pipeline flag of eval] [--candidates 25,50,100,200]
//
// Every model queries the collection as the services answer a query from
// outside it: its fused row (the eval's scales and weights) re-ranked while
// it joins the neighbour graph (RerankRow with no self). Exact: the whole
// row. With C candidates: each method's C nearest by its own distance, the
// row kept on their union only (+inf elsewhere), re-ranked the same way.
// This is what the services compute when every method's proposals are its
// exact nearest (global methods, and collections below the histogram
// embedding's fit at 2,048 models; above it the embedding's own recall is
// bench/results/index.txt's). Prints, per C, recall@10 against the exact
// top 10 (mean, worst query, queries with all ten), the union's mean size,
// and the first tier of both rankings. Then, per --graph_candidates C, an
// approximate neighbour graph (each model's list from the fused distances
// to its own union of C per method only): the share of the exact graph's
// list entries it keeps, and the first tier of eval's matrix over it.
#include <algorithm>
#include <limits>
#include <cstdio>
#include <numeric>
#include <set>
#include <string>
#include <vector>

#include "absl/flags/flag.h"
#include "absl/strings/numbers.h"
#include "absl/strings/str_cat.h"
#include "absl/strings/str_split.h"
#include "common/flags/pipeline_flags.h"
#include "common/eval/distance_matrix.h"
#include "common/eval/manifest.h"
#include "common/eval/retrieval_metrics.h"
#include "common/search/fusion.h"
#include "common/search/neighbor_graph.h"
#include "common/search/rerank.h"

ABSL_FLAG(std::string, manifest, "", "CSV manifest id,class,path (the matrices' order)");
ABSL_FLAG(std::string, eval, "", "the folder an in-process eval of the fused collection wrote");
ABSL_FLAG(std::string, candidates, "10,25,50,100,200",
          "query candidates per method, comma-separated");
ABSL_FLAG(bool, global_proposes, false,
          "global methods (LFD) propose candidates too (the services: only the histogram methods)");
ABSL_FLAG(std::string, graph_candidates, "10,25,50,100",
          "candidates per method of an approximate neighbour graph, comma-separated");

namespace meshseek {
namespace {

constexpr std::size_t kRecallAt = 10;

// Row order of a ranking: by (distance, index), as the services break ties
// (index order is ordinal order).
std::vector<uint32_t> Top(absl::Span<const float> row, std::size_t k) {
  std::vector<uint32_t> order(row.size());
  std::iota(order.begin(), order.end(), 0u);
  k = std::min(k, order.size());
  std::partial_sort(order.begin(), order.begin() + k, order.end(), [&](uint32_t a, uint32_t b) {
    return row[a] < row[b] || (row[a] == row[b] && a < b);
  });
  order.resize(k);
  return order;
}

absl::StatusOr<std::vector<std::size_t>> Counts(const absl::Flag<std::string>& flag) {
  std::vector<std::size_t> counts;
  for (absl::string_view c : absl::StrSplit(absl::GetFlag(flag), ',', absl::SkipEmpty())) {
    std::size_t value = 0;
    if (!absl::SimpleAtoi(c, &value) || value == 0) {
      return absl::InvalidArgumentError(absl::StrCat("'", c, "' is not a positive count"));
    }
    counts.push_back(value);
  }
  return counts;
}

// The union of each method's c nearest to model i.
std::vector<uint32_t> Proposed(const std::vector<std::vector<float>>& matrices,
                               const std::vector<bool>& proposes,
                               std::size_t n,
                               std::size_t i,
                               std::size_t c) {
  std::set<uint32_t> proposed;
  for (std::size_t m = 0; m < matrices.size(); ++m) {
    if (!proposes[m]) continue;
    for (uint32_t j : Top(absl::MakeConstSpan(matrices[m]).subspan(i * n, n), c)) {
      proposed.insert(j);
    }
  }
  return std::vector<uint32_t>(proposed.begin(), proposed.end());
}

// Row i of `fused` kept on `on` only, +inf elsewhere.
std::vector<float> Restricted(const std::vector<float>& fused,
                              std::size_t n,
                              std::size_t i,
                              const std::vector<uint32_t>& on) {
  std::vector<float> row(n, std::numeric_limits<float>::infinity());
  for (uint32_t j : on) row[j] = fused[i * n + j];
  return row;
}

int Run(const flags::ParamFlags& params) {
  absl::StatusOr<std::vector<ManifestEntry>> models = ReadManifest(absl::GetFlag(FLAGS_manifest));
  absl::StatusOr<CollectionOptions> options = flags::CollectionOptionsFromFlags(params);
  if (!models.ok() || !options.ok()) {
    std::fprintf(stderr, "%s %s\n", models.status().ToString().c_str(),
                 options.status().ToString().c_str());
    return 2;
  }
  if (!options->rescaled() || !options->rerank.enabled()) {
    std::fprintf(stderr, "--method must name a fused, re-ranked collection\n");
    return 2;
  }
  absl::StatusOr<std::vector<std::size_t>> candidate_counts = Counts(FLAGS_candidates);
  absl::StatusOr<std::vector<std::size_t>> graph_counts = Counts(FLAGS_graph_candidates);
  if (!candidate_counts.ok() || !graph_counts.ok()) {
    std::fprintf(stderr, "%s %s\n", candidate_counts.status().ToString().c_str(),
                 graph_counts.status().ToString().c_str());
    return 2;
  }
  const std::size_t n = models->size();
  // Which methods propose candidates: the histogram methods, and the global
  // ones only when asked (the services do not ask them: their index scans).
  std::vector<bool> proposes;
  for (const RetrievalPipelineOptions& method : options->methods) {
    proposes.push_back(absl::GetFlag(FLAGS_global_proposes) ||
                       FeatureMethodInfoOf(method.extractor.method).kind != DescriptorKind::kGlobal);
  }
  std::vector<std::vector<float>> matrices;
  for (const RetrievalPipelineOptions& method : options->methods) {
    const std::string path = absl::StrCat(absl::GetFlag(FLAGS_eval), "/distances.",
                                          FeatureMethodName(method.extractor.method), ".bin");
    absl::StatusOr<std::vector<float>> matrix = ReadDistanceMatrix(path, n);
    if (!matrix.ok()) {
      std::fprintf(stderr, "%s\n", matrix.status().ToString().c_str());
      return 1;
    }
    matrices.push_back(*std::move(matrix));
  }
  // The eval's fusion: scales over the sample rows, then every fused row.
  std::vector<double> scales;
  for (const std::vector<float>& m : matrices) {
    DistanceScale scale;
    for (std::size_t r : ScaleSampleRows(n)) scale.AddRow(r, absl::MakeConstSpan(m).subspan(r * n, n));
    scales.push_back(scale.Scale());
  }
  const std::vector<double> factors = *FusionFactors(options->weights, scales);
  std::vector<float> fused(n * n);
  for (std::size_t i = 0; i < n; ++i) {
    std::vector<absl::Span<const float>> rows;
    for (const std::vector<float>& m : matrices) rows.push_back(absl::MakeConstSpan(m).subspan(i * n, n));
    FuseRows(rows, factors, absl::MakeSpan(fused).subspan(i * n, n));
  }
  const NeighborGraph graph = *NeighborGraph::FromMatrix(fused, n, options->rerank.graph_k());
  std::vector<std::string> labels;
  for (const ManifestEntry& m : *models) labels.push_back(m.label);

  std::vector<float> exact(n * n);
  for (std::size_t i = 0; i < n; ++i) {
    const std::vector<float> row =
        *RerankRow(graph, absl::MakeConstSpan(fused).subspan(i * n, n), std::nullopt, options->rerank);
    std::copy(row.begin(), row.end(), exact.begin() + i * n);
  }
  const RetrievalMetrics exact_metrics = *EvaluateRetrieval(labels, exact, 1);
  std::printf("%zu models, %zu methods; exact: FT %.4f (macro %.4f)\n", n, matrices.size(),
              exact_metrics.micro.rp_excl, exact_metrics.macro.rp_excl);
  std::printf("%10s %10s %12s %10s %10s %10s %10s\n", "candidates", "union", "recall@10",
              "worst", "all_ten", "FT", "FT_macro");
  for (const std::size_t c : *candidate_counts) {
    std::vector<float> ranked(n * n);
    double recall_sum = 0, union_sum = 0, worst = 1;
    std::size_t all_ten = 0;
    for (std::size_t i = 0; i < n; ++i) {
      const std::vector<uint32_t> proposed = Proposed(matrices, proposes, n, i, c);
      const std::vector<float> got =
          *RerankRow(graph, Restricted(fused, n, i, proposed), std::nullopt, options->rerank);
      std::copy(got.begin(), got.end(), ranked.begin() + i * n);
      const std::vector<uint32_t> want = Top(absl::MakeConstSpan(exact).subspan(i * n, n), kRecallAt);
      const std::vector<uint32_t> have = Top(got, kRecallAt);
      const std::set<uint32_t> want_set(want.begin(), want.end());
      std::size_t hits = 0;
      for (uint32_t j : have) hits += want_set.count(j);
      const double recall = static_cast<double>(hits) / static_cast<double>(want.size());
      recall_sum += recall;
      worst = std::min(worst, recall);
      all_ten += hits == want.size();
      union_sum += static_cast<double>(proposed.size());
    }
    const RetrievalMetrics metrics = *EvaluateRetrieval(labels, ranked, 1);
    std::printf("%10zu %10.1f %12.4f %10.2f %10zu %10.4f %10.4f\n", c, union_sum / n,
                recall_sum / n, worst, all_ten, metrics.micro.rp_excl, metrics.macro.rp_excl);
  }

  // Approximate graphs: each model's list from its candidates' fused
  // distances only; every model then ranked as eval ranks it (its whole row,
  // itself a node), against the exact graph's eval matrix.
  const std::vector<float> eval_exact = *RerankMatrix(graph, fused, options->rerank);
  const RetrievalMetrics eval_metrics = *EvaluateRetrieval(labels, eval_exact, 1);
  std::printf("\neval rows (each model a node, whole rows); exact graph: FT %.4f (macro %.4f)\n",
              eval_metrics.micro.rp_excl, eval_metrics.macro.rp_excl);
  std::printf("%16s %10s %14s %10s %10s\n", "graph_candidates", "union", "list_recall", "FT",
              "FT_macro");
  const int k = options->rerank.graph_k();
  for (const std::size_t c : *graph_counts) {
    NeighborGraph approximate = *NeighborGraph::Create(n, k);
    double union_sum = 0;
    for (std::size_t i = 0; i < n; ++i) {
      const std::vector<uint32_t> proposed = Proposed(matrices, proposes, n, i, c);
      union_sum += static_cast<double>(proposed.size());
      approximate.SetRow(static_cast<uint32_t>(i), Restricted(fused, n, i, proposed));
    }
    std::size_t kept = 0, entries = 0;
    for (uint32_t i = 0; i < n; ++i) {
      std::set<uint32_t> want;
      for (const GraphNeighbor& nb : graph.Of(i)) want.insert(nb.node);
      for (const GraphNeighbor& nb : approximate.Of(i)) kept += want.count(nb.node);
      entries += want.size();
    }
    const std::vector<float> ranked = *RerankMatrix(approximate, fused, options->rerank);
    const RetrievalMetrics metrics = *EvaluateRetrieval(labels, ranked, 1);
    std::printf("%16zu %10.1f %14.4f %10.4f %10.4f\n", c, union_sum / n,
                static_cast<double>(kept) / static_cast<double>(entries), metrics.micro.rp_excl,
                metrics.macro.rp_excl);
  }
  return 0;
}

}  // namespace
}  // namespace meshseek

int main(int argc, char** argv) {
  const meshseek::flags::CommandLine line = meshseek::flags::ParseCommandLineWithParams(
      argc, argv, "fused_candidates --manifest F --eval DIR --method M");
  return meshseek::Run(line.params);
}
