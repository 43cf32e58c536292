// Fusion and re-ranking choices on a labelled collection, from the distance
// matrices each method's `meshseek eval` wrote (bench/results/fusion.txt):
//
//   fusion_sweep --manifest SET/manifest.csv
//     --matrices bfdsift=out/bf/distances.bin,rld=out/rld/distances.bin,...
//     --combos bfdsift+rld,bfdsift+rld+lfd [--weights "1,1;2,1"]
//     [--normalisations scale,query_mean,query_z,query_knn]
//     [--k1 10,20 --k2 1,4 --lambda 0.1,0.3 --depth 100] [--csv OUT] [--tag TEXT]
//
// Every combination of the lists is one row: the methods, their weights (a
// weight list per combination size; default the methods' own), the normalisation, and
// the re-ranking (rerank none first, then every k1, k2, lambda, depth).
// "scale" is what meshseek ships (CombineMethodDistances, each method divided
// by its mean over the collection); the query_* normalisations divide each
// row by its own mean, standardise it, or divide by the mean of its 10
// nearest, for comparison. Metrics as metrics.json computes them.
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <map>
#include <string>
#include <vector>

#include "absl/flags/flag.h"
#include "absl/flags/parse.h"
#include "absl/strings/numbers.h"
#include "absl/strings/str_format.h"
#include "absl/strings/str_join.h"
#include "absl/strings/str_replace.h"
#include "absl/strings/str_split.h"
#include "common/eval/distance_matrix.h"
#include "common/eval/manifest.h"
#include "common/eval/retrieval_metrics.h"
#include "common/pipeline/collection_evaluation.h"
#include "common/search/fusion.h"
#include "common/search/neighbor_graph.h"
#include "common/search/rerank.h"

ABSL_FLAG(std::string, manifest, "", "CSV manifest id,class,path (the matrices' order)");
ABSL_FLAG(std::string, matrices, "", "method=path of its distances.bin, comma-separated");
ABSL_FLAG(std::string, combos, "", "methods joined by +, comma-separated (default: all given)");
ABSL_FLAG(std::string, weights, "", "weight lists separated by ';' (default: the methods' own)");
ABSL_FLAG(std::string, normalisations, "scale", "scale,query_mean,query_z,query_knn");
ABSL_FLAG(std::string, k1, "20", "re-ranking k1 values");
ABSL_FLAG(std::string, k2, "4", "re-ranking k2 values");
ABSL_FLAG(std::string, lambda, "0.1", "re-ranking lambda values");
ABSL_FLAG(std::string, depth, "200", "re-ranking depth values");
ABSL_FLAG(std::string,
          manifold,
          "",
          "experimental second re-ranking, manifold ranking on the k-NN graph: k:alpha pairs, "
          "comma-separated (e.g. 10:0.9,20:0.95), each with every --lambda");
ABSL_FLAG(bool, rerank_only, false, "skip the rows without re-ranking");
ABSL_FLAG(std::string, csv, "", "append rows to this CSV file");
ABSL_FLAG(std::string, tag, "", "free text copied into the rows");
ABSL_FLAG(int, threads, 0, "threads (0: all cores)");

