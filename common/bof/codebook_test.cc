#include "common/bof/codebook.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <cstring>
#include <limits>
#include <random>
#include <string>
#include <vector>

#include "common/base/hash.h"

namespace meshseek {
namespace {

constexpr std::size_t kDim = 128;  // a SIFT descriptor

using ::testing::HasSubstr;

std::vector<uint8_t> RandomDescriptors(std::size_t count, std::size_t dim, uint32_t seed) {
  std::mt19937 rng(seed);
  std::vector<uint8_t> values(count * dim);
  for (uint8_t& v : values) v = static_cast<uint8_t>(rng() % 256);
  return values;
}

Codebook RandomCodebook(std::size_t size, std::size_t dim, uint32_t seed) {
  std::mt19937 rng(seed);
  std::vector<float> centroids(size * dim);
  for (float& v : centroids) v = static_cast<float>(rng() % 25600) / 100.0f;
  return Codebook::FromCentroids(std::move(centroids), dim).value();
}

// The nearest centroid by definition, in double.
uint32_t BruteForceNearest(const uint8_t* x, const Codebook& codebook) {
  uint32_t best = 0;
  double best_distance = std::numeric_limits<double>::infinity();
  for (std::size_t c = 0; c < codebook.size(); ++c) {
    double d2 = 0.0;
    for (std::size_t d = 0; d < codebook.dim(); ++d) {
      const double e = x[d] - static_cast<double>(codebook.centroids()[c * codebook.dim() + d]);
      d2 += e * e;
    }
    if (d2 < best_distance) best_distance = d2, best = static_cast<uint32_t>(c);
  }
  return best;
}

TEST(CodebookTest, NearestCentroidsEqualBruteForce) {
  const Codebook codebook = RandomCodebook(100, kDim, 1);
  const std::vector<uint8_t> descriptors = RandomDescriptors(500, kDim, 2);
  const absl::StatusOr<std::vector<uint32_t>> labels =
      codebook.NearestCentroids(descriptors.data(), 500);
  ASSERT_TRUE(labels.ok()) << labels.status();
  for (std::size_t i = 0; i < 500; ++i) {
    EXPECT_EQ((*labels)[i], BruteForceNearest(&descriptors[i * kDim], codebook))
        << "descriptor " << i;
  }
}

TEST(CodebookTest, EncodeIsTheNormalisedHistogramOfNearestWords) {
  const Codebook codebook = RandomCodebook(50, kDim, 3);
  const std::size_t count = 777;
  const std::vector<uint8_t> descriptors = RandomDescriptors(count, kDim, 4);
  const absl::StatusOr<std::vector<float>> histogram =
      codebook.Encode(descriptors.data(), count, kDim);
  ASSERT_TRUE(histogram.ok()) << histogram.status();
  ASSERT_EQ(histogram->size(), 50u);
  std::vector<double> expected(50, 0.0);
  for (std::size_t i = 0; i < count; ++i) {
    expected[BruteForceNearest(&descriptors[i * kDim], codebook)] += 1.0 / count;
  }
  double sum = 0.0;
  for (std::size_t w = 0; w < 50; ++w) {
    EXPECT_NEAR((*histogram)[w], expected[w], 1e-6) << "word " << w;
    sum += (*histogram)[w];
  }
  EXPECT_NEAR(sum, 1.0, 1e-5);
}

TEST(CodebookTest, EmptyDescriptorSetIsAnError) {
  const Codebook codebook = RandomCodebook(4, 8, 5);
  const uint8_t unused[8] = {};
  const absl::StatusOr<std::vector<float>> histogram = codebook.Encode(unused, 0, kDim);
  EXPECT_EQ(histogram.status().code(), absl::StatusCode::kInvalidArgument);
  EXPECT_THAT(std::string(histogram.status().message()), HasSubstr("empty descriptor set"));
  EXPECT_THAT(std::string(codebook.NearestCentroids(nullptr, 3).status().message()),
              HasSubstr("null"));
}

TEST(CodebookTest, TrainLearnsTheRequestedVocabulary) {
  const std::vector<uint8_t> descriptors = RandomDescriptors(2000, kDim, 6);
  KMeansOptions options;
  options.num_centroids = 16;
  options.min_points_per_centroid = 1;
  KMeansReport report;
  const absl::StatusOr<Codebook> codebook =
      Codebook::Train(descriptors.data(), 2000, kDim, options, &report);
  ASSERT_TRUE(codebook.ok()) << codebook.status();
  EXPECT_EQ(codebook->size(), 16u);
  EXPECT_EQ(codebook->dim(), kDim);
  EXPECT_EQ(report.training_points, 2000u);
  // Every word is used: k-means leaves no cluster empty on such data.
  const std::vector<float> histogram = codebook->Encode(descriptors.data(), 2000, kDim).value();
  for (float h : histogram) EXPECT_GT(h, 0.0f);
  // Blocks of descriptors on several threads (a query's encoding): the same.
  const std::vector<uint8_t> many = RandomDescriptors(9000, kDim, 7);
  EXPECT_EQ(codebook->Encode(many.data(), 9000, kDim).value(),
            codebook->Encode(many.data(), 9000, kDim, /*num_threads=*/3).value());

  options.num_centroids = 3000;
  EXPECT_THAT(
      std::string(Codebook::Train(descriptors.data(), 2000, kDim, options).status().message()),
      HasSubstr("got 2000 training points for 3000 centroids"));
}

TEST(CodebookTest, FromCentroidsValidates) {
  EXPECT_THAT(std::string(Codebook::FromCentroids({1, 2, 3}, 0).status().message()),
              HasSubstr("dim must be >= 1"));
  EXPECT_THAT(std::string(Codebook::FromCentroids({1, 2, 3}, 2).status().message()),
              HasSubstr("got 3 centroid values, not a positive multiple of dim 2"));
  EXPECT_THAT(std::string(Codebook::FromCentroids({}, 2).status().message()),
              HasSubstr("got 0 centroid values"));
  EXPECT_THAT(std::string(Codebook::FromCentroids({1, std::nanf(""), 3, 4}, 2).status().message()),
              HasSubstr("centroid 0, coordinate 1 is nan"));
}

TEST(CodebookTest, SerializationRoundTripsExactly) {
  const Codebook codebook = RandomCodebook(37, 9, 7);
  const std::string bytes = codebook.Serialize();
  EXPECT_EQ(bytes.size(), 24 + 37 * 9 * 4 + 8u);
  EXPECT_EQ(bytes.substr(0, 4), "MSCB");
  const absl::StatusOr<Codebook> restored = Codebook::Deserialize(bytes);
  ASSERT_TRUE(restored.ok()) << restored.status();
  EXPECT_EQ(restored->size(), 37u);
  EXPECT_EQ(restored->dim(), 9u);
  EXPECT_EQ(restored->centroids(), codebook.centroids());
  EXPECT_EQ(restored->Serialize(), bytes);
}

// FNV-1a 64, as the format specifies, to forge checksums in corrupt input.
void Rehash(std::string* bytes) {
  const uint64_t hash = Fnv1a64(absl::string_view(*bytes).substr(0, bytes->size() - 8));
  for (int i = 0; i < 8; ++i) (*bytes)[bytes->size() - 8 + i] = static_cast<char>(hash >> (8 * i));
}

TEST(CodebookTest, DeserializeRejectsCorruptInput) {
  const std::string good = RandomCodebook(5, 3, 8).Serialize();
  ASSERT_TRUE(Codebook::Deserialize(good).ok());
  auto message = [](const std::string& bytes) {
    const absl::StatusOr<Codebook> result = Codebook::Deserialize(bytes);
    EXPECT_EQ(result.status().code(), absl::StatusCode::kInvalidArgument);
    return std::string(result.status().message());
  };

  EXPECT_THAT(message(""), HasSubstr("got 0 bytes"));
  EXPECT_THAT(message(good.substr(0, 20)), HasSubstr("got 20 bytes"));
  EXPECT_THAT(message(good.substr(0, good.size() - 1)), HasSubstr("inconsistent with"));
  EXPECT_THAT(message(good + "x"), HasSubstr("inconsistent with"));

  std::string bad = good;
  bad[0] = 'X';
  EXPECT_THAT(message(bad), HasSubstr("bad magic"));

  bad = good;
  bad[4] = 4;
  EXPECT_THAT(message(bad), HasSubstr("unsupported version 4 (this build reads 1 to 3)"));

  bad = good;
  bad[4] = 2;  // a version-1 body read with the longer version-2 header
  EXPECT_THAT(message(bad), HasSubstr("inconsistent with"));

  bad = good;
  bad[8] = 0;  // V = 0
  EXPECT_THAT(message(bad), HasSubstr("header says 0 words x 3 dims"));

  bad = good;
  for (int i = 8; i < 24; ++i) bad[i] = static_cast<char>(0xff);  // sizes that overflow
  EXPECT_THAT(message(bad), HasSubstr("inconsistent with"));

  bad = good;
  bad[30] ^= 0x10;  // a flipped bit in the payload
  EXPECT_THAT(message(bad), HasSubstr("checksum mismatch"));

  bad = good;
  const float nan = std::numeric_limits<float>::quiet_NaN();
  std::memcpy(&bad[24 + 4 * 4], &nan, 4);  // centroid 1, coordinate 1 (little-endian host)
  Rehash(&bad);
  EXPECT_THAT(message(bad), HasSubstr("centroid 1, coordinate 1 is nan"));
}

TEST(CodebookTest, TrainedCodebookEncodesWithTheTrainingsAssignment) {
  const std::vector<uint8_t> descriptors = RandomDescriptors(3000, kDim, 9);
  KMeansOptions options;
  options.num_centroids = 40;
  options.min_points_per_centroid = 1;
  options.max_iterations = 3;
  const Codebook exact = Codebook::Train(descriptors.data(), 3000, kDim, options).value();
  EXPECT_FALSE(exact.approximate().has_value());
  EXPECT_EQ(exact.Serialize()[4], 1);  // exact codebooks keep the version-1 form

  options.assignment = KMeansOptions::Assignment::kApproximate;
  options.approximate_probes = 2;
  const Codebook approx = Codebook::Train(descriptors.data(), 3000, kDim, options).value();
  ASSERT_TRUE(approx.approximate().has_value());
  EXPECT_EQ(*approx.approximate(), (ApproximateSearchParams{9, 2}));
  // The codebook's words are those of the approximate search over its centroids.
  std::vector<uint32_t> expected(3000);
  ApproximateNearestCentroidIndex(approx.centroids().data(), 40, kDim, {9, 2}, 1)
      .Search(descriptors.data(), 3000, 1, expected.data(), nullptr);
  EXPECT_EQ(approx.NearestCentroids(descriptors.data(), 3000).value(), expected);
}

TEST(CodebookTest, ApproximateCodebookRoundTrips) {
  const Codebook exact = RandomCodebook(37, 9, 7);
  const Codebook codebook =
      Codebook::FromCentroids(exact.centroids(), 9, ApproximateSearchParams{6, 2}).value();
  const std::string bytes = codebook.Serialize();
  EXPECT_EQ(bytes.size(), 32 + 37 * 9 * 4 + 8u);
  EXPECT_EQ(bytes[4], 2);
  const absl::StatusOr<Codebook> restored = Codebook::Deserialize(bytes);
  ASSERT_TRUE(restored.ok()) << restored.status();
  ASSERT_TRUE(restored->approximate().has_value());
  EXPECT_EQ(*restored->approximate(), (ApproximateSearchParams{6, 2}));
  EXPECT_EQ(restored->centroids(), exact.centroids());
  EXPECT_EQ(restored->Serialize(), bytes);
  const std::vector<uint8_t> descriptors = RandomDescriptors(500, 9, 10);
  EXPECT_EQ(restored->NearestCentroids(descriptors.data(), 500).value(),
            codebook.NearestCentroids(descriptors.data(), 500).value());
}

TEST(CodebookTest, ApproximateParametersAreValidated) {
  const std::vector<float> centroids = RandomCodebook(10, 2, 3).centroids();
  for (const ApproximateSearchParams& p : {ApproximateSearchParams{0, 1},
                                           ApproximateSearchParams{11, 1},
                                           ApproximateSearchParams{4, 5},
                                           ApproximateSearchParams{4, 0}}) {
    EXPECT_THAT(std::string(Codebook::FromCentroids(centroids, 2, p).status().message()),
                HasSubstr("probes <= groups <= words"))
        << p.groups << " " << p.probes;
  }
  // The same through the serialised form: groups = 2^32 - 1 for 10 words.
  std::string bad = Codebook::FromCentroids(centroids, 2, ApproximateSearchParams{3, 1})
                        .value()
                        .Serialize();
  for (int i = 24; i < 28; ++i) bad[i] = static_cast<char>(0xff);
  Rehash(&bad);
  EXPECT_THAT(std::string(Codebook::Deserialize(bad).status().message()),
              HasSubstr("approximate search with 4294967295 groups and 1 probes for 10 words"));
}

}  // namespace
}  // namespace meshseek
