// Candidates for exact KL search, chosen by measurement (docs/design.md
// "Fused candidates"): the hand-written scan of the 128-d Hellinger embedding
// (histogram_embedding.h, what KlInvertedIndex::Search does with candidates)
// against Faiss' exact batched search (IndexFlatL2: a matrix product on BLAS),
// HNSW (IndexHNSWFlat) and IVF (IndexIVFFlat) over the same embeddings, on
// synthetic histograms of one member's shape (common/search/synthetic_histograms.h):
//
//   candidate_search --models 10000 [--vocabulary 2000] [--descriptors 3791]
//     [--candidates 50] [--queries 200] [--hnsw_m 32] [--threads 2]
//
// For each it prints the build time, the time of the whole-collection
// neighbour pass (each of the N models' C nearest: what an approximate
// neighbour graph needs), the bytes of the index (vectors, links, lists), and
// recall@10: the share of each
// query model's exact KL 10 nearest (itself excluded; KlInvertedIndex's exact
// search) among its C candidates, over --queries stored models, and "exact
// C": the share of every model's exact embedding C nearest (the flat index's)
// that an approximate index finds, its own loss apart from the embedding's. The
// hand-written scan's pass is extrapolated from the queries it times.
#include <omp.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <iterator>
#include <random>
#include <string>
#include <vector>

#include <faiss/IndexFlat.h>
#include <faiss/IndexHNSW.h>
#include <faiss/IndexIVFFlat.h>

#include "absl/flags/flag.h"
#include "absl/flags/parse.h"
#include "common/search/synthetic_histograms.h"
#include "common/base/parallel.h"
#include "common/search/histogram_embedding.h"
#include "common/search/kl_inverted_index.h"

ABSL_FLAG(int, models, 10000, "models in the collection");
ABSL_FLAG(int, vocabulary, 2000, "words (RLD-SIFT and LSF: 2,000; BF-DSIFT: 40,000)");
ABSL_FLAG(int, descriptors, 3791, "local features a model (RLD-SIFT's McGill median)");
ABSL_FLAG(int, centres, 4,
          "centres a model's words are drawn around (1: common/search/synthetic_histograms.h's models, "
          "which lie near a curve, too easy for any index)");
ABSL_FLAG(int, candidates, 50, "C, candidates a model");
ABSL_FLAG(int, queries, 200, "stored models whose exact 10 nearest the recall is measured on");
ABSL_FLAG(int, hnsw_m, 32, "HNSW links a node");
ABSL_FLAG(int, threads, 2, "threads (Faiss' OpenMP and the exact search)");

