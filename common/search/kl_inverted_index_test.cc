#include "common/search/kl_inverted_index.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <numeric>
#include <random>
#include <set>

#include "common/bof/kl_divergence.h"

namespace meshseek {
namespace {

using ::testing::HasSubstr;

constexpr float kInf = std::numeric_limits<float>::infinity();

// Dense histograms with about `used` of `bins` words non-zero, shaped like
// bag-of-features histograms: integer counts over a total, a few frequent
// words and many rare ones.
std::vector<std::vector<float>> CountHistograms(std::size_t count,
                                                std::size_t bins,
                                                std::size_t descriptors,
                                                uint32_t seed) {
  std::mt19937 rng(seed);
  std::vector<std::vector<float>> out(count, std::vector<float>(bins, 0.0f));
  for (auto& h : out) {
    // Each model prefers its own region of the vocabulary (Zipf-like).
    const std::size_t centre = rng() % bins;
    std::vector<uint32_t> counts(bins, 0);
    for (std::size_t d = 0; d < descriptors; ++d) {
      const double u = std::uniform_real_distribution<double>(0.0, 1.0)(rng);
      const auto offset = static_cast<std::size_t>(std::pow(u, 3.0) * bins);
      ++counts[(centre + offset) % bins];
    }
    for (std::size_t k = 0; k < bins; ++k) {
      h[k] = static_cast<float>(counts[k]) / static_cast<float>(descriptors);
    }
  }
  return out;
}

KlInvertedIndex MakeIndex(const std::vector<std::vector<float>>& dense,
                          const KlDivergenceOptions& options = {}) {
  absl::StatusOr<KlInvertedIndex> index =
      KlInvertedIndex::Create(static_cast<uint32_t>(dense[0].size()), options);
  EXPECT_TRUE(index.ok()) << index.status();
  for (std::size_t i = 0; i < dense.size(); ++i) {
    const absl::Status added = index->Upsert(static_cast<uint32_t>(i), SparseFromDense(dense[i]));
    EXPECT_TRUE(added.ok()) << added;
  }
  return *std::move(index);
}

std::vector<float> ByDoc(const std::vector<KlNeighbor>& neighbors, std::size_t n) {
  std::vector<float> out(n, -1.0f);
  for (const KlNeighbor& nb : neighbors) out[nb.doc] = nb.distance;
  return out;
}

// Ranking of row i of an n x n matrix: the others by (distance, index).
std::vector<std::size_t> Ranking(const std::vector<float>& matrix, std::size_t n, std::size_t i) {
  std::vector<std::size_t> order;
  for (std::size_t j = 0; j < n; ++j) {
    if (j != i) order.push_back(j);
  }
  std::stable_sort(order.begin(), order.end(), [&](std::size_t a, std::size_t b) {
    return matrix[i * n + a] < matrix[i * n + b];
  });
  return order;
}

TEST(KlInvertedIndexTest, EqualsThePairwiseCodeOnCountHistograms) {
  for (const std::size_t bins : {50u, 2000u}) {
    const auto dense = CountHistograms(120, bins, 2500, 7);
    const KlInvertedIndex index = MakeIndex(dense);
    std::vector<uint32_t> docs(dense.size());
    std::iota(docs.begin(), docs.end(), 0u);
    const absl::StatusOr<std::vector<float>> fast = index.DistanceMatrix(docs, 2);
    ASSERT_TRUE(fast.ok()) << fast.status();
    const absl::StatusOr<std::vector<float>> reference = SymmetricKlDistanceMatrix(dense, {}, 2);
    ASSERT_TRUE(reference.ok());
    const std::size_t n = dense.size();
    for (std::size_t i = 0; i < n * n; ++i) {
      EXPECT_NEAR((*fast)[i], (*reference)[i], 1e-5 * (*reference)[i] + 1e-6) << "entry " << i;
    }
    std::size_t identical_rankings = 0;
    for (std::size_t i = 0; i < n; ++i) {
      identical_rankings += Ranking(*fast, n, i) == Ranking(*reference, n, i);
    }
    EXPECT_EQ(identical_rankings, n) << "bins " << bins;
  }
}

TEST(KlInvertedIndexTest, EqualsThePairwiseCodeOnSmoothRandomHistograms) {
  // Non-count weights, a sum that is 1 only within float rounding, and
  // another epsilon.
  std::mt19937 rng(3);
  std::vector<std::vector<float>> dense(40, std::vector<float>(300));
  for (auto& h : dense) {
    double sum = 0.0;
    std::vector<double> raw(h.size());
    for (double& v : raw) {
      sum += v = std::uniform_real_distribution<double>(0, 1)(rng) < 0.6
                     ? 0.0
                     : std::uniform_real_distribution<double>(0, 1)(rng);
    }
    for (std::size_t k = 0; k < h.size(); ++k) h[k] = static_cast<float>(raw[k] / sum);
  }
  KlDivergenceOptions options;
  options.epsilon = 1e-6;
  const KlInvertedIndex index = MakeIndex(dense, options);
  for (std::size_t q = 0; q < dense.size(); q += 7) {
    const auto fast = index.Distances(SparseFromDense(dense[q]), 1);
    ASSERT_TRUE(fast.ok());
    const auto reference = SymmetricKlDistances(dense[q], dense, options, 1);
    ASSERT_TRUE(reference.ok());
    const std::vector<float> by_doc = ByDoc(*fast, dense.size());
    for (std::size_t j = 0; j < dense.size(); ++j) {
      EXPECT_NEAR(by_doc[j], (*reference)[j], 1e-5 * (*reference)[j] + 1e-6);
    }
  }
}

TEST(KlInvertedIndexTest, MatrixIsExactlySymmetricAndEqualsQueriesBitForBit) {
  const auto dense = CountHistograms(60, 400, 800, 11);
  const KlInvertedIndex index = MakeIndex(dense);
  std::vector<uint32_t> docs(dense.size());
  std::iota(docs.begin(), docs.end(), 0u);
  const auto matrix = index.DistanceMatrix(docs, 2);
  ASSERT_TRUE(matrix.ok());
  const std::size_t n = dense.size();
  for (std::size_t i = 0; i < n; ++i) {
    EXPECT_EQ((*matrix)[i * n + i], 0.0f);
    for (std::size_t j = 0; j < n; ++j) EXPECT_EQ((*matrix)[i * n + j], (*matrix)[j * n + i]);
    const auto row = index.Distances(SparseFromDense(dense[i]), 1);
    ASSERT_TRUE(row.ok());
    const std::vector<float> by_doc = ByDoc(*row, n);
    for (std::size_t j = 0; j < n; ++j) EXPECT_EQ(by_doc[j], (*matrix)[i * n + j]);
    // A model as its own query: exactly 0.
    EXPECT_EQ(by_doc[i], 0.0f);
  }
}

TEST(KlInvertedIndexTest, ResultsDoNotDependOnThreadsOrSegments) {
  // More models than one segment holds, so queries span two segments.
  const std::size_t n = KlInvertedIndex::kSegmentSlots + 300;
  const auto dense = CountHistograms(n, 64, 60, 5);
  const KlInvertedIndex index = MakeIndex(dense);
  EXPECT_EQ(index.size(), n);
  const SparseHistogram query = SparseFromDense(dense[17]);
  const auto one = index.Distances(query, 1);
  const auto two = index.Distances(query, 2);
  ASSERT_TRUE(one.ok() && two.ok());
  EXPECT_EQ(ByDoc(*one, n), ByDoc(*two, n));
  const auto reference = SymmetricKlDistances(dense[17], dense, {}, 2);
  ASSERT_TRUE(reference.ok());
  const std::vector<float> by_doc = ByDoc(*one, n);
  for (std::size_t j = 0; j < n; j += 97) {
    EXPECT_NEAR(by_doc[j], (*reference)[j], 1e-5 * (*reference)[j] + 1e-6);
  }
}

TEST(KlInvertedIndexTest, ManyDistinctWeightsOpenNewSegments) {
  // 200 models of 600 distinct random weights: more than the 65,536 value
  // ids of one segment.
  std::mt19937 rng(13);
  std::vector<std::vector<float>> dense(200, std::vector<float>(1500, 0.0f));
  for (auto& h : dense) {
    double sum = 0.0;
    std::vector<double> raw(h.size(), 0.0);
    for (int i = 0; i < 600; ++i) {
      raw[rng() % raw.size()] += std::uniform_real_distribution<double>(0.1, 1.0)(rng);
    }
    for (double v : raw) sum += v;
    for (std::size_t k = 0; k < h.size(); ++k) h[k] = static_cast<float>(raw[k] / sum);
  }
  const KlInvertedIndex index = MakeIndex(dense);
  std::vector<uint32_t> docs(dense.size());
  std::iota(docs.begin(), docs.end(), 0u);
  const auto matrix = index.DistanceMatrix(docs, 2);
  const auto reference = SymmetricKlDistanceMatrix(dense, {}, 2);
  ASSERT_TRUE(matrix.ok() && reference.ok());
  for (std::size_t i = 0; i < matrix->size(); ++i) {
    EXPECT_NEAR((*matrix)[i], (*reference)[i], 1e-5 * (*reference)[i] + 1e-6);
  }
  for (uint32_t doc : {0u, 150u, 199u}) EXPECT_EQ(DenseFromSparse(*index.Histogram(doc)), dense[doc]);
}

TEST(KlInvertedIndexTest, SearchReturnsTheNearestWithTies) {
  std::vector<std::vector<float>> dense = CountHistograms(30, 100, 500, 2);
  dense[20] = dense[3];  // an exact duplicate: tied with 3 for any query
  const KlInvertedIndex index = MakeIndex(dense);
  const SparseHistogram query = SparseFromDense(dense[3]);
  const auto all = index.Distances(query, 1);
  ASSERT_TRUE(all.ok());
  std::vector<KlNeighbor> sorted = *all;
  std::sort(sorted.begin(), sorted.end(), [](const KlNeighbor& a, const KlNeighbor& b) {
    return a.distance < b.distance || (a.distance == b.distance && a.doc < b.doc);
  });
  const auto top = index.Search(query, 1, 1);
  ASSERT_TRUE(top.ok());
  // Models 3 and 20 are both at distance 0: the tie comes back too.
  ASSERT_EQ(top->size(), 2u);
  EXPECT_EQ((*top)[0].doc, 3u);
  EXPECT_EQ((*top)[1].doc, 20u);
  EXPECT_EQ((*top)[1].distance, 0.0f);
  const auto top5 = index.Search(query, 5, 2);
  ASSERT_TRUE(top5.ok());
  ASSERT_EQ(top5->size(), 5u);
  for (std::size_t i = 0; i < 5; ++i) {
    EXPECT_EQ((*top5)[i].doc, sorted[i].doc);
    EXPECT_EQ((*top5)[i].distance, sorted[i].distance);
  }
  EXPECT_EQ(index.Search(query, 100, 1)->size(), 30u);
  EXPECT_THAT(std::string(index.Search(query, 0, 1).status().message()), HasSubstr("k must be"));
}

TEST(KlInvertedIndexTest, CandidatesAreReRankedWithExactDistancesAndFindTheNearest) {
  // Past kEmbeddingFitModels, so that the embedding is fitted.
  const std::size_t n = KlInvertedIndex::kEmbeddingFitModels + 904;
  const auto dense = CountHistograms(n, 500, 1500, 21);
  const KlInvertedIndex index = MakeIndex(dense);
  std::size_t found = 0, wanted = 0;
  for (std::size_t q = 0; q < 40; ++q) {
    // Fresh queries of the same kind, not members.
    const SparseHistogram query = SparseFromDense(CountHistograms(1, 500, 1500, 1000 + q)[0]);
    const auto exact = index.Search(query, 10, 1);
    const auto approximate = index.Search(query, 10, 2, /*candidates=*/n / 20);
    ASSERT_TRUE(exact.ok() && approximate.ok());
    const std::vector<float> all = ByDoc(*index.Distances(query, 1), n);
    for (const KlNeighbor& nb : *approximate) EXPECT_EQ(nb.distance, all[nb.doc]) << nb.doc;
    std::set<uint32_t> truth;
    for (std::size_t i = 0; i < 10; ++i) truth.insert((*exact)[i].doc);
    for (std::size_t i = 0; i < 10; ++i) found += truth.count((*approximate)[i].doc);
    wanted += 10;
  }
  // 5 % of the models as candidates: recall@10 measured 0.99+ here.
  EXPECT_GE(static_cast<double>(found) / wanted, 0.97);
  // More candidates than models: the exact answer.
  const SparseHistogram query = SparseFromDense(dense[5]);
  const auto exact = index.Search(query, 10, 1);
  const auto all_candidates = index.Search(query, 10, 1, n);
  ASSERT_EQ(exact->size(), all_candidates->size());
  for (std::size_t i = 0; i < exact->size(); ++i) {
    EXPECT_EQ((*exact)[i].doc, (*all_candidates)[i].doc);
    EXPECT_EQ((*exact)[i].distance, (*all_candidates)[i].distance);
  }
}

TEST(KlInvertedIndexTest, StoredModelsAsQueriesGiveTheirHistogramsAnswersBitForBit) {
  // Past the fit (candidates from the graph) and with churn: a replaced
  // model and a removed one.
  const std::size_t n = KlInvertedIndex::kEmbeddingFitModels + 100;
  const auto dense = CountHistograms(n + 1, 300, 1200, 5);
  KlInvertedIndex index = MakeIndex(std::vector<std::vector<float>>(dense.begin(), dense.begin() + n));
  ASSERT_TRUE(index.has_embedding());
  ASSERT_TRUE(index.Upsert(7, SparseFromDense(dense[n])).ok());
  ASSERT_TRUE(index.Remove(9));
  for (uint32_t doc : {0u, 7u, 1000u, static_cast<uint32_t>(n - 1)}) {
    const SparseHistogram histogram = *index.Histogram(doc);
    for (std::size_t candidates : {std::size_t{0}, std::size_t{50}}) {
      const auto given = index.Search(histogram, 20, 1, candidates);
      const auto stored = index.SearchStored(doc, 20, 1, candidates);
      ASSERT_TRUE(given.ok() && stored.ok()) << stored.status();
      ASSERT_EQ(given->size(), stored->size());
      EXPECT_EQ((*stored)[0].doc, doc);
      for (std::size_t i = 0; i < given->size(); ++i) {
        EXPECT_EQ((*given)[i].doc, (*stored)[i].doc);
        EXPECT_EQ((*given)[i].distance, (*stored)[i].distance);
      }
    }
    const std::vector<uint32_t> docs = {3, doc, 2000, 7};
    const auto given = index.DistancesTo(histogram, docs, 1);
    const auto stored = index.DistancesFromStored(doc, docs, 1);
    ASSERT_TRUE(given.ok() && stored.ok());
    for (std::size_t i = 0; i < docs.size(); ++i) {
      EXPECT_EQ((*given)[i].distance, (*stored)[i].distance);
    }
  }
  EXPECT_EQ(index.SearchStored(9, 5, 1).status().code(), absl::StatusCode::kNotFound);
  EXPECT_EQ(index.DistancesFromStored(9, std::vector<uint32_t>{0}, 1).status().code(),
            absl::StatusCode::kNotFound);
}

// Every answer of `a` and `b` over the docs < n, bit for bit.
void ExpectSameAnswers(const KlInvertedIndex& a, const KlInvertedIndex& b,
                       const std::vector<std::vector<float>>& queries, std::size_t n) {
  ASSERT_EQ(a.size(), b.size());
  std::vector<uint32_t> docs;
  for (uint32_t d = 0; d < n; ++d) {
    if (a.Contains(d)) docs.push_back(d);
  }
  for (const auto& dense : queries) {
    const SparseHistogram q = SparseFromDense(dense);
    EXPECT_EQ(ByDoc(*a.Distances(q, 2), n), ByDoc(*b.Distances(q, 1), n));
    const auto x = a.Search(q, 10, 1, 40), y = b.Search(q, 10, 2, 40);
    ASSERT_EQ(x->size(), y->size());
    for (std::size_t i = 0; i < x->size(); ++i) {
      EXPECT_EQ((*x)[i].doc, (*y)[i].doc);
      EXPECT_EQ((*x)[i].distance, (*y)[i].distance);
    }
    EXPECT_EQ(ByDoc(*a.DistancesTo(q, docs, 1), n), ByDoc(*b.DistancesTo(q, docs, 2), n));
  }
  const std::vector<uint32_t> some(docs.begin(), docs.begin() + std::min<std::size_t>(docs.size(), 30));
  EXPECT_EQ(*a.DistanceMatrix(some, 1), *b.DistanceMatrix(some, 2));
  for (uint32_t d : some) {
    EXPECT_EQ(a.Histogram(d)->words, b.Histogram(d)->words);
    EXPECT_EQ(a.Histogram(d)->weights, b.Histogram(d)->weights);
  }
}

TEST(KlInvertedIndexTest, AForwardFileWithoutPostingsAnswersBitForBitAsMemory) {
  // Past the fit, with replacements and removals enough to compact segments
  // and rewrite the forward file (its dead entries past a million).
  const std::size_t n = 1600;
  const auto first = CountHistograms(n, 1000, 2400, 31);
  const auto second = CountHistograms(n, 1000, 2400, 32);
  KlIndexStorage storage;
  storage.forward_dir = ::testing::TempDir() + "/forward";
  storage.postings_max_models = 500;
  KlInvertedIndex memory = *KlInvertedIndex::Create(1000);
  KlInvertedIndex file = *KlInvertedIndex::Create(1000, {}, storage);
  for (KlInvertedIndex* index : {&memory, &file}) {
    for (uint32_t d = 0; d < n; ++d) ASSERT_TRUE(index->Upsert(d, SparseFromDense(first[d])).ok());
  }
  EXPECT_TRUE(memory.has_postings());
  EXPECT_FALSE(file.has_postings());
  EXPECT_GT(file.FileBytes(), 0u);
  EXPECT_EQ(memory.FileBytes(), 0u);
  EXPECT_LT(file.MemoryBytes(), memory.MemoryBytes() / 3);
  const std::vector<std::vector<float>> queries = {first[3], second[7], CountHistograms(1, 1000, 2400, 99)[0]};
  ExpectSameAnswers(memory, file, queries, n);
  const uint64_t grown = file.FileBytes();
  for (KlInvertedIndex* index : {&memory, &file}) {
    for (uint32_t d = 0; d < n; ++d) ASSERT_TRUE(index->Upsert(d, SparseFromDense(second[d])).ok());
    for (uint32_t d = 0; d < n; ++d) {
      if (d % 8 != 0) ASSERT_TRUE(index->Remove(d));
    }
  }
  EXPECT_LT(file.FileBytes(), grown);  // rewritten without the dead entries
  ExpectSameAnswers(memory, file, queries, n);
  KlIndexStorage bad;
  bad.postings_max_models = 0;
  EXPECT_EQ(KlInvertedIndex::Create(10, {}, bad).status().code(), absl::StatusCode::kInvalidArgument);
  bad = {};
  bad.forward_dir = "/proc/no/such/folder";
  EXPECT_EQ(KlInvertedIndex::Create(10, {}, bad).status().code(), absl::StatusCode::kInternal);
}

TEST(KlInvertedIndexTest, CandidatesBeforeTheEmbeddingIsFittedSearchExactly) {
  const auto dense = CountHistograms(300, 200, 600, 22);
  const KlInvertedIndex index = MakeIndex(dense);
  const SparseHistogram query = SparseFromDense(CountHistograms(1, 200, 600, 23)[0]);
  const auto exact = index.Search(query, 10, 1);
  const auto with_candidates = index.Search(query, 10, 1, /*candidates=*/20);
  ASSERT_TRUE(exact.ok() && with_candidates.ok());
  ASSERT_EQ(exact->size(), with_candidates->size());
  for (std::size_t i = 0; i < exact->size(); ++i) {
    EXPECT_EQ((*exact)[i].doc, (*with_candidates)[i].doc);
  }
}

TEST(KlInvertedIndexTest, UpsertReplacesAndRemoveCompacts) {
  const auto dense = CountHistograms(40, 80, 300, 9);
  KlInvertedIndex index = MakeIndex(dense);
  // Replace model 5 by model 6's histogram: it becomes 6's twin.
  ASSERT_TRUE(index.Upsert(5, SparseFromDense(dense[6])).ok());
  EXPECT_EQ(index.size(), 40u);
  const auto twin = index.Distances(SparseFromDense(dense[6]), 1);
  EXPECT_EQ(ByDoc(*twin, 40)[5], 0.0f);
  // Removing most models rewrites the segment; the rest are unchanged.
  const auto before = index.Distances(SparseFromDense(dense[1]), 1);
  for (uint32_t doc = 10; doc < 40; ++doc) EXPECT_TRUE(index.Remove(doc));
  EXPECT_FALSE(index.Remove(10));
  EXPECT_EQ(index.size(), 10u);
  EXPECT_FALSE(index.Contains(10));
  const auto after = index.Distances(SparseFromDense(dense[1]), 1);
  ASSERT_EQ(after->size(), 10u);
  const std::vector<float> was = ByDoc(*before, 40);
  for (const KlNeighbor& nb : *after) EXPECT_EQ(nb.distance, was[nb.doc]) << nb.doc;
  // Histograms read back are the ones stored.
  const auto stored = index.Histogram(7);
  ASSERT_TRUE(stored.ok());
  EXPECT_EQ(DenseFromSparse(*stored), dense[7]);
  EXPECT_EQ(index.Histogram(30).status().code(), absl::StatusCode::kNotFound);
  std::size_t visited = 0;
  index.ForEach([&](uint32_t doc, const SparseHistogram& h) {
    ++visited;
    EXPECT_EQ(DenseFromSparse(h), doc == 5 ? dense[6] : dense[doc]) << doc;
  });
  EXPECT_EQ(visited, 10u);
}

TEST(KlInvertedIndexTest, ModelsWithoutFeaturesAreInfinitelyFar) {
  auto dense = CountHistograms(5, 20, 100, 4);
  KlInvertedIndex index = MakeIndex(dense);
  SparseHistogram empty;
  empty.vocabulary = 20;
  ASSERT_TRUE(index.Upsert(9, empty).ok());
  const auto from_model = index.Distances(SparseFromDense(dense[0]), 1);
  for (const KlNeighbor& nb : *from_model) {
    if (nb.doc == 9) {
      EXPECT_EQ(nb.distance, kInf);
    }
  }
  const auto from_empty = index.Distances(empty, 1);
  for (const KlNeighbor& nb : *from_empty) EXPECT_EQ(nb.distance, kInf);
  const auto matrix = index.DistanceMatrix({0, 9, 1}, 1);
  ASSERT_TRUE(matrix.ok());
  EXPECT_THAT(*matrix, ::testing::ElementsAre(0.0f, kInf, (*matrix)[2], kInf, 0.0f, kInf,
                                              (*matrix)[2], kInf, 0.0f));
}

TEST(KlInvertedIndexTest, DistancesToAFewModelsAreTheScansBitForBit) {
  // Among them an empty model and a removed one.
  auto dense = CountHistograms(300, 120, 2000, 21);
  KlInvertedIndex index = MakeIndex(dense);
  SparseHistogram empty;
  empty.vocabulary = 120;
  ASSERT_TRUE(index.Upsert(400, empty).ok());
  ASSERT_TRUE(index.Remove(17));
  for (uint32_t query : {0u, 150u, 299u}) {
    const SparseHistogram q = SparseFromDense(dense[query]);
    const std::vector<float> scan = ByDoc(*index.Distances(q, 2), 401);
    const std::vector<uint32_t> docs = {299, 3, 400, query, 250, 3};
    const auto some = index.DistancesTo(q, docs, 2);
    ASSERT_TRUE(some.ok()) << some.status();
    ASSERT_EQ(some->size(), docs.size());
    for (std::size_t i = 0; i < docs.size(); ++i) {
      EXPECT_EQ((*some)[i].doc, docs[i]);
      EXPECT_EQ((*some)[i].distance, scan[docs[i]]) << docs[i];
    }
    EXPECT_EQ((*some)[2].distance, kInf);
  }
  const auto from_empty = index.DistancesTo(empty, std::vector<uint32_t>{0, 400}, 1);
  ASSERT_TRUE(from_empty.ok());
  EXPECT_EQ((*from_empty)[0].distance, kInf);
  EXPECT_EQ((*from_empty)[1].distance, kInf);
  const auto removed = index.DistancesTo(SparseFromDense(dense[0]), std::vector<uint32_t>{17}, 1);
  EXPECT_EQ(removed.status().code(), absl::StatusCode::kNotFound);
  EXPECT_THAT(removed.status().message(), HasSubstr("model 17"));
}

TEST(KlInvertedIndexTest, RejectsBadInputAndLeavesTheIndexUnchanged) {
  EXPECT_FALSE(KlInvertedIndex::Create(0).ok());
  KlDivergenceOptions bad;
  bad.epsilon = 0;
  EXPECT_FALSE(KlInvertedIndex::Create(10, bad).ok());
  auto index = KlInvertedIndex::Create(10);
  ASSERT_TRUE(index.ok());
  ASSERT_TRUE(index->Upsert(1, {10, {2}, {1.0f}}).ok());
  const absl::Status wrong_size = index->Upsert(1, {12, {2}, {1.0f}});
  EXPECT_THAT(std::string(wrong_size.message()), HasSubstr("model 1 has vocabulary 12"));
  const absl::Status not_normalised = index->Upsert(1, {10, {2, 3}, {0.5f, 0.2f}});
  EXPECT_THAT(std::string(not_normalised.message()), HasSubstr("model 1 sums to 0.7"));
  EXPECT_EQ(index->size(), 1u);
  EXPECT_EQ(DenseFromSparse(*index->Histogram(1))[2], 1.0f);
  EXPECT_THAT(std::string(index->Distances({10, {11}, {1.0f}}, 1).status().message()),
              HasSubstr("query, entry 0: word 11"));
  EXPECT_EQ(index->DistanceMatrix({1, 2}, 1).status().code(), absl::StatusCode::kNotFound);
}

}  // namespace
}  // namespace meshseek