namespace {

using namespace meshseek;

std::vector<double> Numbers(absl::string_view text) {
  std::vector<double> values;
  for (absl::string_view part : absl::StrSplit(text, ',', absl::SkipEmpty())) {
    double v;
    if (!absl::SimpleAtod(part, &v)) {
      std::fprintf(stderr, "bad number '%s'\n", std::string(part).c_str());
      std::exit(2);
    }
    values.push_back(v);
  }
  return values;
}

// Each row divided by (or standardised with) its own statistics over the
// other models, then symmetrised.
std::vector<float> QueryNormalised(const std::vector<float>& d,
                                   std::size_t n,
                                   const std::string& how) {
  std::vector<float> out(n * n);
  for (std::size_t i = 0; i < n; ++i) {
    std::vector<double> others;
    for (std::size_t j = 0; j < n; ++j) {
      if (j != i && std::isfinite(d[i * n + j])) others.push_back(d[i * n + j]);
    }
    double mean = 0, var = 0;
    for (double x : others) mean += x;
    mean /= std::max<std::size_t>(others.size(), 1);
    for (double x : others) var += (x - mean) * (x - mean);
    const double sd = std::sqrt(var / std::max<std::size_t>(others.size(), 1));
    double knn = mean;
    if (how == "query_knn") {
      std::sort(others.begin(), others.end());
      knn = 0;
      const std::size_t k = std::min<std::size_t>(10, others.size());
      for (std::size_t r = 0; r < k; ++r) knn += others[r];
      knn /= std::max<std::size_t>(k, 1);
    }
    for (std::size_t j = 0; j < n; ++j) {
      const double x = d[i * n + j];
      out[i * n + j] = static_cast<float>(how == "query_z"     ? (x - mean) / sd
                                          : how == "query_knn" ? x / knn
                                                               : x / mean);
    }
  }
  for (std::size_t i = 0; i < n; ++i) {
    for (std::size_t j = i + 1; j < n; ++j) {
      const float s = 0.5f * (out[i * n + j] + out[j * n + i]);
      out[i * n + j] = out[j * n + i] = s;
    }
    out[i * n + i] = how == "query_z" ? -1e30f : 0.0f;
  }
  return out;
}

// Manifold ranking (Zhou, Weston, Gretton, Bousquet & Schoelkopf, NIPS
// 2003), the diffusion alternative to k-reciprocal re-ranking, over the
// symmetric k-NN graph of the fused distances d: W_ij = exp(-d_ij^2 /
// (s_i s_j)) on the graph's edges (s_i: i's distance to its k-th neighbour,
// local scaling), S = D^-1/2 W D^-1/2, scores F = (1 - alpha)(I - alpha
// S)^-1, computed by iterating F <- alpha S F + (1 - alpha) I. A query's
// distance to j is (1 - lambda)(1 - F_qj / max_j F_qj) + lambda d_qj.
// Dense N x N: for the development sets only (meshseek ships k-reciprocal).
std::vector<float> ManifoldRanked(
    const std::vector<float>& d, std::size_t n, int k, double alpha, double lambda) {
  const NeighborGraph graph = *NeighborGraph::FromMatrix(d, n, k + 1);
  std::vector<double> sigma(n, 1.0);
  std::vector<std::map<uint32_t, double>> w(n);
  for (std::size_t i = 0; i < n; ++i) {
    const auto list = graph.Of(static_cast<uint32_t>(i));
    if (!list.empty()) sigma[i] = std::max<double>(list.back().distance, 1e-12);
  }
  for (std::size_t i = 0; i < n; ++i) {
    for (const auto& nb : graph.Of(static_cast<uint32_t>(i))) {
      const std::size_t j = nb.node;
      if (j == i || !std::isfinite(nb.distance)) continue;
      const double x = std::exp(-double(nb.distance) * nb.distance / (sigma[i] * sigma[j]));
      w[i][j] = x;
      w[j][i] = x;
    }
  }
  std::vector<double> degree(n, 0.0);
  for (std::size_t i = 0; i < n; ++i) {
    for (const auto& [j, x] : w[i]) degree[i] += x;
  }
  std::vector<std::vector<std::pair<uint32_t, double>>> s(n);
  for (std::size_t i = 0; i < n; ++i) {
    for (const auto& [j, x] : w[i]) {
      s[i].emplace_back(j, x / std::sqrt(std::max(degree[i] * degree[j], 1e-300)));
    }
  }
  std::vector<double> f(n * n, 0.0), next(n * n);
  for (std::size_t i = 0; i < n; ++i) f[i * n + i] = 1 - alpha;
  const int iterations = static_cast<int>(std::ceil(std::log(1e-4) / std::log(alpha)));
  for (int t = 0; t < iterations; ++t) {
    for (std::size_t i = 0; i < n; ++i) {
      double* row = &next[i * n];
      std::fill(row, row + n, 0.0);
      row[i] = 1 - alpha;
      for (const auto& [j, x] : s[i]) {
        const double* src = &f[j * n];
        for (std::size_t c = 0; c < n; ++c) row[c] += alpha * x * src[c];
      }
    }
    f.swap(next);
  }
  std::vector<float> out(n * n);
  for (std::size_t q = 0; q < n; ++q) {
    double top = 0;
    for (std::size_t j = 0; j < n; ++j) top = std::max(top, f[q * n + j]);
    for (std::size_t j = 0; j < n; ++j) {
      const double diffusion = top > 0 ? 1 - f[q * n + j] / top : 1;
      out[q * n + j] =
          q == j ? 0.0f : static_cast<float>((1 - lambda) * diffusion + lambda * d[q * n + j]);
    }
  }
  return out;
}

// One result row: the tag, the methods, their weights, the normalisation,
// the re-ranking `settings` (method,k1,k2,lambda,depth), the metrics and the
// time; printed and appended to --csv.
void PrintRow(const std::string& combo,
              const std::vector<double>& weights,
              absl::string_view how,
              const std::string& settings,
              const RetrievalMetrics& metrics,
              double seconds) {
  std::vector<std::string> w;
  for (double x : weights) w.push_back(absl::StrFormat("%g", x));
  const std::string row = absl::StrFormat("%s,%s,%s,%s,%s,%.2f,%.2f,%.2f,%.2f,%.2f,%.2f,%.2f",
                                          absl::GetFlag(FLAGS_tag),
                                          combo,
                                          absl::StrJoin(w, ":"),
                                          how,
                                          settings,
                                          100 * metrics.micro.nn,
                                          100 * metrics.micro.rp_excl,
                                          100 * metrics.micro.second_tier,
                                          100 * metrics.micro.e_measure,
                                          100 * metrics.micro.dcg,
                                          100 * metrics.macro.rp_excl,
                                          seconds);
  std::printf("%s\n", row.c_str());
  std::fflush(stdout);
  if (!absl::GetFlag(FLAGS_csv).empty()) {
    std::ofstream(absl::GetFlag(FLAGS_csv), std::ios::app) << row << "\n";
  }
}

}  // namespace