namespace meshseek {
namespace {

constexpr int kDim = KlInvertedIndex::kEmbeddingDimensions;
constexpr int kTop = 10;

double Seconds(std::chrono::steady_clock::time_point start) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

// Each of the query models' candidates (C ids a row) against its exact top 10.
double Recall(const std::vector<std::vector<uint32_t>>& exact, const std::vector<int>& queries,
              const std::vector<faiss::Index::idx_t>& ids, int c) {
  std::size_t found = 0, wanted = 0;
  for (std::size_t q = 0; q < queries.size(); ++q) {
    const faiss::Index::idx_t* row = ids.data() + static_cast<std::size_t>(queries[q]) * c;
    for (uint32_t want : exact[q]) {
      ++wanted;
      found += std::find(row, row + c, static_cast<faiss::Index::idx_t>(want)) != row + c;
    }
  }
  return wanted == 0 ? 0.0 : static_cast<double>(found) / wanted;
}

// Share of the exact embedding neighbours (`reference`, C a row) that
// `ids` found, over every model: the index's own loss, apart from the
// embedding's.
double Agreement(const std::vector<faiss::Index::idx_t>& reference,
                 const std::vector<faiss::Index::idx_t>& ids, int c) {
  std::size_t found = 0;
  for (std::size_t row = 0; row < ids.size(); row += c) {
    std::vector<faiss::Index::idx_t> a(reference.begin() + row, reference.begin() + row + c);
    std::vector<faiss::Index::idx_t> b(ids.begin() + row, ids.begin() + row + c);
    std::sort(a.begin(), a.end());
    std::sort(b.begin(), b.end());
    std::vector<faiss::Index::idx_t> both;
    std::set_intersection(a.begin(), a.end(), b.begin(), b.end(), std::back_inserter(both));
    found += both.size();
  }
  return ids.empty() ? 0.0 : static_cast<double>(found) / ids.size();
}

void Report(const char* name, double build_s, double pass_s, double mb, double recall,
            double agreement, int n) {
  std::printf("%-26s build %7.2f s  neighbour pass %8.2f s (%6.3f ms a model)  %7.1f MB  "
              "recall@10 %.4f  exact C %.4f\n",
              name, build_s, pass_s, 1e3 * pass_s / n, mb, recall, agreement);
}

// A model of `centres` parts: SyntheticHistogram's words around each of its
// centres, in random shares, merged. One centre puts every model near a
// one-dimensional curve (its centre's position), where any index finds the
// neighbours; several give the embeddings the spread of real ones.
SparseHistogram Model(std::mt19937_64& rng, int vocabulary, int descriptors, int centres) {
  if (centres <= 1) return SyntheticHistogram(rng, vocabulary, descriptors);
  std::vector<double> share(centres);
  std::uniform_real_distribution<double> uniform(0.1, 1.0);
  double total = 0;
  for (double& s : share) total += (s = uniform(rng));
  std::vector<float> dense(vocabulary, 0.0f);
  for (double s : share) {
    const SparseHistogram part = SyntheticHistogram(rng, vocabulary, descriptors);
    for (std::size_t i = 0; i < part.words.size(); ++i) {
      dense[part.words[i]] += static_cast<float>(s / total) * part.weights[i];
    }
  }
  SparseHistogram h;
  h.vocabulary = static_cast<uint32_t>(vocabulary);
  float sum = 0;
  for (float w : dense) sum += w;
  for (int k = 0; k < vocabulary; ++k) {
    if (dense[k] > 0) {
      h.words.push_back(k);
      h.weights.push_back(dense[k] / sum);
    }
  }
  return h;
}

int Run() {
  const int n = absl::GetFlag(FLAGS_models), v = absl::GetFlag(FLAGS_vocabulary);
  const int c = absl::GetFlag(FLAGS_candidates), threads = absl::GetFlag(FLAGS_threads);
  omp_set_num_threads(threads);
  std::printf("candidate_search: %d models, V = %d, %d descriptors a model around %d centres, "
              "C = %d, %d threads\n",
              n, v, absl::GetFlag(FLAGS_descriptors), absl::GetFlag(FLAGS_centres), c, threads);

  // The collection, a generator a block of 1,000 models (the same for any
  // thread count).
  auto start = std::chrono::steady_clock::now();
  std::vector<SparseHistogram> histograms(n);
  ParallelFor((n + 999) / 1000, threads, [&](std::size_t block) {
    std::mt19937_64 rng(1000003 * (block + 1));
    for (std::size_t i = block * 1000; i < std::min<std::size_t>(n, (block + 1) * 1000); ++i) {
      histograms[i] =
          Model(rng, v, absl::GetFlag(FLAGS_descriptors) / absl::GetFlag(FLAGS_centres),
                absl::GetFlag(FLAGS_centres));
    }
  });
  auto index = KlInvertedIndex::Create(v);
  if (!index.ok()) return std::fprintf(stderr, "%s\n", index.status().ToString().c_str()), 1;
  for (int i = 0; i < n; ++i) {
    if (auto s = index->Upsert(i, histograms[i]); !s.ok()) return 1;
  }
  std::printf("histograms made and indexed in %.1f s (index %.0f MB)\n", Seconds(start),
              index->MemoryBytes() / 1048576.0);

  // The exact KL 10 nearest of the query models, themselves excluded.
  std::vector<int> queries;
  std::mt19937_64 pick(7);
  for (int q = 0; q < std::min(n, absl::GetFlag(FLAGS_queries)); ++q) queries.push_back(pick() % n);
  std::vector<std::vector<uint32_t>> exact(queries.size());
  start = std::chrono::steady_clock::now();
  for (std::size_t q = 0; q < queries.size(); ++q) {
    auto top = index->Search(histograms[queries[q]], kTop + 1, threads);
    if (!top.ok()) return 1;
    for (const KlNeighbor& m : *top) {
      if (static_cast<int>(m.doc) != queries[q] && exact[q].size() < kTop) exact[q].push_back(m.doc);
    }
  }
  std::printf("exact KL search: %.2f ms a query\n", 1e3 * Seconds(start) / queries.size());

  // The embedding, fitted as the index fits it (on its first 2,048 models).
  start = std::chrono::steady_clock::now();
  const std::size_t fit = std::min<std::size_t>(n, KlInvertedIndex::kEmbeddingFitModels);
  auto embedding = HistogramEmbedding::Fit(
      absl::MakeConstSpan(histograms.data(), fit), v, kDim, /*seed=*/1);
  if (!embedding.ok()) return 1;
  std::vector<float> x(static_cast<std::size_t>(n) * kDim);
  ParallelFor(n, threads, [&](std::size_t i) {
    embedding->Embed(histograms[i].words, histograms[i].weights, x.data() + i * kDim);
  });
  std::printf("embedding fitted and %d models embedded in %.1f s\n", n, Seconds(start));
  std::vector<faiss::Index::idx_t> ids(static_cast<std::size_t>(n) * c);
  std::vector<float> distances(ids.size());

  // The hand-written scan: squared distances to every model, C smallest.
  {
    start = std::chrono::steady_clock::now();
    std::vector<std::pair<float, faiss::Index::idx_t>> scored(n);
    for (int q : queries) {
      const float* a = x.data() + static_cast<std::size_t>(q) * kDim;
      for (int j = 0; j < n; ++j) {
        const float* b = x.data() + static_cast<std::size_t>(j) * kDim;
        float d = 0;
        for (int k = 0; k < kDim; ++k) d += (a[k] - b[k]) * (a[k] - b[k]);
        scored[j] = {d, j};
      }
      std::partial_sort(scored.begin(), scored.begin() + c, scored.end());
      for (int r = 0; r < c; ++r) ids[static_cast<std::size_t>(q) * c + r] = scored[r].second;
    }
    const double per_query = Seconds(start) / queries.size();
    Report("scan (hand-written, 1 thr)", 0, per_query * n, 0, Recall(exact, queries, ids, c), 1.0,
           n);
  }
  // Faiss, exact: every model's C nearest in one batched search.
  std::vector<faiss::Index::idx_t> reference;
  {
    start = std::chrono::steady_clock::now();
    faiss::IndexFlatL2 flat(kDim);
    flat.add(n, x.data());
    const double build = Seconds(start);
    start = std::chrono::steady_clock::now();
    flat.search(n, x.data(), c, distances.data(), ids.data());
    Report("faiss IndexFlatL2", build, Seconds(start), flat.codes.size() / 1048576.0,
           Recall(exact, queries, ids, c), 1.0, n);
    reference = ids;
  }
  // Faiss, HNSW over the embeddings, at several search depths.
  {
    start = std::chrono::steady_clock::now();
    faiss::IndexHNSWFlat hnsw(kDim, absl::GetFlag(FLAGS_hnsw_m));
    hnsw.hnsw.efConstruction = 40;
    hnsw.add(n, x.data());
    const double build = Seconds(start);
    const double mb = (static_cast<faiss::IndexFlatCodes*>(hnsw.storage)->codes.size() +
                       hnsw.hnsw.neighbors.size() * sizeof(hnsw.hnsw.neighbors[0]) +
                       hnsw.hnsw.offsets.size() * sizeof(hnsw.hnsw.offsets[0]) +
                       hnsw.hnsw.levels.size() * sizeof(hnsw.hnsw.levels[0])) /
                      1048576.0;
    for (int ef : {64, 128, 256}) {
      hnsw.hnsw.efSearch = std::max(ef, c);
      start = std::chrono::steady_clock::now();
      hnsw.search(n, x.data(), c, distances.data(), ids.data());
      const std::string name = "faiss HNSW M=" + std::to_string(absl::GetFlag(FLAGS_hnsw_m)) +
                               " ef=" + std::to_string(hnsw.hnsw.efSearch);
      Report(name.c_str(), build, Seconds(start), mb, Recall(exact, queries, ids, c),
             Agreement(reference, ids, c), n);
    }
  }
  // Faiss, IVF: sqrt(N) lists, trained on 64 models a list (Faiss wants at
  // least 39).
  {
    const int lists = std::max(1, static_cast<int>(std::sqrt(static_cast<double>(n))));
    start = std::chrono::steady_clock::now();
    faiss::IndexFlatL2 quantizer(kDim);
    faiss::IndexIVFFlat ivf(&quantizer, kDim, lists);
    ivf.train(std::min<faiss::Index::idx_t>(n, 64 * lists), x.data());
    ivf.add(n, x.data());
    const double build = Seconds(start);
    const double mb = (n * (kDim * sizeof(float) + sizeof(faiss::Index::idx_t)) +
                       quantizer.codes.size()) / 1048576.0;
    for (int probes : {8, 16, 32}) {
      ivf.nprobe = probes;
      start = std::chrono::steady_clock::now();
      ivf.search(n, x.data(), c, distances.data(), ids.data());
      const std::string name =
          "faiss IVF " + std::to_string(lists) + " nprobe=" + std::to_string(probes);
      Report(name.c_str(), build, Seconds(start), mb, Recall(exact, queries, ids, c),
             Agreement(reference, ids, c), n);
    }
  }
  return 0;
}

}  // namespace
}  // namespace meshseek

int main(int argc, char** argv) {
  absl::ParseCommandLine(argc, argv);
  return meshseek::Run();
}
