// The ranking engines side by side on a real collection's histograms:
//   1. the exact inverted file (what eval and the index service use) against
//      the pairwise dense code it replaced: largest relative difference of
//      the distances, queries whose whole ranking is identical, every metric
//      of both, and the time of each;
//   2. the candidate stage on real histograms: recall@10 of Search with C
//      candidates against exact search, each model querying all the others.
//
//   rank_check --manifest FILE [any pipeline flag of `meshseek eval`]
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <limits>
#include <numeric>
#include <opencv2/core.hpp>
#include <set>
#include <vector>

#include "absl/flags/flag.h"
#include "absl/flags/parse.h"
#include "common/flags/pipeline_flags.h"
#include "common/eval/retrieval_metrics.h"
#include "common/pipeline/retrieval_pipeline.h"
#include "common/search/kl_inverted_index.h"

ABSL_FLAG(std::string, manifest, "", "CSV manifest id,class,path");
ABSL_FLAG(std::string, histograms_in, "",
          "read the histograms from here (as --histograms_out writes them) instead of "
          "extracting and encoding the collection");
ABSL_FLAG(std::string, histograms_out, "",
          "also write the histograms here: uint32 N, uint32 V, then N x V float32, manifest "
          "order (for experiments with candidate stages)");

namespace meshseek {
namespace {

double Since(std::chrono::steady_clock::time_point start) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

// The pairwise dense ranking as RankCollection computed it before the
// inverted file (+inf to and from models without features).
std::vector<float> PairwiseMatrix(const std::vector<std::vector<float>>& histograms,
                                  const RetrievalPipelineOptions& options) {
  const std::size_t n = histograms.size();
  std::vector<std::size_t> present;
  std::vector<std::vector<float>> compared;
  for (std::size_t i = 0; i < n; ++i) {
    if (histograms[i].empty()) continue;
    present.push_back(i);
    compared.push_back(histograms[i]);
  }
  std::vector<float> out(n * n, std::numeric_limits<float>::infinity());
  for (std::size_t i = 0; i < n; ++i) out[i * n + i] = 0;
  const std::vector<float> sub = *SymmetricKlDistanceMatrix(compared, options.kl, options.num_threads);
  const std::size_t m = present.size();
  for (std::size_t a = 0; a < m; ++a) {
    for (std::size_t b = 0; b < m; ++b) out[present[a] * n + present[b]] = sub[a * m + b];
  }
  return out;
}

std::vector<std::size_t> Ranking(const std::vector<float>& matrix, std::size_t n, std::size_t i) {
  std::vector<std::size_t> order(n);
  std::iota(order.begin(), order.end(), 0);
  std::stable_sort(order.begin(), order.end(), [&](std::size_t a, std::size_t b) {
    return matrix[i * n + a] < matrix[i * n + b];
  });
  return order;
}

void PrintMetrics(const char* name, const RetrievalMetrics& m) {
  std::printf("  %-22s NN %.4f  FT %.4f  ST %.4f  E %.4f  DCG %.4f  (macro FT %.4f)\n", name,
              m.micro.nn, m.micro.rp_excl, m.micro.second_tier, m.micro.e_measure, m.micro.dcg,
              m.macro.rp_excl);
}

int Run(const flags::ParamFlags& params) {
  auto models = ReadManifest(absl::GetFlag(FLAGS_manifest));
  auto parsed = flags::PipelineOptionsFromFlags(params);
  if (!models.ok() || !parsed.ok()) {
    std::fprintf(stderr, "%s %s\n", models.status().ToString().c_str(),
                 parsed.status().ToString().c_str());
    return 2;
  }
  const RetrievalPipelineOptions options = *parsed;
  std::vector<std::vector<float>> histograms;
  std::size_t vocabulary = 0;
  if (const std::string in = absl::GetFlag(FLAGS_histograms_in); !in.empty()) {
    std::FILE* f = std::fopen(in.c_str(), "rb");
    uint32_t header[2] = {0, 0};
    if (f == nullptr || std::fread(header, sizeof(header), 1, f) != 1 ||
        header[0] != models->size()) {
      std::fprintf(stderr, "%s: cannot read histograms for %zu models\n", in.c_str(),
                   models->size());
      return 1;
    }
    vocabulary = header[1];
    histograms.assign(header[0], std::vector<float>(vocabulary));
    for (auto& h : histograms) {
      if (std::fread(h.data(), sizeof(float), vocabulary, f) != vocabulary) return 1;
      if (std::all_of(h.begin(), h.end(), [](float v) { return v == 0; })) h.clear();
    }
    std::fclose(f);
  } else {
    auto features = ExtractCollection(*models, options);
    if (!features.ok()) {
      std::fprintf(stderr, "%s\n", features.status().ToString().c_str());
      return 1;
    }
    auto codebook = TrainCollectionCodebook(*features, options);
    if (!codebook.ok()) {
      std::fprintf(stderr, "%s\n", codebook.status().ToString().c_str());
      return 1;
    }
    histograms = *EncodeCollection(*codebook, *features, options);
    vocabulary = codebook->size();
  }
  const std::size_t n = histograms.size();
  if (const std::string out = absl::GetFlag(FLAGS_histograms_out); !out.empty()) {
    std::FILE* f = std::fopen(out.c_str(), "wb");
    const uint32_t header[2] = {static_cast<uint32_t>(n), static_cast<uint32_t>(vocabulary)};
    std::fwrite(header, sizeof(header), 1, f);
    for (const auto& h : histograms) {
      std::vector<float> row = h;
      row.resize(vocabulary, 0.0f);
      std::fwrite(row.data(), sizeof(float), row.size(), f);
    }
    std::fclose(f);
  }
  std::vector<std::string> labels;
  for (const auto& m : *models) labels.push_back(m.label);
  std::size_t words = 0;
  for (const auto& h : histograms) {
    words += std::count_if(h.begin(), h.end(), [](float v) { return v > 0; });
  }
  std::printf("%s: %zu models, V = %zu, %.0f words per histogram on average\n",
              absl::GetFlag(FLAGS_manifest).c_str(), n, vocabulary,
              static_cast<double>(words) / n);

  // 1. Inverted file against the pairwise code.
  auto start = std::chrono::steady_clock::now();
  const std::vector<float> pairwise = PairwiseMatrix(histograms, options);
  const double pairwise_s = Since(start);
  start = std::chrono::steady_clock::now();
  const std::vector<float> inverted = *RankCollection(histograms, options);
  const double inverted_s = Since(start);
  double worst = 0;
  for (std::size_t i = 0; i < n * n; ++i) {
    if (std::isinf(pairwise[i]) || pairwise[i] == 0) continue;
    worst = std::max(worst, std::fabs(double(inverted[i]) - pairwise[i]) / pairwise[i]);
  }
  // Where rankings differ: the pairs of models the two put in opposite
  // orders, and how far apart the pairwise code puts them (relative).
  std::size_t identical = 0, swapped_pairs = 0;
  double widest_swap = 0;
  for (std::size_t i = 0; i < n; ++i) {
    const std::vector<std::size_t> a = Ranking(pairwise, n, i), b = Ranking(inverted, n, i);
    if (a == b) {
      ++identical;
      continue;
    }
    std::vector<std::size_t> rank_b(n);
    for (std::size_t r = 0; r < n; ++r) rank_b[b[r]] = r;
    for (std::size_t r = 0; r + 1 < n; ++r) {
      for (std::size_t t = r + 1; t < n && t < r + 20; ++t) {
        if (rank_b[a[r]] < rank_b[a[t]]) continue;
        ++swapped_pairs;
        const double x = pairwise[i * n + a[r]], y = pairwise[i * n + a[t]];
        if (y > 0 && std::isfinite(y)) widest_swap = std::max(widest_swap, (y - x) / y);
      }
    }
  }
  std::printf("all-pairs: pairwise %.2f s, inverted file %.2f s; largest relative difference %.2e; "
              "identical rankings %zu of %zu queries",
              pairwise_s, inverted_s, worst, identical, n);
  if (identical < n) {
    std::printf(" (the others swap %zu pairs of models whose pairwise distances differ by at most "
                "%.2e relative)",
                swapped_pairs, widest_swap);
  }
  std::printf("\n");
  PrintMetrics("pairwise (before)", *EvaluateRetrieval(labels, pairwise, options.num_threads));
  PrintMetrics("inverted file (now)", *EvaluateRetrieval(labels, inverted, options.num_threads));

  // 2. Candidates on real histograms: each model against all the others.
  auto index = KlInvertedIndex::Create(static_cast<uint32_t>(vocabulary), options.kl);
  std::vector<SparseHistogram> sparse(n);
  for (std::size_t i = 0; i < n; ++i) {
    sparse[i] = histograms[i].empty() ? SparseHistogram{static_cast<uint32_t>(vocabulary), {}, {}}
                                      : SparseFromDense(histograms[i]);
    (void)index->Upsert(static_cast<uint32_t>(i), sparse[i]);
  }
  // The embedding is fitted automatically from 2,048 models; fit it on this
  // (smaller) collection now, as the index would on a larger one.
  index->FitEmbedding();
  for (const std::size_t candidates : {n / 50, n / 20, n / 10, n / 5}) {
    if (candidates < 11) continue;
    std::size_t found = 0, wanted = 0;
    for (std::size_t i = 0; i < n; ++i) {
      if (sparse[i].empty()) continue;
      const auto exact = *index->Search(sparse[i], 11, 1);
      const auto approximate = *index->Search(sparse[i], 11, 1, candidates);
      std::set<uint32_t> truth;
      for (std::size_t r = 0; r < 11; ++r) {
        if (exact[r].doc != i) truth.insert(exact[r].doc);
      }
      for (std::size_t r = 0; r < 11; ++r) {
        if (approximate[r].doc != i) found += truth.count(approximate[r].doc);
      }
      wanted += truth.size();
    }
    std::printf("candidates %zu of %zu models (%.0f %%): recall@10 %.4f\n", candidates, n,
                100.0 * candidates / n, static_cast<double>(found) / wanted);
  }
  return 0;
}

}  // namespace
}  // namespace meshseek

int main(int argc, char** argv) {
  const meshseek::flags::CommandLine line =
      meshseek::flags::ParseCommandLineWithParams(argc, argv, "");
  cv::setNumThreads(0);
  return meshseek::Run(line.params);
}
