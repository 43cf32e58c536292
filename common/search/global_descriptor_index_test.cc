#include "common/search/global_descriptor_index.h"

#include <gtest/gtest.h>

#include <random>

namespace meshseek {
namespace {

// Random valid LFD descriptors: the coefficient bytes random, padding zero
// (ValidateLfdDescriptor's form).
std::vector<uint8_t> RandomLfd(uint32_t seed) {
  std::mt19937 rng(seed);
  std::vector<uint8_t> d(kLfdDescriptorBytes, 0);
  for (std::size_t i = 0; i < d.size(); ++i) {
    if (i % 48 < 45) d[i] = static_cast<uint8_t>(rng() % 64);
  }
  return d;
}

TEST(GlobalDescriptorIndexTest, OnlyGlobalMethodsWithTheirOwnSize) {
  EXPECT_FALSE(GlobalDescriptorIndex::Create(FeatureMethod::kDldSift, 128).ok());
  EXPECT_FALSE(GlobalDescriptorIndex::Create(FeatureMethod::kLfd, 100).ok());
  auto index = GlobalDescriptorIndex::Create(FeatureMethod::kLfd, kLfdDescriptorBytes);
  ASSERT_TRUE(index.ok()) << index.status();
  const std::vector<uint8_t> short_descriptor(10, 0);
  EXPECT_FALSE(index->Upsert(0, short_descriptor).ok());
  EXPECT_FALSE(index->Distances(short_descriptor, 1).ok());
}

TEST(GlobalDescriptorIndexTest, SearchIsTheExhaustiveRankingAndSurvivesRemovals) {
  auto index = GlobalDescriptorIndex::Create(FeatureMethod::kLfd, kLfdDescriptorBytes);
  ASSERT_TRUE(index.ok());
  std::vector<std::vector<uint8_t>> data;
  for (uint32_t i = 0; i < 40; ++i) {
    data.push_back(RandomLfd(i));
    ASSERT_TRUE(index->Upsert(i, data.back()).ok());
  }
  ASSERT_TRUE(index->Upsert(7, data[7]).ok());  // an upsert does not duplicate
  EXPECT_EQ(index->size(), 40u);
  EXPECT_TRUE(index->Remove(3));
  EXPECT_FALSE(index->Remove(3));
  const std::vector<uint8_t> query = data[11];
  auto found = index->Search(query, 5, 2);
  ASSERT_TRUE(found.ok());
  ASSERT_GE(found->size(), 5u);
  EXPECT_EQ((*found)[0].doc, 11u);
  EXPECT_EQ((*found)[0].distance, 0.0f);
  // Against brute force over what is left.
  std::vector<std::pair<float, uint32_t>> expected;
  for (uint32_t i = 0; i < 40; ++i) {
    if (i != 3) expected.push_back({LfdDistance(query.data(), data[i].data()), i});
  }
  std::sort(expected.begin(), expected.end());
  for (std::size_t r = 0; r < 5; ++r) {
    EXPECT_EQ((*found)[r].doc, expected[r].second);
    EXPECT_EQ((*found)[r].distance, expected[r].first);
  }
  const std::vector<uint32_t> some = {20, 11, 0};
  const auto to_some = index->DistancesTo(query, some);
  ASSERT_TRUE(to_some.ok());
  for (std::size_t i = 0; i < some.size(); ++i) {
    EXPECT_EQ((*to_some)[i].doc, some[i]);
    EXPECT_EQ((*to_some)[i].distance, LfdDistance(query.data(), data[some[i]].data()));
  }
  EXPECT_EQ(index->DistancesTo(query, std::vector<uint32_t>{3}).status().code(),
            absl::StatusCode::kNotFound);
  std::size_t visited = 0;
  index->ForEach([&](uint32_t doc, absl::Span<const uint8_t> bytes) {
    ++visited;
    EXPECT_TRUE(std::equal(bytes.begin(), bytes.end(), data[doc].begin()));
  });
  EXPECT_EQ(visited, 39u);
}

TEST(GlobalDescriptorIndexTest, SearchByViewRanksByEachModelsNearestView) {
  auto index = GlobalDescriptorIndex::Create(FeatureMethod::kLfd, kLfdDescriptorBytes);
  ASSERT_TRUE(index.ok());
  std::vector<std::vector<uint8_t>> data;
  for (uint32_t i = 0; i < 50; ++i) {
    data.push_back(RandomLfd(100 + i));
    ASSERT_TRUE(index->Upsert(i, data.back()).ok());
  }
  // Model 23's view 61 as the picture: model 23 first, at distance 0.
  const absl::Span<const uint8_t> view(data[23].data() + 61 * kLfdViewStride, kLfdViewStride);
  const auto found = index->SearchView(view, 5, 2);
  ASSERT_TRUE(found.ok()) << found.status();
  ASSERT_GE(found->size(), 5u);
  EXPECT_EQ((*found)[0].doc, 23u);
  EXPECT_EQ((*found)[0].distance, 0);
  // Every distance is LfdViewDistance, in ascending order.
  for (std::size_t r = 0; r < found->size(); ++r) {
    EXPECT_EQ((*found)[r].distance, LfdViewDistance(view.data(), data[(*found)[r].doc].data()));
    if (r > 0) EXPECT_LE((*found)[r - 1].distance, (*found)[r].distance);
  }
  EXPECT_EQ(index->SearchView(absl::MakeConstSpan(data[0].data(), 10), 5, 1).status().code(),
            absl::StatusCode::kInvalidArgument);
}

}  // namespace
}  // namespace meshseek
