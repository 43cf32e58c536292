#include "common/search/candidate_index.h"

#include <algorithm>
#include <random>
#include <vector>

#include "gtest/gtest.h"

namespace meshseek {
namespace {

constexpr int kDim = 16;

std::vector<float> RandomVectors(std::size_t n, uint32_t seed) {
  std::mt19937 rng(seed);
  std::normal_distribution<float> normal;
  std::vector<float> v(n * kDim);
  for (float& x : v) x = normal(rng);
  return v;
}

// The exact k nearest docs of row `q` among the live `docs` by squared L2.
std::vector<uint32_t> Exact(const std::vector<float>& v, const float* q,
                            const std::vector<uint32_t>& docs, std::size_t k) {
  std::vector<std::pair<float, uint32_t>> scored;
  for (uint32_t d : docs) {
    float s = 0;
    for (int j = 0; j < kDim; ++j) s += (v[d * kDim + j] - q[j]) * (v[d * kDim + j] - q[j]);
    scored.emplace_back(s, d);
  }
  std::sort(scored.begin(), scored.end());
  std::vector<uint32_t> out;
  for (std::size_t i = 0; i < std::min(k, scored.size()); ++i) out.push_back(scored[i].second);
  return out;
}

TEST(CandidateIndex, FindsTheExactNearestOnSmallSets) {
  const std::size_t n = 2000;
  const std::vector<float> v = RandomVectors(n, 1);
  CandidateIndex index = *CandidateIndex::Create(kDim);
  std::vector<uint32_t> docs;
  for (uint32_t d = 0; d < n; ++d) {
    index.Add(d, absl::MakeConstSpan(&v[d * kDim], kDim));
    docs.push_back(d);
  }
  EXPECT_EQ(index.size(), n);
  std::size_t found = 0, asked = 0;
  for (uint32_t q = 0; q < n; q += 40) {
    const std::vector<Candidate> got = index.Nearest(absl::MakeConstSpan(&v[q * kDim], kDim), 10);
    ASSERT_EQ(got.size(), 10u);
    EXPECT_EQ(got[0].doc, q);  // itself, at distance 0
    EXPECT_EQ(got[0].distance, 0.0f);
    for (std::size_t i = 1; i < got.size(); ++i) EXPECT_LE(got[i - 1].distance, got[i].distance);
    const std::vector<uint32_t> exact = Exact(v, &v[q * kDim], docs, 10);
    for (const Candidate& c : got) found += std::count(exact.begin(), exact.end(), c.doc);
    asked += 10;
  }
  EXPECT_GE(static_cast<double>(found) / asked, 0.97);
}

TEST(CandidateIndex, RemovedAndReplacedDocsAreNeverProposedStale) {
  const std::size_t n = 600;
  const std::vector<float> v = RandomVectors(2 * n, 2);
  CandidateIndex index = *CandidateIndex::Create(kDim);
  for (uint32_t d = 0; d < n; ++d) index.Add(d, absl::MakeConstSpan(&v[d * kDim], kDim));
  // Replace the even docs with new vectors, remove every third odd one:
  // enough churn to rebuild the graph on the way.
  std::vector<uint32_t> live;
  for (uint32_t d = 0; d < n; ++d) {
    if (d % 2 == 0) {
      index.Add(d, absl::MakeConstSpan(&v[(n + d) * kDim], kDim));
    } else if (d % 3 == 0) {
      EXPECT_TRUE(index.Remove(d));
      continue;
    }
    live.push_back(d);
  }
  EXPECT_FALSE(index.Remove(3));
  EXPECT_EQ(index.size(), live.size());
  for (uint32_t d : {0u, 2u, 100u}) {
    const std::vector<Candidate> got =
        index.Nearest(absl::MakeConstSpan(&v[(n + d) * kDim], kDim), 5);
    ASSERT_EQ(got.size(), 5u);
    EXPECT_EQ(got[0].doc, d);  // the replacement's own vector
    EXPECT_EQ(got[0].distance, 0.0f);
    for (const Candidate& c : got) {
      EXPECT_TRUE(std::count(live.begin(), live.end(), c.doc)) << c.doc;
    }
  }
  EXPECT_EQ(*index.Vector(2), std::vector<float>(&v[(n + 2) * kDim], &v[(n + 3) * kDim]));
  EXPECT_FALSE(index.Vector(3).ok());
  // Asking for more than are live gives every live doc once.
  const std::vector<Candidate> all = index.Nearest(absl::MakeConstSpan(&v[0], kDim), 10 * n);
  EXPECT_EQ(all.size(), live.size());
}

TEST(CandidateIndex, TheSameAddsGiveTheSameAnswers) {
  const std::size_t n = 1500;
  const std::vector<float> v = RandomVectors(n, 3);
  CandidateIndex a = *CandidateIndex::Create(kDim);
  CandidateIndex b = *CandidateIndex::Create(kDim);
  for (uint32_t d = 0; d < n; ++d) {
    a.Add(d, absl::MakeConstSpan(&v[d * kDim], kDim));
    b.Add(d, absl::MakeConstSpan(&v[d * kDim], kDim));
  }
  for (uint32_t q = 0; q < n; q += 97) {
    const auto x = a.Nearest(absl::MakeConstSpan(&v[q * kDim], kDim), 20);
    const auto y = b.Nearest(absl::MakeConstSpan(&v[q * kDim], kDim), 20);
    ASSERT_EQ(x.size(), y.size());
    for (std::size_t i = 0; i < x.size(); ++i) {
      EXPECT_EQ(x[i].doc, y[i].doc);
      EXPECT_EQ(x[i].distance, y[i].distance);
    }
  }
}

TEST(CandidateIndex, RefusesBadOptions) {
  EXPECT_FALSE(CandidateIndex::Create(0).ok());
  CandidateIndexOptions options;
  options.links = 2;
  EXPECT_FALSE(CandidateIndex::Create(kDim, options).ok());
  options = {};
  options.build_breadth = 8;  // below links
  EXPECT_FALSE(CandidateIndex::Create(kDim, options).ok());
  options = {};
  options.search_breadth = 0;
  EXPECT_FALSE(CandidateIndex::Create(kDim, options).ok());
  CandidateIndex empty = *CandidateIndex::Create(kDim);
  std::vector<float> q(kDim, 0.0f);
  EXPECT_TRUE(empty.Nearest(q, 5).empty());
}

}  // namespace
}  // namespace meshseek