int main(int argc, char** argv) {
  absl::ParseCommandLine(argc, argv);
  auto models = ReadManifest(absl::GetFlag(FLAGS_manifest));
  if (!models.ok()) {
    std::fprintf(stderr, "%s\n", models.status().ToString().c_str());
    return 1;
  }
  const std::size_t n = models->size();
  std::vector<std::string> labels;
  for (const ManifestEntry& m : *models) labels.push_back(m.label);

  std::map<std::string, std::vector<float>> matrices;
  std::vector<std::string> given;
  for (absl::string_view item :
       absl::StrSplit(absl::GetFlag(FLAGS_matrices), ',', absl::SkipEmpty())) {
    std::pair<std::string, std::string> kv = absl::StrSplit(item, absl::MaxSplits('=', 1));
    auto matrix = ReadDistanceMatrix(kv.second, n);
    if (!matrix.ok()) {
      std::fprintf(stderr, "%s\n", matrix.status().ToString().c_str());
      return 1;
    }
    matrices[kv.first] = *std::move(matrix);
    given.push_back(kv.first);
  }
  std::vector<std::string> combos =
      absl::StrSplit(absl::GetFlag(FLAGS_combos), ',', absl::SkipEmpty());
  if (combos.empty()) combos.push_back(absl::StrJoin(given, "+"));
  std::vector<std::string> weight_lists =
      absl::StrSplit(absl::GetFlag(FLAGS_weights), ';', absl::SkipEmpty());

  std::printf(
      "tag,methods,weights,normalisation,rerank,k1,k2,lambda,depth,NN,FT,ST,E,DCG,"
      "FT_macro,seconds\n");
  for (const std::string& combo : combos) {
    const std::vector<std::string> names = absl::StrSplit(combo, '+');
    std::vector<FeatureMethod> methods;
    std::vector<absl::Span<const float>> parts;
    for (const std::string& name : names) {
      auto m = ParseFeatureMethod(name);
      if (!m.ok() || !matrices.count(name)) {
        std::fprintf(stderr, "no matrix for method '%s'\n", name.c_str());
        return 2;
      }
      methods.push_back(*m);
      parts.push_back(matrices[name]);
    }
    std::vector<std::vector<double>> weightings;
    for (const std::string& w : weight_lists) {
      if (Numbers(w).size() == names.size()) weightings.push_back(Numbers(w));
    }
    if (weightings.empty()) weightings.push_back(CollectionOptions::ForMethods(methods).weights);
    for (const std::vector<double>& weights : weightings) {
      for (absl::string_view how :
           absl::StrSplit(absl::GetFlag(FLAGS_normalisations), ',', absl::SkipEmpty())) {
        // The re-ranking settings: none first, then every combination.
        std::vector<RerankOptions> reranks;
        if (!absl::GetFlag(FLAGS_rerank_only)) {
          reranks.emplace_back();
          reranks.back().method = RerankOptions::Method::kNone;
        }
        for (double k1 : Numbers(absl::GetFlag(FLAGS_k1))) {
          for (double k2 : Numbers(absl::GetFlag(FLAGS_k2))) {
            for (double lambda : Numbers(absl::GetFlag(FLAGS_lambda))) {
              for (double depth : Numbers(absl::GetFlag(FLAGS_depth))) {
                RerankOptions r;
                r.k1 = static_cast<int>(k1);
                r.k2 = static_cast<int>(k2);
                r.lambda = lambda;
                r.depth = static_cast<int>(depth);
                reranks.push_back(r);
              }
            }
          }
        }
        for (const RerankOptions& rerank : reranks) {
          const auto start = std::chrono::steady_clock::now();
          CollectionOptions options = CollectionOptions::ForMethods(methods);
          options.SetRunOptions(absl::GetFlag(FLAGS_threads), false);
          options.weights = weights;
          options.rerank = rerank;
          absl::StatusOr<std::vector<float>> ranked;
          std::vector<double> scales;
          if (how == "scale") {
            // One method without re-ranking is its own distance: rescaling
            // changes no ranking, so the shipped path serves every row.
            ranked = CombineMethodDistances(parts, n, options, &scales);
          } else {
            // Per-query normalisations: each method's rows normalised, then
            // fused with the weights (scales 1) and re-ranked the same way.
            std::vector<std::vector<float>> normalised;
            for (const absl::Span<const float>& p : parts) {
              normalised.push_back(
                  QueryNormalised(std::vector<float>(p.begin(), p.end()), n, std::string(how)));
            }
            std::vector<absl::Span<const float>> spans(normalised.begin(), normalised.end());
            std::vector<float> fused(n * n);
            const std::vector<double> ones(names.size(), 1.0);
            auto factors = FusionFactors(weights, ones);
            for (std::size_t i = 0; i < n; ++i) {
              std::vector<absl::Span<const float>> rows;
              for (const auto& s : spans) rows.push_back(s.subspan(i * n, n));
              FuseRows(rows, *factors, absl::MakeSpan(fused).subspan(i * n, n));
            }
            ranked = fused;
            if (rerank.enabled() && how != "query_z") {
              auto graph = NeighborGraph::FromMatrix(fused, n, rerank.graph_k());
              ranked = RerankMatrix(*graph, fused, rerank);
            }
          }
          if (!ranked.ok()) {
            std::fprintf(stderr, "%s\n", ranked.status().ToString().c_str());
            return 1;
          }
          auto metrics = EvaluateRetrieval(labels, *ranked, absl::GetFlag(FLAGS_threads));
          const double seconds =
              std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
          PrintRow(combo,
                   weights,
                   how,
                   absl::StrFormat("%s,%d,%d,%g,%d",
                                   rerank.enabled() ? "kreciprocal" : "none",
                                   rerank.k1,
                                   rerank.k2,
                                   rerank.lambda,
                                   rerank.depth),
                   *metrics,
                   seconds);
        }
        if (how != "scale") continue;
        for (absl::string_view pair :
             absl::StrSplit(absl::GetFlag(FLAGS_manifold), ',', absl::SkipEmpty())) {
          const std::vector<double> ka = Numbers(absl::StrReplaceAll(pair, {{":", ","}}));
          if (ka.size() != 2) continue;
          for (double lambda : Numbers(absl::GetFlag(FLAGS_lambda))) {
            const auto start = std::chrono::steady_clock::now();
            CollectionOptions options = CollectionOptions::ForMethods(methods);
            options.SetRunOptions(absl::GetFlag(FLAGS_threads), false);
            options.weights = weights;
            options.rerank.method = RerankOptions::Method::kNone;
            std::vector<double> scales;
            auto fused = CombineMethodDistances(parts, n, options, &scales);
            if (!fused.ok()) return 1;
            const std::vector<float> ranked =
                ManifoldRanked(*fused, n, static_cast<int>(ka[0]), ka[1], lambda);
            auto metrics = EvaluateRetrieval(labels, ranked, absl::GetFlag(FLAGS_threads));
            const double seconds =
                std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
            PrintRow(combo,
                     weights,
                     how,
                     absl::StrFormat("manifold,%g,%g,%g,0", ka[0], ka[1], lambda),
                     *metrics,
                     seconds);
          }
        }
      }
    }
  }
  return 0;
}
